"""Issue 14 item 6 in one run, for a session that has a CUDA GPU: its throughput and run-time figures, and whether the
GPU's runs agree with the CPU's.

    python benchmarks/gpu_check.py [--device cuda:0] [--out DIR] [--steps 50] [--quick] [--skip-cpu] [--large]

1. CDEM throughput at 1 M elements (1.15 M: building the model takes ~40 s on one core), all rock terms on
   (``bench_cdem.run``); target ≥ 1e9 element-steps/s at ≥ 1 M elements. ``--large`` adds 2 M.
2. MPM throughput at 1.6 M points, the full MUSL step (``bench_mpm.run``); target ≥ 5e8 particle-steps/s.
   ``--large`` adds 6.4 M.
3. The demo and issue 14's confined P0 reference problem (``bench_coupled.CASES``), whole runs, outputs off: on the
   GPU with the coupled steps captured (``simulation.graph = 'on'``) and through the launches (``'off'``), and on
   the CPU (two threads); run wall [s] (target for P0 < 3 s), and the agreement of each GPU run with the CPU's:
   fracture degree D within 2 % (relative), the energy budget within 1 % (each energy term's difference as a share
   of the explosive energy released, and the budget errors' difference).

On a lent machine (``../.library/device``), which lacks Warp, gmsh and pydantic and carries 64 MiB a call, the
dependencies travel in parts (``benchmarks/gpu_pack.py``) and ``benchmarks/gpu_device.sh`` unpacks them and runs this
with ``--skip-cpu``; ``--compare JSON`` then runs the CPU side of the same cases on the developer's machine and
writes the agreement, so that no device time goes to CPU runs.

The GPU's atomics add in another order than the CPU's, and fracture amplifies round-off, so the runs are compared by
these measures, not to the bit. Writes DIR/gpu_check.json and DIR/gpu_check.md (default DIR: $OUT, else
out/gpu_check) after each part (MPM first, which needs no mesh; then CDEM and each run), so that a call cut off by
its time limit brings back what it measured, and prints the markdown. A part that fails is recorded in the files
(``errors``) and the others still run; the exit status is then 1. ``--quick``: small sizes and short runs, to try
the script (on a CPU with ``--device cpu``). Kernels compile on first use (a minute or two on a fresh machine: the CUDA compile of the
block-contact kernels alone takes ~50 s through NVRTC).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
import traceback
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_cdem
import bench_coupled
import bench_mpm

TERMS = ("kinetic", "strain", "springs", "fracture", "friction", "damping", "gas_internal", "gas_kinetic",
         "contact_energy", "viscous_absorbed")


def _run_case(name: str, device: str, graph: str, threads: int, max_steps: int | None) -> dict:
    path, extra = bench_coupled.CASES[name]
    extra = extra + [f"simulation.graph={graph}", f"simulation.threads={threads}"]
    with tempfile.TemporaryDirectory() as tmp:
        sim = bench_coupled._sim(path, extra, device, tmp)
        if max_steps:
            sim.max_steps = max_steps
        t0 = time.perf_counter()
        s = sim.run(progress=False)
        wall = time.perf_counter() - t0
    return {"case": name, "device": device, "graph": graph, "threads": threads, "steps": s["steps"],
            "run_wall_s": s["wall_time_s"], "with_setup_s": wall, "elements": s["counts"]["elements"],
            "particles": s["counts"]["particles"], "D": s["fracture_degree"]["D"], "energy": s["energy"],
            "graph_report": s.get("graph"), "warnings": s.get("warnings", [])}


def agreement(cpu: dict, other: dict) -> dict:
    """D's relative difference, each energy term's difference over the explosive energy released, and the budget
    errors' difference (both relative to what was put in)."""
    e0, e1 = cpu["energy"], other["energy"]
    released = max(abs(e0.get("explosive_released", 0.0)), 1e-300)
    terms = {k: (e1.get(k, 0.0) - e0.get(k, 0.0)) / released for k in TERMS if k in e0}
    worst = max(terms, key=lambda k: abs(terms[k]))
    out = {"D_rel": (other["D"] - cpu["D"]) / cpu["D"] if cpu["D"] else 0.0,
           "worst_term": worst, "worst_term_share": terms[worst],
           "budget_diff": e1["budget_error_relative"] - e0["budget_error_relative"]}
    out["ok"] = abs(out["D_rel"]) <= 0.02 and abs(out["worst_term_share"]) <= 0.01 and abs(out["budget_diff"]) <= 0.01
    return out


def gpu_pairs(case: str, gpu: list[dict]) -> list[dict]:
    """The GPU's captured run against its run through the launches, by the same measures: what the GPU's own
    nondeterminism (atomic sums in any order, docs/scenario.md "Graphs") spreads a case by, against which the
    CPU–GPU differences are read. No device time: both runs are made anyway."""
    by = {r["graph"]: r for r in gpu}
    if "on" not in by or "off" not in by:
        return []
    return [{"case": case, "graph": "on vs off (both GPU)", **agreement(by["off"], by["on"])}]


def markdown(res: dict) -> str:
    lines = [f"GPU check on {res['device_name']} ({res['device']}), Warp {res['warp']}, {res['date']}", ""]
    for e in res.get("errors", []):
        lines += [f"**{e['stage']} failed**: {e['error']}", ""]
    for key, unit in (("cdem", "element-steps/s"), ("mpm", "particle-steps/s")):
        lines += [f"| {key.upper()} size | steps | wall [s] | {unit} |", "|---:|---:|---:|---:|"]
        for r in res.get(key, []):
            n = r.get("elements", r.get("n_particles"))
            rate = r.get("element_steps_per_s", r.get("particle_steps_per_s"))
            lines.append(f"| {n:,} | {r['steps']} | {r['wall_s']:.3f} | {rate:.3e} |")
        lines.append("")
    lines += ["| case | device | graph | threads | steps | run wall [s] | D | budget error | coupled steps replayed |",
              "|---|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in res["runs"]:
        g = r["graph_report"] or {}
        lines.append(f"| {r['case']} | {r['device']} | {r['graph']} | {r['threads']} | {r['steps']} | "
                     f"{r['run_wall_s']:.2f} | {r['D']:.4f} | {r['energy']['budget_error_relative']:.3%} | "
                     f"{g.get('coupled_steps_replayed', 0)} |")
    lines += ["", ("| case | GPU run | D vs CPU ('on vs off': vs the other GPU run) | worst energy term (share of "
                   "released) | budget error diff | within 2 % / 1 % |"), "|---|---|---:|---|---:|---|"]
    for a in res["agreement"]:
        lines.append(f"| {a['case']} | graph {a['graph']} | {a['D_rel']:+.2%} | {a['worst_term']} "
                     f"{a['worst_term_share']:+.3%} | {a['budget_diff']:+.3%} | {'yes' if a['ok'] else 'NO'} |")
    return "\n".join(lines)


def compare(gpu_json: Path, out: Path) -> int:
    """The CPU side of the agreement check, run on this machine after a GPU session (gpu_device.sh ran the GPU side
    with --skip-cpu, at the device's expense only for the GPU): each case of the GPU run on the CPU (two threads, the
    same step limit), then the agreement table; writes OUT/gpu_check.json and OUT/gpu_check.md."""
    res = json.loads(gpu_json.read_text())
    quick = bool(res.get("quick", False))
    device_runs = list(res["runs"])                 # every run of the file was made on the device (--skip-cpu)
    for case in dict.fromkeys(r["case"] for r in device_runs):
        gpu = [r for r in device_runs if r["case"] == case]
        cpu = _run_case(case, "cpu", "auto", 2, 300 if quick else None)
        cpu["host"] = platform.node()
        res["runs"].append(cpu)
        res["agreement"] += [{"case": case, "graph": r["graph"], **agreement(cpu, r)} for r in gpu]
        res["agreement"] += gpu_pairs(case, gpu)
    save(res, out)
    print(markdown(res))
    return 0 if all(a["ok"] for a in res["agreement"]) else 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--device", default="cuda:0")
    ap.add_argument("--out", default=os.environ.get("OUT") or "out/gpu_check")
    ap.add_argument("--steps", type=int, default=50, help="timed steps of the throughput benchmarks")
    ap.add_argument("--quick", action="store_true", help="small sizes, 300-step runs (to try the script)")
    ap.add_argument("--skip-cpu", action="store_true", help="no CPU runs (no agreement check)")
    ap.add_argument("--large", action="store_true", help="also 2 M elements and 6.4 M points")
    ap.add_argument("--compare", metavar="JSON", default=None,
                    help="a GPU run's gpu_check.json (made with --skip-cpu on the device): run its cases on this "
                         "machine's CPU and write the agreement beside the GPU figures in --out")
    args = ap.parse_args(argv)
    if args.compare:
        return compare(Path(args.compare), Path(args.out))
    import warp as wp

    from blastfrac._warp import init_warp, resolve_device

    init_warp()
    device = resolve_device(args.device)
    res = {"device": device, "device_name": wp.get_device(device).name, "warp": wp.__version__,
           "date": time.strftime("%Y-%m-%d %H:%M"), "host": platform.node(), "runs": [], "agreement": [],
           "errors": [], "quick": args.quick, "cdem": [], "mpm": []}
    out = Path(args.out)
    t0 = time.perf_counter()

    def stage(name: str, fn) -> None:
        """Run one part of the check; a failure is recorded and the others still run. The results so far are
        written after each part, so that a call cut off by its time limit still brings back what it measured."""
        try:
            fn()
        except Exception as err:                    # noqa: BLE001 (a lent GPU's minutes: keep what the rest gives)
            res["errors"].append({"stage": name, "error": f"{type(err).__name__}: {err}",
                                  "traceback": traceback.format_exc()[-4000:]})
            print(f"{name} FAILED: {type(err).__name__}: {err}", flush=True)
        save(res, out)
        print(f"{name} done at {time.perf_counter() - t0:.0f} s", flush=True)

    big = args.large and not args.quick
    # MPM first: it builds no mesh, so it measures even where gmsh cannot run
    stage("mpm", lambda: res["mpm"].extend(
        bench_mpm.run((40_000,) if args.quick else (1_600_000, 6_400_000)[: 1 + big], args.steps, device)))
    stage("cdem", lambda: res["cdem"].extend(
        bench_cdem.run((20_000,) if args.quick else (1_000_000, 2_000_000)[: 1 + big], args.steps, device)))
    max_steps = 300 if args.quick else None
    for case in ("demo", "confined_P0"):
        for g in ("on", "off"):
            stage(f"{case} graph {g}", lambda case=case, g=g: res["runs"].append(_run_case(case, device, g, 1,
                                                                                              max_steps)))
        if not args.skip_cpu:
            def on_cpu(case=case):
                cpu = _run_case(case, "cpu", "auto", 2, max_steps)
                res["runs"].append(cpu)
                gpu = [r for r in res["runs"] if r["case"] == case and r["device"] == device and r is not cpu]
                res["agreement"] += [{"case": case, "graph": r["graph"], **agreement(cpu, r)} for r in gpu]
                res["agreement"] += gpu_pairs(case, gpu)
            stage(f"{case} cpu", on_cpu)
    print(markdown(res))
    return 1 if res["errors"] else 0


def save(res: dict, out: Path) -> None:
    """OUT/gpu_check.json and OUT/gpu_check.md as they stand."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "gpu_check.json").write_text(json.dumps(res, indent=1, default=str))
    (out / "gpu_check.md").write_text(markdown(res) + "\n")


if __name__ == "__main__":
    sys.exit(main())
