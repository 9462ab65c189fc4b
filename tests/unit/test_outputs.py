"""Outputs a user can trust: strict JSON, VTU without NaN and with the plane-strain σzz, atomic writes,
CSV units, the energy-budget warning and a blow-up that says where (docs/results.md)."""

import csv
import json
import math
import os
from pathlib import Path

import meshio
import numpy as np
import pytest
import tomli_w

from blastfrac.cli import main
from blastfrac.io import paraview
from blastfrac.io.atomic import atomic_open, write_atomic, write_text_atomic
from blastfrac.io.tables import CsvHistory, read_csv, strip_unit, write_summary
from blastfrac.scenario import ScenarioError, scenario_from_dict
from blastfrac.simulation import Simulation, SimulationError


def _strict_loads(text: str):
    def no_constant(name):
        raise ValueError(f"non-standard JSON constant {name}")

    return json.loads(text, parse_constant=no_constant)


def _scenario(tmp_path: Path, **extra) -> dict:
    d = {
        "title": "outputs",
        "simulation": {"end_time": 2e-6, "progress": False},
        "output": {"directory": str(tmp_path / "out"), "figures": False, "interval": 2e-7, "monitor_interval": 5e-8},
        "geometry": {"domain": {"type": "rectangle", "width": 0.1, "height": 0.1}, "mesh_size": 0.01,
                     "boreholes": [{"radius": 0.005}]},
        "borehole_pressure": [{"borehole": 0, "pulse": {"type": "constant", "value": 5e6}}],
        "monitors": [{"name": "m1", "position": [0.02, 0.0], "quantities": ["ux", "vx", "speed", "sxx", "pressure"]}],
    }
    for k, v in extra.items():
        d[k] = {**d.get(k, {}), **v} if isinstance(v, dict) else v
    return d


# ------------------------------------------------------------------ (1) strict JSON
def test_write_summary_is_strict_json_with_null(tmp_path):
    p = tmp_path / "summary.json"
    write_summary(p, {"a": float("nan"), "b": [1.0, float("inf"), {"c": -math.inf}], "d": np.float64("nan"),
                      "e": (np.float32(2.5), np.int64(3)), "f": np.array([1.0, np.nan]), "g": True, "h": None})
    s = _strict_loads(p.read_text())
    assert s == {"a": None, "b": [1.0, None, {"c": None}], "d": None, "e": [2.5, 3], "f": [1.0, None],
                 "g": True, "h": None}


@pytest.fixture(scope="module")
def initial_insitu_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("insitu")
    sc = scenario_from_dict(_scenario(tmp, insitu={"method": "initial", "sxx": -1e6, "syy": -2e6}))
    sim = Simulation(sc, max_steps=40)
    return sim, sim.run(progress=False)


def test_insitu_initial_summary_parses_strictly(initial_insitu_run):
    sim, _ = initial_insitu_run
    s = _strict_loads((sim.out_dir / "summary.json").read_text())
    assert s["insitu_stage"]["method"] == "initial"
    assert s["insitu_stage"]["kinetic_to_strain_ratio"] is None       # it does not exist: no relaxation
    assert s["status"] == "completed" and isinstance(s["warnings"], list)


# ------------------------------------------------------------------ (2) VTU: σzz and no NaN
def test_vtu_plane_strain_szz_and_no_nan(tmp_path):
    sc = scenario_from_dict(_scenario(tmp_path))
    sim = Simulation(sc)
    st = sim.state
    rng = np.random.default_rng(1)
    sig = rng.normal(0, 1e6, (sim.model.element_count, 3))
    st.sigma.assign(sig)
    mode = np.zeros(sim.model.spring_count, np.int32)
    mode[[0, 1, 6, 11]] = [1, 1, 2, 2]                       # springs of 3 interfaces broken
    st.pair_mode.assign(mode)
    sim.out_dir.mkdir(parents=True)
    paraview.ParaviewSeries(sim.out_dir).write(sim.model, st, 0.0)
    m = meshio.read(sim.out_dir / "rock_0000.vtu")
    types = [c.type for c in m.cells]
    assert types == ["triangle", "line"] and len(m.cells[1].data) == 3
    for name, blocks in m.cell_data.items():
        for b in blocks:
            assert np.isfinite(b).all(), name
    tri_stress, line_stress = (np.asarray(b).reshape(len(b), 3, 3) for b in m.cell_data["stress"])
    nu = sim.model.elastic.block_nu                          # the blocks' Poisson ratio
    assert np.allclose(tri_stress[:, 0, 0], sig[:, 0]) and np.allclose(tri_stress[:, 1, 1], sig[:, 1])
    assert np.allclose(tri_stress[:, 0, 1], sig[:, 2]) and np.allclose(tri_stress[:, 1, 0], sig[:, 2])
    assert np.allclose(tri_stress[:, 2, 2], nu * (sig[:, 0] + sig[:, 1]), rtol=1e-12, atol=1e-6)
    assert np.all(tri_stress[:, 0:2, 2] == 0) and np.all(tri_stress[:, 2, 0:2] == 0)
    assert np.all(line_stress == 0)
    tri_mode, line_mode = m.cell_data["crack_mode"]
    assert np.all(tri_mode == 0) and sorted(line_mode.tolist()) == [1, 2, 2]
    assert 0 < nu < 0.5 and math.isclose(paraview.block_poisson_ratio(sim.model), nu, rel_tol=1e-12)


# ------------------------------------------------------------------ (3) atomic writes
class Boom(RuntimeError):
    pass


def _only(dirpath: Path) -> list[str]:
    return sorted(p.name for p in dirpath.iterdir())


def test_write_atomic_failure_keeps_previous_file(tmp_path):
    p = tmp_path / "f.txt"
    write_text_atomic(p, "old\n")

    def half(tmp: Path):
        tmp.write_text("new, half wri")
        raise Boom

    with pytest.raises(Boom):
        write_atomic(p, half)
    assert p.read_text() == "old\n" and _only(tmp_path) == ["f.txt"]
    with pytest.raises(Boom):
        with atomic_open(tmp_path / "g.txt") as fh:
            fh.write("partial")
            raise Boom
    assert _only(tmp_path) == ["f.txt"]                    # no partial g.txt, no temporary left
    with atomic_open(p) as fh:
        fh.write("new\n")
    assert p.read_text() == "new\n" and _only(tmp_path) == ["f.txt"]
    mode = os.stat(p).st_mode & 0o777
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o666 & ~umask


def test_csv_and_vtu_writes_are_atomic(tmp_path, monkeypatch):
    h = CsvHistory(tmp_path / "energy.csv", ["kinetic"], unit="J/m")
    h.append(0.0, [1.0])
    h.flush()
    before = (tmp_path / "energy.csv").read_text()
    h.append(1.0, ["not a number"])
    with pytest.raises(ValueError):
        h.flush()
    assert (tmp_path / "energy.csv").read_text() == before and _only(tmp_path) == ["energy.csv"]

    sc = scenario_from_dict(_scenario(tmp_path))
    sim = Simulation(sc)

    def broken_write(path, mesh, **kw):
        Path(path).write_bytes(b"<VTKFile partial")
        raise Boom

    monkeypatch.setattr(paraview.meshio, "write", broken_write)
    with pytest.raises(Boom):
        paraview.ParaviewSeries(tmp_path).write(sim.model, sim.state, 0.0)
    assert _only(tmp_path) == ["energy.csv"]               # no rock_0000.vtu, no rock.pvd, no temporary


# ------------------------------------------------------------------ (4) energy-budget warning
def test_budget_warning_option_is_validated(tmp_path):
    for bad in (0.0, -0.1, 1.5):
        with pytest.raises(ScenarioError, match="output.budget_warning"):
            scenario_from_dict(_scenario(tmp_path, output={"budget_warning": bad}))
    assert scenario_from_dict(_scenario(tmp_path)).output.budget_warning == 0.05


def test_budget_warning_once_on_stderr_and_in_summary(tmp_path, capsys):
    sc = scenario_from_dict(_scenario(tmp_path, simulation={"end_time": 1e-5}, output={"budget_warning": 1e-14}))
    sim = Simulation(sc, max_steps=60)                  # past the 50 steps before which no sample is checked
    s = sim.run(progress=False)
    err = capsys.readouterr().err
    assert err.count("warning: energy budget error") == 1 and "output.budget_warning" in err
    written = _strict_loads((sim.out_dir / "summary.json").read_text())
    assert len(written["warnings"]) == 1 and "energy budget error" in written["warnings"][0]
    assert abs(written["energy"]["budget_error_relative"]) > 1e-14 or len(s["warnings"]) == 1


def test_no_budget_warning_for_a_run_shorter_than_the_check_window(tmp_path, capsys):
    """A 2-step run warned of a +100 % error in its 6e-6 J/m: the final state of so short a run is not checked."""
    sim = Simulation(scenario_from_dict(_scenario(tmp_path, output={"budget_warning": 1e-14})), max_steps=2)
    s = sim.run(progress=False)
    assert s["warnings"] == [] and "energy budget" not in capsys.readouterr().err


def test_budget_warning_follows_the_final_error(tmp_path, initial_insitu_run, capsys):
    sim = Simulation(scenario_from_dict(_scenario(tmp_path)), max_steps=40)
    s = sim.run(progress=False)
    if abs(s["energy"]["budget_error_relative"]) <= 0.05:
        assert s["warnings"] == [] or "energy budget error" in s["warnings"][0]   # an early sample may exceed
    _, s2 = initial_insitu_run
    if abs(s2["energy"]["budget_error_relative"]) > 0.05:                  # over the default limit at the end
        assert len(s2["warnings"]) == 1 and "5 %" in s2["warnings"][0]


# ------------------------------------------------------------------ (5) CSV units
def test_csv_headers_carry_units_and_read_back(initial_insitu_run):
    sim, _ = initial_insitu_run
    heads = {}
    for f in ("monitors.csv", "energy.csv", "fracture_degree.csv"):
        with open(sim.out_dir / f, newline="") as fh:
            heads[f] = next(csv.reader(fh))
    assert heads["monitors.csv"] == ["time [s]", "m1:ux [m]", "m1:vx [m/s]", "m1:speed [m/s]", "m1:sxx [Pa]",
                                     "m1:pressure [Pa]"]
    assert heads["energy.csv"][0] == "time [s]" and all(h.endswith(" [J/m]") for h in heads["energy.csv"][1:])
    assert "budget_error [J/m]" in heads["energy.csv"]
    assert heads["fracture_degree.csv"][:4] == ["time [s]", "D [-]", "D_tensile [-]", "D_shear [-]"]
    mon = read_csv(sim.out_dir / "monitors.csv")
    assert list(mon) == ["time", "m1:ux", "m1:vx", "m1:speed", "m1:sxx", "m1:pressure"]
    assert np.allclose(mon["m1:pressure"][1:], 1.5e6, rtol=0.2)     # in-situ −(σxx+σyy)/2 = 1.5 MPa, compression
    assert strip_unit("m1:sxx [Pa]") == "m1:sxx" and strip_unit("D") == "D"
    data = np.loadtxt(sim.out_dir / "energy.csv", delimiter=",", skiprows=1)
    assert data.shape[1] == len(heads["energy.csv"])


# ------------------------------------------------------------------ (6) blow-up report
def test_blow_up_names_position_and_writes_outputs(tmp_path, monkeypatch, capsys):
    # a time step 10 x the stable one makes the central-difference scheme diverge within a few hundred steps
    monkeypatch.setattr(Simulation, "_time_step", lambda self: 10.0 * self.model.stable_dt)
    d = _scenario(tmp_path, simulation={"end_time": 1e-3}, output={"monitor_interval": 1e-9, "paraview": False})
    path = tmp_path / "blow.toml"
    path.write_text(tomli_w.dumps(d))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-progress", "--max-steps", "3000"]) == 1
    err = capsys.readouterr().err
    assert "non-finite energy" in err and "at (x, y) = (" in err and "time step" in err
    for f in ("resolved.toml", "summary.json", "monitors.csv", "energy.csv", "fracture_degree.csv"):
        assert (out / f).is_file() and (out / f).stat().st_size > 0, f
    s = _strict_loads((out / "summary.json").read_text())
    assert s["status"] == "failed" and "non-finite energy" in s["error"]
    node = s["failure"]["node"]
    x, y = node["reference_position"]
    assert abs(x) <= 0.05 + 1e-9 and abs(y) <= 0.05 + 1e-9         # a point of the 0.1 m square
    assert s["failure"]["step"] > 0 and "time step" in s["failure"]["likely_causes"][0]   # dt was 10x stable
    e = read_csv(out / "energy.csv")
    # the history runs up to the blow-up: its last sample non-finite, or already past any physical value
    assert len(e["time"]) >= 2 and not (np.isfinite(e["kinetic"][-1]) and e["kinetic"][-1] < 1e100)


def test_simulation_error_carries_details():
    e = SimulationError("boom", {"step": 3})
    assert str(e) == "boom" and e.details == {"step": 3}


def test_a_new_run_clears_the_frames_of_an_earlier_one(tmp_path, capsys):
    """Run twice into one directory, the second with fewer frames: no stale rock_NNNN.vtu of the first stays in
    it (ParaView would read them as part of the series); files that are not blastfrac's own are left alone."""
    d = _scenario(tmp_path)
    Simulation(scenario_from_dict(d)).run()
    out = tmp_path / "out"
    first = sorted(p.name for p in out.glob("rock_*.vtu"))
    (out / "notes.txt").write_text("mine")
    d["output"]["interval"] = 1e-6
    Simulation(scenario_from_dict(d)).run()
    second = sorted(p.name for p in out.glob("rock_*.vtu"))
    assert len(second) < len(first)
    frames = [l for l in (out / "rock.pvd").read_text().splitlines() if "file=" in l]
    assert len(frames) == len(second)
    assert (out / "notes.txt").read_text() == "mine"
    assert "removed" in capsys.readouterr().err


def test_max_steps_bounds_the_insitu_stage_and_non_convergence_warns(tmp_path, capsys):
    d = _scenario(tmp_path, insitu={"syy": -10e6, "max_steps": 100_000, "tolerance": 1e-12})
    d.pop("borehole_pressure")
    sim = Simulation(scenario_from_dict(d), max_steps=400)
    s = sim.run()
    assert s["insitu_stage"]["steps"] == 400 and not s["insitu_stage"]["converged"]
    assert any("did not converge" in w for w in s["warnings"])
    assert "did not converge" in capsys.readouterr().err


def test_a_full_disk_ends_in_one_clear_message(tmp_path, monkeypatch, capsys):
    """ENOSPC while writing the results: exit 2 with one line naming the directory, no traceback, and no file
    left half-written (the writes are atomic)."""
    import errno

    from blastfrac.io import atomic

    d = _scenario(tmp_path)
    scen = tmp_path / "s.toml"
    scen.write_text(tomli_w.dumps(d))
    real = atomic.write_text_atomic
    calls = {"n": 0}

    def full(path, text):
        calls["n"] += 1
        if str(path).endswith("summary.json"):
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return real(path, text)

    monkeypatch.setattr(atomic, "write_text_atomic", full)
    import blastfrac.io.tables as tables

    monkeypatch.setattr(tables, "write_text_atomic", full)
    rc = main(["run", str(scen), "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 2 and "No space left on device" in err and "Traceback" not in err
    assert not list((tmp_path / "out").glob("*.tmp*"))
