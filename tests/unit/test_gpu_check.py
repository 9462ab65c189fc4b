"""benchmarks/gpu_check.py keeps what a lent GPU's minutes measured: a part that fails is recorded and the other
parts still run, and the results are on disk after each part (a call cut off by its time limit brings back its
files). Run here on the CPU with the parts replaced by stand-ins, so only the bookkeeping is under test."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

BENCH = Path(__file__).parents[2] / "benchmarks"


def _load():
    sys.path.insert(0, str(BENCH))
    spec = importlib.util.spec_from_file_location("gpu_check", BENCH / "gpu_check.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_a_failed_part_is_recorded_and_the_rest_still_runs(tmp_path, monkeypatch):
    gc = _load()
    seen = []

    def cdem_fails(*a, **k):
        raise RuntimeError("no gmsh here")

    def mpm(sizes, steps, device):
        # written to disk before the next part starts: what a cut-off call would still bring back
        seen.append(json.loads((tmp_path / "gpu_check.json").read_text()) if (tmp_path / "gpu_check.json").exists()
                    else None)
        return [{"n_particles": n, "steps": steps, "wall_s": 1.0, "particle_steps_per_s": n * steps} for n in sizes]

    def run_case(case, device, graph, threads, max_steps):
        on_disk = json.loads((tmp_path / "gpu_check.json").read_text())
        seen.append(on_disk)
        return {"case": case, "device": device, "graph": graph, "threads": threads, "steps": 10, "run_wall_s": 1.0,
                "D": 0.2, "energy": {"explosive_released": 1.0, "kinetic": 0.1, "budget_error_relative": 0.004},
                "graph_report": None, "warnings": []}

    monkeypatch.setattr(gc.bench_cdem, "run", cdem_fails)
    monkeypatch.setattr(gc.bench_mpm, "run", mpm)
    monkeypatch.setattr(gc, "_run_case", run_case)
    rc = gc.main(["--device", "cpu", "--quick", "--skip-cpu", "--out", str(tmp_path)])
    res = json.loads((tmp_path / "gpu_check.json").read_text())
    assert rc == 1                                            # a part failed ...
    assert [e["stage"] for e in res["errors"]] == ["cdem"] and "no gmsh here" in res["errors"][0]["error"]
    assert len(res["mpm"]) == 1 and len(res["runs"]) == 4    # ... and every other part ran
    assert seen[0] is None                                    # MPM ran first (it needs no mesh)
    assert seen[1]["mpm"] and seen[1]["errors"]               # the first run saw MPM's figures, CDEM's failure
    assert len(seen[-1]["runs"]) == 3                         # the last run saw the three runs before it
    assert "cdem failed" in (tmp_path / "gpu_check.md").read_text()
