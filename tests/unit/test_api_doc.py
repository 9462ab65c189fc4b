"""docs/api.md runs: its runnable examples execute as documented and give sensible numbers.

The ```python blocks preceded by ``<!-- test -->`` are executed in order, as one script, in an empty directory
(a borehole pressure pulse in a small rock square: a few seconds). The other python blocks (they need the
repository's example files or a Dask cluster) must at least compile.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "api.md"
MARK = "<!-- test -->"


def python_blocks(text: str) -> list[tuple[bool, str]]:
    """(runnable, source) of every ```python block; runnable when the last non-blank line before it is MARK."""
    lines = text.splitlines()
    out, i = [], 0
    while i < len(lines):
        if lines[i].strip() == "```python":
            j = i - 1
            while j >= 0 and not lines[j].strip():
                j -= 1
            runnable = j >= 0 and lines[j].strip() == MARK
            k = i + 1
            while k < len(lines) and lines[k].strip() != "```":
                k += 1
            out.append((runnable, "\n".join(lines[i + 1:k]) + "\n"))
            i = k + 1
        else:
            i += 1
    return out


def test_block_extraction():
    text = "a\n<!-- test -->\n\n```python\nx = 1\n```\n```python\ny = 2\n```\n"
    assert python_blocks(text) == [(True, "x = 1\n"), (False, "y = 2\n")]


def test_every_python_block_compiles():
    blocks = python_blocks(DOC.read_text())
    assert sum(r for r, _ in blocks) >= 3, "docs/api.md should mark its runnable examples with <!-- test -->"
    for n, (_, src) in enumerate(blocks):
        compile(src, f"docs/api.md block {n}", "exec")


@pytest.fixture(scope="module")
def api_run(tmp_path_factory):
    """Run the runnable blocks of docs/api.md in order in an empty directory; (namespace, stdout, directory)."""
    work = tmp_path_factory.mktemp("api_doc")
    src = [s for r, s in python_blocks(DOC.read_text()) if r]
    ns: dict = {"__name__": "__api_doc__"}
    buf = io.StringIO()
    old = Path.cwd()
    os.chdir(work)
    try:
        with contextlib.redirect_stdout(buf):
            for n, s in enumerate(src):
                exec(compile(s, f"docs/api.md runnable block {n}", "exec"), ns)
    finally:
        os.chdir(old)
    return ns, buf.getvalue(), work


def test_complete_example_runs_and_writes_its_outputs(api_run):
    ns, out, work = api_run
    s = ns["summary"]
    assert s["status"] == "completed" and "status completed" in out
    sc = ns["scenario"]
    assert sc.simulation.end_time == pytest.approx(3e-6)                 # the --set override was applied
    assert s["steps"] > 10
    assert s["simulated_time"] == pytest.approx(3e-6, abs=2 * s["time_step"])
    d = work / "out" / "api_pulse"
    for f in ("summary.json", "resolved.toml", "monitors.csv", "energy.csv", "fracture_degree.csv"):
        assert (d / f).is_file(), f
    on_disk = json.loads((d / "summary.json").read_text())
    assert on_disk["steps"] == s["steps"] and on_disk["broken_springs"] == s["broken_springs"]


def test_complete_example_numbers_make_sense(api_run):
    ns, out, _ = api_run
    s = ns["summary"]
    fd = s["fracture_degree"]
    assert 0.0 <= fd["D"] <= 1.0
    assert fd["D"] == pytest.approx(fd["D_tensile"] + fd["D_shear"], abs=1e-12)
    assert s["broken_springs"]["total"] == s["broken_springs"]["tensile"] + s["broken_springs"]["shear"]
    assert fd["D"] == pytest.approx(s["broken_springs"]["total"] / s["counts"]["springs"], rel=1e-12)
    assert fd["near:D"] >= fd["D"]              # the annulus at the hole is more broken than the model on average
    assert abs(s["energy"]["budget_error_relative"]) < 0.05
    # the monitor 5 mm out from a 100 MPa wall pulse sees compression, weaker than the wall pressure
    peak = ns["peak_sxx"]
    assert -100e6 < peak < -1e6
    e = ns["energy"]
    assert e["external_work"][-1] > 0 and np.all(e["viscous_absorbed"] >= -1e-12)
    held = e["kinetic"][-1] + e["strain"][-1] + e["springs"][-1] + e["fracture"][-1]
    assert 0 < held <= 1.05 * e["external_work"][-1]       # the rock holds no more than the pulse put in
    t_peak = ns["mon"]["time"][ns["mon"]["m1:sxx"].argmin()]
    assert 0 < t_peak < ns["mon"]["time"][-1]                # the peak has passed the monitor within the run
    assert np.all(np.diff(ns["mon"]["time"]) > 0)
    assert re.search(r"peak radial stress at the monitor -\d+\.\d MPa", out)


def test_step_by_step_loop(api_run):
    ns, out, _ = api_run
    h = ns["history"]
    assert len(h) >= 3
    t = np.array([r[0] for r in h])
    broken = np.array([r[3] for r in h])
    D = np.array([r[4] for r in h])
    assert np.all(np.diff(t) > 0) and ns["sim"].time >= 1.5e-6 and t[-1] <= ns["sim"].time
    assert np.all(np.diff(broken) >= 0)          # springs do not heal
    assert np.all((D >= 0) & (D <= 1))
    assert all(r[1] >= 0 for r in h) and h[-1][2] > 0     # kinetic energy ≥ 0, the pulse has done work
    assert ns["u"].shape[1] == 2 and 0 < np.abs(ns["u"]).max() < 1e-3
    c = ns["cracks"]
    assert c["crushed_zone_radius_over_rb"] >= 1.0 and c["cracked_interfaces"] >= 0
    assert "largest displacement" in out and "crushed zone r_c/r_b" in out


def test_checkpoint_restart_matches_the_straight_run(api_run):
    ns, out, work = api_run
    first, rest, straight = ns["first"], ns["rest"], ns["summary"]
    assert first["steps"] == 60 and first["simulated_time"] < straight["simulated_time"]
    assert (work / "out" / "api_ckpt" / "checkpoint.npz").is_file()
    assert rest["steps"] == straight["steps"]
    assert rest["broken_springs"] == straight["broken_springs"]
    assert math.isclose(rest["simulated_time"], straight["simulated_time"], rel_tol=0, abs_tol=0)
    assert rest["energy"]["kinetic"] == straight["energy"]["kinetic"]     # bit-identical
    assert "same as the straight run: True" in out
