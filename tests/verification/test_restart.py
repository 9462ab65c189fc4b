"""Checkpoint and restart (io/checkpoint.py): a coupled blast with crack gas stopped half-way and restarted from
its checkpoint ends bit-identical to the same run gone through (rock, gas, crack gas, histories); a checkpoint
of another scenario is refused; SIGINT during a run writes a checkpoint, the CSVs and an interrupted summary."""

import json
import os
import signal
import subprocess
import sys
import threading

import numpy as np
import pytest

from blastfrac.io.checkpoint import read
from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import CHECKPOINT_NAME, Simulation

R_B = 0.003
ROCK = {"density": 2600.0, "youngs_modulus": 50e9, "poisson_ratio": 0.2, "tensile_strength": 10e6,
        "cohesion": 40e6, "friction_angle": 40.0, "residual_friction_angle": 30.0,
        "bulk_viscosity_linear": 0.02, "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.15,
        "tensile_fracture_energy": 50.0, "shear_fracture_energy": 500.0}


def _scenario(end_time=6e-6, **output):
    h = R_B / 4
    return {
        "title": "restart", "simulation": {"end_time": end_time, "progress": False},
        "output": {"paraview": True, "figures": False, "interval": 2e-6, **output},
        "rock": ROCK,
        "geometry": {"domain": {"type": "rectangle", "width": 0.04, "height": 0.04}, "mesh_size": 5 * h,
                     "mesh_size_near": h, "refinement_distance": 0.012,
                     "boreholes": [{"center": [0.0, 0.0], "radius": R_B}]},
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
        "monitors": [{"name": "m", "position": [0.008, 0.0], "quantities": ["sxx", "vx"]}],
        "explosive": {"name": "emulsion", "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": R_B}],
                      "grid": {"cell_size": h, "points_per_cell": 2,
                               "bounds": [[-4 * R_B, -4 * R_B], [4 * R_B, 4 * R_B]]}},
        "crack_gas": {"enabled": True},
    }


def _final(sim):
    return {"x": sim.state.x.numpy(), "v": sim.state.v.numpy(), "mode": sim.state.pair_mode.numpy(),
            "gas_x": sim.gas.x.numpy(), "gas_ie": sim.gas.ie.numpy(), "gas_mass": sim.gas.mass.numpy(),
            "crack_mass": sim.crack_gas.gas.mass.numpy(), "crack_e": sim.crack_gas.gas.energy.numpy(),
            "acc": sim.coupler.acc.numpy(), "energy_acc": sim.state.energy_acc.numpy()}


def test_stopped_and_restarted_run_is_bit_identical(tmp_path):
    full = Simulation(scenario_from_dict(_scenario()), out_dir=tmp_path / "full")
    full.run()
    a = _final(full)
    assert a["mode"].any() and a["crack_mass"].sum() > 0, "the case must crack and carry crack gas"
    # the same run, checkpointed every 1 µs and stopped at 3 µs (max_steps), then restarted
    sc = _scenario(checkpoint_interval=1e-6)
    n_half = int(round(3e-6 / full.dt * 0.999))
    part = Simulation(scenario_from_dict(sc), out_dir=tmp_path / "part", max_steps=n_half)
    part.run()
    ck = tmp_path / "part" / CHECKPOINT_NAME
    _, meta = read(ck)
    assert 0 < meta["steps"] <= n_half
    # resumed on one thread (the runs above take the default two): the thread count may change at a restart
    sc1 = {**sc, "simulation": {**sc["simulation"], "threads": 1}}
    resumed = Simulation(scenario_from_dict(sc1), out_dir=tmp_path / "part")
    resumed.run(restart=ck)
    b = _final(resumed)
    assert resumed.steps == full.steps
    for k in a:
        assert np.array_equal(a[k], b[k]), f"{k} differs after the restart"
    for name in ("monitors.csv", "energy.csv", "fracture_degree.csv", "borehole_pressure.csv"):
        assert (tmp_path / "full" / name).read_text() == (tmp_path / "part" / name).read_text(), name
    pvd = lambda d: [l.split("file=")[1] for l in (d / "rock.pvd").read_text().splitlines() if "file=" in l]  # noqa: E731
    assert pvd(tmp_path / "full") == pvd(tmp_path / "part")


def test_checkpoint_of_another_scenario_is_refused(tmp_path):
    sc = _scenario(end_time=1e-6, checkpoint_interval=0.5e-6)
    Simulation(scenario_from_dict(sc), out_dir=tmp_path / "a").run()
    other = _scenario(end_time=1e-6)
    other["rock"] = {**ROCK, "tensile_strength": 12e6}
    with pytest.raises(ValueError, match="another scenario"):
        Simulation(scenario_from_dict(other), out_dir=tmp_path / "a").run(restart=tmp_path / "a" / CHECKPOINT_NAME)


def test_sigint_writes_checkpoint_csvs_and_an_interrupted_summary(tmp_path):
    """`blastfrac run` in a subprocess, SIGINT after a few seconds: exit 130, the checkpoint, summary.json with
    status 'interrupted', the CSVs; `blastfrac run --restart` then completes it."""
    import tomli_w

    scen = tmp_path / "s.toml"
    d = _scenario(end_time=15e-6)
    d["output"]["directory"] = str(tmp_path / "out")
    scen.write_text(tomli_w.dumps(d))
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    p = subprocess.Popen([sys.executable, "-m", "blastfrac", "run", str(scen), "--no-progress"], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out = tmp_path / "out"
    # wait until the dynamic stage writes its first frame, then interrupt
    deadline = threading.Event()
    for _ in range(600):
        if (out / "rock.pvd").exists():
            break
        deadline.wait(0.1)
    deadline.wait(1.0)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=300)
    assert p.returncode == 130, err
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "interrupted" and (out / CHECKPOINT_NAME).is_file()
    for name in ("monitors.csv", "energy.csv", "fracture_degree.csv"):
        assert len((out / name).read_text().splitlines()) >= 2
    assert "--restart" in err
    r = subprocess.run([sys.executable, "-m", "blastfrac", "run", "--restart", str(out), "--no-progress"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"
