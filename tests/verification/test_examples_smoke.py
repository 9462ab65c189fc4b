"""Every shipped scenario is valid and runs a few steps through the CLI (the full runs: make validate)."""

import json
from pathlib import Path

import pytest

from blastfrac.cli import main

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "examples").glob("*/*.toml")
                   if p.parent.name != "calibration" and not p.name.startswith("sweep"))
SWEEPS = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "examples").glob("*/sweep*.toml"))


@pytest.mark.parametrize("path", SCENARIOS)
def test_example_runs_a_few_steps(path, tmp_path):
    args = ["run", str(ROOT / path), "--out", str(tmp_path), "--max-steps", "3",
            "--set", "simulation.progress=false", "--set", "output.figures=false", "--set", "insitu.max_steps=400"]
    assert main(args) == 0
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["steps"] == 3
    assert s["counts"]["elements"] > 1000
    assert (tmp_path / "resolved.toml").exists()


@pytest.mark.parametrize("path", SWEEPS)
def test_shipped_sweeps_are_valid(path):
    """Every case of a shipped sweep loads and validates (the sweep itself: make validate / blastfrac sweep)."""
    from blastfrac.sweep import load_sweep, validate_cases

    sw = load_sweep(ROOT / path)
    validate_cases(sw)
    assert len(sw.cases) >= 2
