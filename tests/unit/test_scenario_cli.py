"""Scenario validation, overrides, CLI exit codes, meshing determinism and topology invariants."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from blastfrac.cli import main
from blastfrac.geometry import generate_mesh
from blastfrac.model.topology import build_topology
from blastfrac.scenario import ScenarioError, load_scenario, scenario_from_dict

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "examples" / "borehole_pulse" / "scenario.toml"

BASE = {"geometry": {"domain": {"type": "rectangle", "width": 0.2, "height": 0.2}, "mesh_size": 0.01,
                     "boreholes": [{"radius": 0.005}]}}


def _err(d) -> str:
    with pytest.raises(ScenarioError) as e:
        scenario_from_dict(d)
    return str(e.value)


def test_unknown_key_is_named():
    msg = _err({**BASE, "rock": {"youngs_modulus": 50e9, "tensile_strenght": 1e6}})
    assert "rock.tensile_strenght" in msg and "unknown key" in msg


def test_negative_modulus_names_key_and_range():
    msg = _err({**BASE, "rock": {"youngs_modulus": -1.0}})
    assert "rock.youngs_modulus" in msg and "greater than 0" in msg


def test_wrong_type_is_reported():
    msg = _err({**BASE, "simulation": {"end_time": "long"}})
    assert "simulation.end_time" in msg


def test_borehole_outside_domain():
    d = {"geometry": {**BASE["geometry"], "boreholes": [{"center": [0.099, 0.0], "radius": 0.005}]}}
    assert "boreholes[0]" in _err(d)


def test_per_area_needs_kn_ks():
    assert "rock.kn" in _err({**BASE, "rock": {"stiffness_mode": "per_area"}})


def test_overrides_and_resolved_roundtrip(tmp_path):
    sc = load_scenario(DEMO, ["rock.tensile_strength=12e6", "simulation.end_time=1e-6", "geometry.boreholes.0.radius=0.004"])
    assert sc.rock.tensile_strength == 12e6 and sc.geometry.boreholes[0].radius == 0.004
    from blastfrac.scenario import write_resolved

    write_resolved(sc, tmp_path / "resolved.toml")
    again = load_scenario(tmp_path / "resolved.toml")
    assert again == sc, "the resolved scenario must reproduce the run exactly"


def test_cli_user_errors_exit_2_without_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[geometry]\ndomain = {type="rectangle", width=0.2, height=0.2}\nmesh_size=0.01\n[rock]\npoisson_ratio = 0.7\n')
    for args in (["check", str(bad)], ["check", str(tmp_path / "missing.toml")], ["run", str(bad)]):
        r = subprocess.run([sys.executable, "-m", "blastfrac.cli", *args], capture_output=True, text=True)
        assert r.returncode == 2, r.stderr
        assert "Traceback" not in r.stderr and r.stderr.startswith("error:")
    r = subprocess.run([sys.executable, "-m", "blastfrac.cli", "check", str(bad)], capture_output=True, text=True)
    assert "rock.poisson_ratio" in r.stderr


def test_check_prints_counts(capsys):
    assert main(["check", str(DEMO)]) == 0
    out = capsys.readouterr().out
    for word in ("elements", "springs", "stable dt", "steps to end time", "memory"):
        assert word in out
    # penalty springs β·E'/h̄ with β = 20 are far stiffer than the blocks: they, not the CST, set the rock's step
    import re
    rock, blocks = re.search(r"stable dt rock \(Gershgorin\)\s+(\S+) s \(the blocks alone would allow (\S+) s", out).groups()
    assert float(blocks) > 3 * float(rock)
    assert "heterogeneity" not in out                      # homogeneous rock: no row
    assert main(["check", str(DEMO), "--set", "rock.heterogeneity.weibull_modulus=5",
                 "--set", "rock.heterogeneity.reference_length=0.002"]) == 0
    out = capsys.readouterr().out
    # CV of the unit-mean Weibull variable at m = 5: sqrt(Γ(1.4) − Γ(1.2)²)/Γ(1.2)
    import math
    cv = math.sqrt(math.gamma(1.4) - math.gamma(1.2) ** 2) / math.gamma(1.2)
    assert f"Weibull m = 5 (CV {cv:.3f})" in out and "L_ref = 0.002 m" in out


def test_run_writes_all_outputs(tmp_path):
    out = tmp_path / "run"
    assert main(["run", str(DEMO), "--out", str(out), "--max-steps", "30", "--no-progress",
                 "--set", "output.interval=1e-7"]) == 0
    for f in ("resolved.toml", "summary.json", "monitors.csv", "fracture_degree.csv", "energy.csv", "rock.pvd",
              "rock_0000.vtu", "fracture_pattern.png"):
        assert (out / f).is_file(), f
    s = json.loads((out / "summary.json").read_text())
    assert s["steps"] == 30 and s["counts"]["springs"] == 2 * s["counts"]["interfaces"]
    import meshio

    frame = meshio.read(out / "rock_0000.vtu")
    assert "displacement" in frame.point_data and "stress" in frame.cell_data


def test_mesh_is_deterministic_and_refined():
    sc = scenario_from_dict({**BASE, "geometry": {**BASE["geometry"], "mesh_size_near": 0.002}})
    m1, m2 = generate_mesh(sc.geometry, 3), generate_mesh(sc.geometry, 3)
    assert np.array_equal(m1.triangles, m2.triangles) and np.array_equal(m1.vertices, m2.vertices)
    L = m1.edge_lengths()
    c = m1.vertices[m1.triangles].mean(axis=1)
    r = np.hypot(c[:, 0], c[:, 1])
    assert L[r < 0.008].mean() < 0.5 * L[r > 0.05].mean(), "refinement around the borehole"
    assert set(m1.boundary_tags) == {"left", "right", "top", "bottom", "hole0"}


def test_topology_counts_follow_euler():
    sc = scenario_from_dict(BASE)
    mesh = generate_mesh(sc.geometry)
    topo = build_topology(mesh)
    n_e, n_b = len(mesh.triangles), len(topo.boundary_slots)
    assert len(topo.iface_elems) == (3 * n_e - n_b) // 2
    assert n_b == len(mesh.boundary_edges)
    # every pair joins two nodes at the same mesh vertex, on different elements
    pn = topo.pair_nodes
    assert np.array_equal(topo.node_vertex[pn[:, 0]], topo.node_vertex[pn[:, 1]])
    assert np.all(pn[:, 0] // 3 != pn[:, 1] // 3)
    # each spring appears once as i and once as j in the node gather table
    s = topo.node_pair_sign
    assert (s == -1).sum() == len(pn) and (s == 1).sum() == len(pn)


def test_check_predicts_steps_from_the_contact_and_mpm_limits(capsys):
    """`check` takes the step from every limit: a contact stiffness of 1e30 Pa gives a contact step of
    2/ω = 2√(m/k)·(...) ~ 1e-17 s, and check predicts its ~1e12 steps and warns (it used to print the rock's)."""
    import re

    root = Path(__file__).resolve().parents[2]
    rc = main(["check", str(root / "examples/circular_rock/demo.toml"), "--set", "coupling.contact_stiffness=1e30"])
    out = capsys.readouterr()
    assert rc == 0
    steps = int(re.search(r"steps to end time\s+([\d,]+)", out.out).group(1).replace(",", ""))
    assert steps > 1e11 and "step limited by              contact" in out.out
    assert "warning" in out.err and "contact_stiffness" in out.err
