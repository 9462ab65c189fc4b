"""Charge resolution (examples/charge_resolution, issue 12 item 1): the wall impulse converges from below with the
number of MPM cells across the charge, and ``blastfrac check`` warns below CHARGE_CELLS_ACROSS_MIN.

Set-up (examples/charge_resolution/study.py, imported here so that the test runs the study's own scenario): a 5 mm
radius emulsion charge filling a 5 mm hole in unbreakable Table 2 rock, viscous sides, grid ±2 R, rock mesh at the
wall = the MPM cell. Reference: the study's finest levels (I_REF below, from examples/charge_resolution/results.json).

Fast test (~15 s): 10 and 20 cells across with the defaults (the study's series v02), to 5 µs: I(5 µs) is low at
both, the error falls by more than 1.5× from 10 to 20 cells, and 20 cells is within 2 % at the warning threshold.
Slow test (make validate, ~40 s): 10, 20, 40 cells to 25 µs: the same trend at 5 µs, the 10–20 µs impulse of
10 and 20 cells within 2 % of 40 cells, and the late wall pressure against the JWL pressure of the hole's gas.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import pytest

from blastfrac.cli import main
from blastfrac.cli.check import CHARGE_CELLS_ACROSS_MIN, charge_width

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("charge_resolution_study", ROOT / "examples/charge_resolution/study.py")
study = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(study)

# The study's reference wall impulse at 5 µs [Pa·s] with the 0.2 gas defaults (series v02): its 80-cell level
# (examples/charge_resolution/README.md); 10 and 20 cells gave 11410 and 11648 Pa·s, -3.6 % and -1.6 % against it.
I5_REF = 11831.0
TOL_20 = 0.02                  # |error| of I(5 µs) at 20 cells allowed (CHARGE_CELLS_ACROSS_MIN: 2 % in the study)


def _impulse(tmp_path, case: str, end: float) -> dict:
    study.run_case(case, tmp_path, end)
    return study.analyse_case(tmp_path / case)


def test_wall_impulse_converges_from_below_with_cells_across(tmp_path):
    i10 = _impulse(tmp_path, "n10_v02", 5e-6)["impulse"]["5us"]
    i20 = _impulse(tmp_path, "n20_v02", 5e-6)["impulse"]["5us"]
    e10, e20 = i10 / I5_REF - 1, i20 / I5_REF - 1
    print(f"I(5 µs): 10 cells {i10:.1f} Pa·s ({e10:+.2%}), 20 cells {i20:.1f} Pa·s ({e20:+.2%}), ref {I5_REF:.1f}")
    assert e10 < e20 < 0, "converges from below"
    assert abs(e10) / abs(e20) > 1.5, "the error falls by more than 1.5x per halving of h"
    assert abs(e20) < TOL_20
    assert abs(e10) > 0.03, "10 cells is clearly under-resolved (the study: 3.6 %)"


@pytest.mark.slow
def test_charge_resolution_study_levels_10_20_40(tmp_path):
    runs = {n: _impulse(tmp_path, f"n{n}_v02", 25e-6) for n in (10, 20, 40)}
    e = {n: r["impulse"]["5us"] / I5_REF - 1 for n, r in runs.items()}
    print({n: f"{v:+.2%}" for n, v in e.items()})
    assert e[10] < e[20] < 0 and abs(e[40]) < 0.02          # the study: +0.1 % (40 cells)
    for n in (10, 20):                               # after the first reverberations: quasi-static gas pressure
        w = study.window_error(runs[n], runs[40], 10e-6, 20e-6)
        print(f"max |I_{n}/I_40 - 1| over 10-20 µs: {w:.2%}")
        assert w < 0.02
    q = runs[40]["quasi_static"][-1]                 # 20-25 µs: the gas has rung down
    assert abs(q["p_wall"] / q["p_jwl_VE"] - 1) < 0.03
    assert q["p_wall"] < q["p_isentrope_E0"] * 1.02  # the gas gave energy to the rock


# ---------------------------------------------------------------------------------------------- the check warning
def _scenario_file(tmp_path, cell_size: float) -> Path:
    f = tmp_path / f"charges_{cell_size:g}.toml"
    f.write_text(f"""
title = "charge resolution check"
[simulation]
end_time = 1e-6
[output]
directory = "{(tmp_path / 'out').as_posix()}"
[rock]
density = 2600.0
youngs_modulus = 50e9
poisson_ratio = 0.2
[geometry]
domain = {{ type = "rectangle", width = 0.04, height = 0.04 }}
mesh_size = 0.004
mesh_size_near = 0.001
[[geometry.boreholes]]
center = [0.0, 0.0]
radius = 0.005
[explosive]
name = "emulsion"
charges = [{{ kind = "circle", center = [0.0, 0.0], radius = 0.005 }},
           {{ kind = "polygon", vertices = [[-0.003, -0.001], [0.003, -0.001], [0.003, 0.001], [-0.003, 0.001]] }}]
[explosive.grid]
cell_size = {cell_size}
bounds = [[-0.008, -0.008], [0.008, 0.008]]
""")
    return f


def test_check_warns_once_per_under_resolved_charge(tmp_path, capsys):
    assert main(["check", str(_scenario_file(tmp_path, 0.001))]) == 0
    err = [ln for ln in capsys.readouterr().err.splitlines() if "cells across" in ln]
    assert len(err) == 2, err
    assert err[0].startswith("warning: explosive.charges[0] (circle") and " 10 grid cells across" in err[0]
    assert err[1].startswith("warning: explosive.charges[1] (polygon") and " 2 grid cells across" in err[1]
    assert f"fewer than {CHARGE_CELLS_ACROSS_MIN}" in err[0]
    assert "cell_size <= 0.5 mm" in err[0] and "cell_size <= 0.1 mm" in err[1]


def test_check_is_quiet_for_resolved_charges(tmp_path, capsys):
    f = _scenario_file(tmp_path, 0.0004)        # circle 25 cells, polygon (2 mm wide) 5: only the polygon warns
    assert main(["check", str(f)]) == 0
    err = [ln for ln in capsys.readouterr().err.splitlines() if "cells across" in ln]
    assert len(err) == 1 and "charges[1]" in err[0]


def test_charge_width():
    sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
    assert charge_width(type("C", (), {"kind": "polygon", "vertices": sq})) == pytest.approx(1.0)
    rect = [(0, 0), (0, 2), (10, 2), (10, 0)]                     # clockwise: the orientation does not matter
    assert charge_width(type("C", (), {"kind": "polygon", "vertices": rect})) == pytest.approx(2.0)
    ell = [(0, 0), (10, 0), (10, 1), (1, 1), (1, 10), (0, 10)]     # L with arms 1 wide
    assert charge_width(type("C", (), {"kind": "polygon", "vertices": ell})) == pytest.approx(1.0)
    tri = [(0, 0), (1, 0), (0.5, math.sqrt(3) / 2)]
    assert charge_width(type("C", (), {"kind": "polygon", "vertices": tri})) == pytest.approx(math.sqrt(3) / 2)
    n = 64
    ngon = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]
    assert charge_width(type("C", (), {"kind": "polygon", "vertices": ngon})) == pytest.approx(2 * math.cos(math.pi / n))
    assert charge_width(type("C", (), {"kind": "circle", "radius": 0.005})) == pytest.approx(0.01)
