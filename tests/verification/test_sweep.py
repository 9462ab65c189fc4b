"""Sweeps on Dask (blastfrac.sweep, `blastfrac sweep`): the product of overrides runs as separate worker
processes, each case in its own directory; sweep.csv holds every case with its overrides and summary figures;
a failing case is reported without stopping the others; a second run skips the finished cases; an existing
scheduler (a `dask scheduler` / `dask worker` pair started by hand) runs it too."""

import csv
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from blastfrac.sweep import load_sweep, run_sweep

ROOT = Path(__file__).resolve().parents[2]
BASE = """
title = "sweep case"
[simulation]
end_time = 2e-6
progress = false
[output]
paraview = false
figures = false
[rock]
density = 2600.0
youngs_modulus = 50e9
poisson_ratio = 0.2
tensile_strength = 10e6
cohesion = 40e6
friction_angle = 40.0
residual_friction_angle = 30.0
[geometry]
domain = { type = "rectangle", width = 0.04, height = 0.04 }
mesh_size = 0.004
mesh_size_near = 0.001
refinement_distance = 0.01
[[geometry.boreholes]]
center = [0.0, 0.0]
radius = 0.003
[[borehole_pressure]]
borehole = 0
pulse = { type = "triangle", peak = 200e6, rise_time = 0.5e-6, duration = 2e-6 }
"""


def _write(tmp: Path, extra: str = "") -> Path:
    (tmp / "base.toml").write_text(BASE)
    (tmp / "broken.msh").write_text("not a mesh")
    sw = tmp / "sweep.toml"
    sw.write_text(f'base = "base.toml"\noutput = "out"\n[parameters]\n"rock.tensile_strength" = [5e6, 20e6]\n'
                  f'{extra}')
    return sw


def test_local_sweep_runs_cases_reports_failures_and_skips_finished(tmp_path):
    sw = _write(tmp_path, '[[cases]]\nname = "bad_mesh"\nset = { "geometry.mesh_file" = "broken.msh" }\n')
    rows = run_sweep(sw, workers=2, progress=False)
    by = {r["case"]: r for r in rows}
    assert set(by) == {"tensile_strength=5e+06", "tensile_strength=2e+07", "bad_mesh"}
    assert by["bad_mesh"]["status"] == "failed" and "mesh" in by["bad_mesh"]["error"]
    weak, strong = by["tensile_strength=5e+06"], by["tensile_strength=2e+07"]
    assert weak["status"] == strong["status"] == "completed"
    assert weak["D"] > strong["D"], "the weaker rock breaks more springs under the same pulse"
    for name in ("tensile_strength=5e+06", "tensile_strength=2e+07"):
        s = json.loads((tmp_path / "out" / name / "summary.json").read_text())
        assert s["fracture_degree"]["D"] == by[name]["D"]
    with open(tmp_path / "out" / "sweep.csv") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == 3 and float(table[0]["set:rock.tensile_strength"]) == 5e6
    info = json.loads((tmp_path / "out" / "sweep.json").read_text())["sweep"]
    assert info["failed"] == ["bad_mesh"] and (tmp_path / "out" / "sweep_comparison.png").is_file()
    again = run_sweep(sw, workers=2, progress=False)
    assert {r["case"]: r["skipped"] for r in again} == {"tensile_strength=5e+06": True, "tensile_strength=2e+07": True,
                                                        "bad_mesh": False}


def test_sweep_on_a_scheduler_started_by_hand(tmp_path):
    dask = shutil.which("dask", path=str(Path(sys.executable).parent))
    if dask is None:
        pytest.skip("no dask command next to this Python")
    sf = tmp_path / "scheduler.json"
    sched = subprocess.Popen([dask, "scheduler", "--scheduler-file", str(sf), "--no-dashboard", "--port", "0"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = None
    try:
        for _ in range(300):
            if sf.exists() and sf.stat().st_size:
                break
            time.sleep(0.1)
        worker = subprocess.Popen([dask, "worker", "--scheduler-file", str(sf), "--nworkers", "1", "--nthreads", "1",
                                   "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        addr = json.loads(sf.read_text())["address"]
        rows = run_sweep(load_sweep(_write(tmp_path)), scheduler=addr, progress=False)
        assert [r["status"] for r in rows] == ["completed", "completed"]
    finally:
        for p in (worker, sched):
            if p is not None:
                p.terminate()
                p.wait(timeout=30)


def test_bad_sweep_files_are_refused(tmp_path):
    from blastfrac.scenario import ScenarioError

    (tmp_path / "base.toml").write_text(BASE)
    for text, words in (('base = "base.toml"\n[parameters]\n"rock.tensile_strength" = 5e6\n', "non-empty list"),
                        ('base = "base.toml"\nfoo = 1\n', "unknown key"),
                        ('base = "base.toml"\n', "no cases"),
                        ('base = "base.toml"\n[parameters]\n"rock.density" = [-1.0]\n', "rock.density")):
        p = tmp_path / "s.toml"
        p.write_text(text)
        with pytest.raises(ScenarioError, match=words):
            from blastfrac.sweep import validate_cases
            validate_cases(load_sweep(p))
