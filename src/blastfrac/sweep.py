"""Parameter sweeps on Dask distributed: the cases of a base scenario, one process per core (docs/sweeps.md).

A sweep file (TOML) names a base scenario and its cases::

    base = "scenario_P0.toml"          # relative to the sweep file
    output = "out/confined_sweep"      # the sweep's directory; each case writes into output/<name>

    [parameters]                       # product of the lists (names like P=..._seed=...)
    "insitu.syy" = [0.0, -15e6]
    "simulation.seed" = [0, 1]

    [[cases]]                          # and/or listed cases, each with its own scenario and overrides
    name = "P30"
    scenario = "scenario_P30.toml"     # optional, default: base
    set = { "simulation.end_time" = 60e-6 }

Overrides are the keys of ``blastfrac run --set``. Cases run as tasks on a ``distributed.LocalCluster`` with one
single-threaded worker process per core (``workers``), or on an existing scheduler (``scheduler``: the address
of a ``dask scheduler`` whose ``dask worker`` processes share this file system). A failed case is reported
with its error and does not stop the others; a case whose directory already holds a completed summary of the
same resolved scenario is skipped. The sweep writes ``sweep.csv`` (overrides and the summary figures of each
case), ``sweep.json`` and ``sweep_comparison.png``.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .scenario.errors import ScenarioError


@dataclass
class Case:
    """One run: its name, scenario file, --set overrides (key → value) and output directory."""

    name: str
    scenario: Path
    overrides: dict = field(default_factory=dict)
    out_dir: Path = Path("out")

    def override_strings(self) -> list[str]:
        import tomli_w

        return [f"{k}={tomli_w.dumps({'v': v}).split('=', 1)[1].strip()}" for k, v in self.overrides.items()]


@dataclass
class Sweep:
    path: Path
    output: Path
    cases: list[Case]


def _case_name(overrides: dict) -> str:
    parts = []
    for k, v in overrides.items():
        key = k.split(".")[-1]
        parts.append(f"{key}={v:g}" if isinstance(v, float) else f"{key}={v}")
    return "_".join(parts).replace("/", "-") or "base"


def load_sweep(path: str | Path) -> Sweep:
    """Read and check a sweep file (ScenarioError naming the key on a bad one)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise ScenarioError(f"{path}: no such file") from None
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(f"{path}: not valid TOML ({e})") from None
    unknown = set(data) - {"base", "output", "parameters", "cases"}
    if unknown:
        raise ScenarioError(f"{path}: unknown key(s) {sorted(unknown)}; a sweep has base, output, parameters, cases")
    here = path.parent
    base = data.get("base")
    output = Path(data.get("output", "out/sweep"))
    if not output.is_absolute():
        output = here / output
    cases: list[Case] = []
    params = data.get("parameters", {})
    if params:
        if base is None:
            raise ScenarioError(f"{path}: parameters: needs a base scenario (base = \"...\")")
        for k, v in params.items():
            if not isinstance(v, list) or not v:
                raise ScenarioError(f"{path}: parameters.{k}: expected a non-empty list of values")
        keys = list(params)
        for combo in itertools.product(*(params[k] for k in keys)):
            ov = dict(zip(keys, combo))
            cases.append(Case(_case_name(ov), here / base, ov))
    for i, c in enumerate(data.get("cases", [])):
        bad = set(c) - {"name", "scenario", "set"}
        if bad:
            raise ScenarioError(f"{path}: cases[{i}]: unknown key(s) {sorted(bad)}; a case has name, scenario, set")
        scen = c.get("scenario", base)
        if scen is None:
            raise ScenarioError(f"{path}: cases[{i}]: no scenario and no base")
        ov = dict(c.get("set", {}))
        cases.append(Case(str(c.get("name") or _case_name(ov)), here / scen, ov))
    if not cases:
        raise ScenarioError(f"{path}: no cases (give [parameters] or [[cases]])")
    names = [c.name for c in cases]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ScenarioError(f"{path}: case names repeat: {dup}")
    for c in cases:
        c.out_dir = output / c.name
    return Sweep(path, output, cases)


def validate_cases(sweep: Sweep) -> None:
    """Load every case's scenario with its overrides before anything runs (ScenarioError names the case)."""
    from .scenario import load_scenario

    for c in sweep.cases:
        try:
            load_scenario(c.scenario, c.override_strings())
        except ScenarioError as e:
            raise ScenarioError(f"case '{c.name}': {e}") from None


# ----------------------------------------------------------------------------- one case (runs on a worker)
def run_case(scenario: str, overrides: list[str], out_dir: str, threads: int | None = None) -> dict:
    """Run one case in this process; returns its summary (or {'status': 'failed', 'error': ...}). ``threads``, if
    given, sets simulation.threads (a sweep of several workers runs each case on one thread)."""
    from .scenario import load_scenario
    from .scenario.load import resolved_dict
    from .simulation import Simulation

    t0 = time.perf_counter()
    try:
        sc = load_scenario(scenario, overrides)
        sc.output.directory = out_dir
        sc.simulation.progress = False
        if threads is not None:
            sc.simulation.threads = threads
        done = _finished(Path(out_dir), resolved_dict(sc))
        if done is not None:
            done["skipped"] = True
            return done
        s = Simulation(sc).run(progress=False)
        s["skipped"] = False
        return s
    except Exception as e:  # noqa: BLE001 - a failed case is reported, the sweep goes on
        return {"status": "failed", "error": f"{type(e).__name__}: {e}", "wall_time_s": time.perf_counter() - t0,
                "skipped": False}


def _finished(out: Path, resolved: dict) -> dict | None:
    """The completed summary of a previous run of the same resolved scenario in ``out``, or None."""
    s, r = out / "summary.json", out / "resolved.toml"
    if not (s.is_file() and r.is_file()):
        return None
    try:
        summary = json.loads(s.read_text())
        prev = tomllib.loads(r.read_text())
    except (OSError, ValueError):
        return None
    if summary.get("status") != "completed":
        return None
    strip = lambda d: {k: v for k, v in d.items() if k != "output"}  # noqa: E731
    return summary if json.dumps(strip(prev), sort_keys=True) == json.dumps(strip(resolved), sort_keys=True) else None


# ----------------------------------------------------------------------------- the sweep
def run_sweep(sweep: Sweep | str | Path, scheduler: str | None = None, workers: int | None = None,
              progress: bool = True) -> list[dict]:
    """Run every case on Dask; returns one row per case (its overrides and summary figures)."""
    from distributed import Client, LocalCluster, as_completed

    if not isinstance(sweep, Sweep):
        sweep = load_sweep(sweep)
    validate_cases(sweep)
    sweep.output.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    cluster = None
    threads = 1                                  # the cases fill the cores: one thread each
    if scheduler:
        client = Client(scheduler)
    else:
        n = workers or os.cpu_count() or 1
        threads = None if n == 1 else 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    results: dict[str, dict] = {}
    try:
        futures = {client.submit(run_case, str(c.scenario), c.override_strings(), str(c.out_dir), threads,
                                 key=f"case-{c.name}", pure=False): c for c in sweep.cases}
        bar = _SweepProgress(len(futures), progress)
        for fut in as_completed(futures):
            c = futures[fut]
            try:
                results[c.name] = fut.result()
            except Exception as e:  # noqa: BLE001 - a worker died
                results[c.name] = {"status": "failed", "error": f"{type(e).__name__}: {e}", "skipped": False}
            bar.update(c.name, results[c.name])
        bar.close()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    wall = time.perf_counter() - t0
    rows = [case_row(c, results[c.name]) for c in sweep.cases]
    write_results(sweep, rows, wall)
    return rows


class _SweepProgress:
    """Cases done / failed / running on the terminal (rich), or nothing."""

    def __init__(self, total: int, show: bool):
        self.total, self.done, self.failed = total, 0, 0
        self.p = None
        if show:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

            self.p = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
            self.p.start()
            self.task = self.p.add_task(self._text(), total=total)

    def _text(self) -> str:
        return f"sweep: {self.done} done, {self.failed} failed, {self.total - self.done - self.failed} running/queued"

    def update(self, name: str, result: dict) -> None:
        if result.get("status") == "completed":
            self.done += 1
        else:
            self.failed += 1
        if self.p is not None:
            self.p.update(self.task, advance=1, description=self._text())
            if result.get("status") != "completed":
                self.p.console.print(f"case {name} failed: {result.get('error')}")

    def close(self) -> None:
        if self.p is not None:
            self.p.stop()


def case_row(case: Case, s: dict) -> dict:
    """Overrides and the summary figures of one case (NaN where the run gives none)."""
    row: dict = {"case": case.name, "scenario": case.scenario.name, "status": s.get("status", "failed"),
                 "skipped": bool(s.get("skipped", False)), "error": s.get("error", "")}
    row.update({f"set:{k}": v for k, v in case.overrides.items()})
    fd = s.get("fracture_degree") or {}
    row.update({f"D:{k}" if k not in ("D", "D_tensile", "D_shear", "D_crushed") else k: v for k, v in fd.items()})
    cracks = (s.get("cracks") or [{}])[0] if s.get("cracks") else {}
    for k in ("crushed_zone_radius", "dense_cracking_radius", "damaged_zone_radius", "radial_crack_count",
              "mean_radial_crack_length", "longest_radial_crack", "crack_extent_r50", "crack_extent_r80", "crack_extent_r90", "connected_crack_length"):
        row[k] = cracks.get(k, math.nan)
    e = s.get("energy") or {}
    row["budget_error_relative"] = e.get("budget_error_relative", math.nan)
    row["wall_time_s"] = s.get("wall_time_s", math.nan)
    row["steps"] = s.get("steps", math.nan)
    return row


def write_results(sweep: Sweep, rows: list[dict], wall: float) -> None:
    """sweep.csv, sweep.json (rows + sweep wall time against the sum of its cases) and the comparison figure."""
    import csv
    import io

    from .io.atomic import write_text_atomic

    cols: list[str] = []
    for r in rows:
        cols += [k for k in r if k not in cols]
    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, fieldnames=cols)
    w.writeheader()
    for r in rows:
        w.writerow({k: r.get(k, "") for k in cols})
    write_text_atomic(sweep.output / "sweep.csv", buf.getvalue())
    ran = [r["wall_time_s"] for r in rows if not r["skipped"] and isinstance(r["wall_time_s"], (int, float))
           and math.isfinite(r["wall_time_s"])]
    info = {"cases": len(rows), "completed": sum(r["status"] == "completed" for r in rows),
            "failed": [r["case"] for r in rows if r["status"] != "completed"],
            "skipped": [r["case"] for r in rows if r["skipped"]],
            "sweep_wall_time_s": wall, "sum_of_case_wall_times_s": float(sum(ran)),
            "parallel_speedup": float(sum(ran) / wall) if wall > 0 and ran else None}
    write_text_atomic(sweep.output / "sweep.json", json.dumps({"sweep": info, "rows": _nan_to_none(rows)}, indent=1))
    comparison_figure(sweep.output / "sweep_comparison.png", rows)


def _nan_to_none(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _nan_to_none(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_nan_to_none(v) for v in x]
    return x


def comparison_figure(path: Path, rows: list[dict]) -> None:
    """Fracture degree by mode and crack reach per case (completed cases)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    ok = [r for r in rows if r["status"] == "completed"]
    if not ok:
        return
    names = [r["case"] for r in ok]
    x = np.arange(len(ok))
    fig, ax = plt.subplots(1, 2, figsize=(10, 4), dpi=130)
    ax[0].bar(x - 0.2, [r.get("D_tensile", 0.0) for r in ok], 0.4, color="tab:red", label="tensile")
    ax[0].bar(x + 0.2, [r.get("D_shear", 0.0) for r in ok], 0.4, color="tab:blue", label="shear")
    ax[0].set_ylabel("fracture degree (broken springs / all) [-]")
    ax[0].legend()
    for k, lab in (("crack_extent_r50", "r50"), ("crack_extent_r80", "r80"), ("crack_extent_r90", "r90")):
        ax[1].plot(x, [1e3 * r.get(k, math.nan) for r in ok], "o-", label=lab)
    ax[1].set_ylabel("crack reach about the hole [mm]")
    ax[1].legend()
    for a in ax:
        a.set_xticks(x, names, rotation=30, ha="right")
    fig.suptitle("sweep: whole-model fracture degree by mode, and the radii within which 50/80/90 % of the "
                 "connected crack length lies", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
