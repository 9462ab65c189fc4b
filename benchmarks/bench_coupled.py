"""The coupled blast step as a user runs it (issue 14 item 5): `blastfrac bench --only coupled`.

For the demo (examples/circular_rock/demo.toml) and the confined example at P = 0, outputs off:

* the whole run: steps, wall time, element-steps/s and particle-steps/s;
* per stage, at the intact start and at the cracked end state (``steps`` timed steps each, synchronised per
  stage): rock forces (springs, CST, loads, block contact), particle–edge contact, crack gas (when on), P2G and
  grid update, rock integration, G2P, burn and EOS, and the ``wp.launch`` calls per step;
* the whole run again pinned to one core (``taskset -c 0``, in a subprocess) against both cores;
* the shipped confined P0 (113,690 blocks) over its first steps on one core and on two threads (``two_cores``).

``--reference DIR`` (run_reference) builds ``../shared/bench-reference`` in a scratch copy and runs its C++
float64 CDEM and MPM loops on one thread beside blastfrac's CDEM and MPM benchmarks at the same sizes; the
ratio is blastfrac ÷ reference per element-step (particle-step).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASES = {"demo": ("examples/circular_rock/demo.toml", ["geometry.mesh_size=0.006"]),
         # issue 14's reference problem: confined P0 on the mesh it shipped until stop 23 (10 mm beyond the
         # refinement zone, 8,514 blocks); the example itself now ships 2.5 mm (113,690 blocks, mesh_study.md)
         # (and without the example's fracture band since stop 25, so that the figures compare across sessions)
         "confined_P0": ("examples/confined_blast/scenario_P0.toml", ["geometry.mesh_size=0.01",
                                                                      "rock.fracture_band_width=0"]),
         # the same with the gas in the cracks (off by default; its cost: docs/scenario.md, [crack_gas])
         "confined_P0_crack_gas": ("examples/confined_blast/scenario_P0.toml", ["geometry.mesh_size=0.01",
                                                                                "rock.fracture_band_width=0",
                                                                                "crack_gas.enabled=true"])}
QUIET = ["output.paraview=false", "output.figures=false", "simulation.progress=false"]


def _sim(path: str, extra: list[str], device: str, out: str):
    from blastfrac.scenario import load_scenario
    from blastfrac.simulation import Simulation

    sc = load_scenario(ROOT / path, QUIET + extra)
    return Simulation(sc, out_dir=out, device=device)


def stage_times(sim, steps: int) -> dict:
    """Seconds per step of each stage over ``steps`` steps (the step's own order), and launches per step."""
    import warp as wp

    st, dt = sim.state, sim.dt
    T: dict[str, float] = {}
    count = [0]
    launch = wp.launch

    def counting(*a, **k):
        count[0] += 1
        return launch(*a, **k)

    def tm(name, f):
        t0 = time.perf_counter()
        f()
        wp.synchronize()
        T[name] = T.get(name, 0.0) + time.perf_counter() - t0

    # launches replayed by the stages' recorders (_warp.Launcher) count too
    launchers = [o for o in (sim.cdem.launch, getattr(sim.cdem.contact, "_launch", None),
                             getattr(sim.gas, "_launch", None), getattr(sim.coupler, "_launch", None),
                             getattr(sim.crack_gas, "_launch", None)) if o is not None]
    replays0 = sum(o.replays for o in launchers)
    wp.launch = counting
    try:
        for _ in range(steps):
            tm("rock forces", lambda: sim.cdem.forces(st, dt, sim.time))
            if sim.gas is not None:
                tm("particle-edge contact", lambda: (sim.coupler.apply(st, dt), sim.coupler.add_reactions(st)))
                if sim.wall_load is not None:
                    tm("wall load", lambda: sim.wall_load.accumulate(sim.coupler.f_react, dt))
                if sim.crack_gas is not None:
                    tm("crack gas", lambda: (sim.crack_gas.apply(st, dt), sim.crack_gas.add_loads(st)))
                tm("P2G + grid", lambda: (sim.gas.to_grid(dt), sim.gas.update_grid(dt)))
            tm("rock integrate + PPV", lambda: sim.cdem.integrate(st, dt, sim.alpha))
            if sim.gas is not None:
                tm("G2P", lambda: sim.gas.to_particles(dt))
                tm("burn + EOS", lambda: sim.gas.update_eos(dt, sim.time))
            sim.time += dt
            sim.steps += 1
    finally:
        wp.launch = launch
    out = {k: v / steps for k, v in T.items()}
    out["total"] = sum(out.values())
    out["launches_per_step"] = (count[0] + sum(o.replays for o in launchers) - replays0) / steps
    return out


def run_case(name: str, device: str = "cpu", steps: int = 100) -> dict:
    path, extra = CASES[name]
    with tempfile.TemporaryDirectory() as tmp:
        sim = _sim(path, extra, device, tmp)
        intact = stage_times(_sim(path, extra, device, tmp + "/i"), steps)
        t0 = time.perf_counter()
        s = sim.run(progress=False)
        wall = time.perf_counter() - t0
        cracked = stage_times(sim, steps)
    c = s["counts"]
    return {"case": name, "elements": c["elements"], "particles": c["particles"], "steps": s["steps"],
            "run_wall_s": s["wall_time_s"], "with_setup_s": wall,
            "element_steps_per_s": c["elements"] * s["steps"] / s["wall_time_s"],
            "particle_steps_per_s": c["particles"] * s["steps"] / s["wall_time_s"],
            "intact_ms": {k: 1e3 * v for k, v in intact.items() if k != "launches_per_step"},
            "cracked_ms": {k: 1e3 * v for k, v in cracked.items() if k != "launches_per_step"},
            "launches_per_step": cracked["launches_per_step"], "broken_springs": s["broken_springs"]["total"]}


def fixed_cost(device: str = "cpu", steps: int = 400) -> dict:
    """The size-independent cost of a coupled step (issue 14 item 1): the demo's step on a 56-element, 20-point
    version of it (4 cm disc, 1 cm mesh, 2 mm cells, one point per cell), against the demo's own step, both on one
    thread, over the ``steps`` steps after the first 50 (wall time); the tiny step on two threads (what the
    second thread's hand-offs cost) and replayed from a captured graph (``simulation.graph = 'on'``: on a GPU the
    step's launch cost, on a CPU Warp's replay of the recorded operations against the Launcher's)."""
    import tomllib

    from blastfrac.scenario import scenario_from_dict
    from blastfrac.simulation import Simulation

    base = tomllib.loads((ROOT / CASES["demo"][0]).read_text())
    base["output"].update(paraview=False, figures=False)
    base["simulation"]["progress"] = False
    tiny = json.loads(json.dumps(base))
    tiny["monitors"][0]["position"] = [0.01, 0.0]
    tiny["zones"] = tiny["zones"][:2]
    tiny["geometry"].update(domain={"type": "disc", "radius": 0.02}, mesh_size=0.01, mesh_size_near=0.004,
                            refinement_distance=0.01)
    tiny["explosive"]["grid"].update(cell_size=0.002, points_per_cell=1, bounds=[[-0.03, -0.03], [0.03, 0.03]])
    out = {}
    tiny2 = json.loads(json.dumps(tiny))
    tiny2["simulation"]["threads"] = 2
    for d in (tiny, base):
        d["simulation"]["threads"] = 1                     # the launches' cost; the second thread's hand-offs apart
        d["simulation"]["graph"] = "off"
    tiny_g = json.loads(json.dumps(tiny))
    tiny_g["simulation"]["graph"] = "on"
    with tempfile.TemporaryDirectory() as tmp:
        for name, d in (("tiny", tiny), ("demo", base), ("tiny_2threads", tiny2), ("tiny_graph", tiny_g)):
            sim = Simulation(scenario_from_dict(d), out_dir=tmp, device=device)
            for _ in range(50):
                sim.step()
            t0 = time.perf_counter()
            for _ in range(steps):
                sim.step()
            out[name + "_ms"] = (time.perf_counter() - t0) / steps * 1e3
            out[name + "_size"] = (sim.model.element_count, sim.gas.n)
            out[name + "_replayed"] = sim.coupled_graph_steps
    out["fraction"] = out["tiny_ms"] / out["demo_ms"]
    out["steps"] = steps
    return out


def one_core_wall(name: str, device: str = "cpu") -> float | None:
    """Run-loop wall time of a case pinned to one core (taskset), in a subprocess; None without taskset."""
    if shutil.which("taskset") is None:
        return None
    path, extra = CASES[name]
    code = ("import json,sys,tempfile; sys.path.insert(0, %r); import bench_coupled as b\n"
            "with tempfile.TemporaryDirectory() as t:\n"
            "    s = b._sim(%r, %r, %r, t).run(progress=False)\n"
            "print('WALL', s['wall_time_s'])") % (str(Path(__file__).parent), path, extra, device)
    r = subprocess.run(["taskset", "-c", "0", sys.executable, "-c", code], capture_output=True, text=True)
    for line in r.stdout.splitlines():
        if line.startswith("WALL"):
            return float(line.split()[1])
    return None


#: issue 14 item 3's problem: the confined example as shipped (113,690 blocks, 2.5 mm beyond the refinement zone)
SHIPPED_P0 = "examples/confined_blast/scenario_P0.toml"


def two_cores(steps: int = 1500, device: str = "cpu") -> dict | None:
    """The shipped confined P0 over ``steps`` steps (after 20 untimed ones, outputs off), once pinned to one core
    with ``simulation.threads = 1`` (taskset) and once on both cores with ``threads = 2``, each in a subprocess;
    seconds per step and the speed-up. None without taskset or on a GPU."""
    if shutil.which("taskset") is None or device != "cpu":
        return None
    code = ("import sys,time,tempfile; sys.path.insert(0, %r); import bench_coupled as b\n"
            "with tempfile.TemporaryDirectory() as t:\n"
            "    sim = b._sim(%r, ['simulation.threads=' + sys.argv[1]], 'cpu', t)\n"
            "    [sim.step() for _ in range(20)]\n"
            "    t0 = time.perf_counter()\n"
            "    [sim.step() for _ in range(%d)]\n"
            "    print('STEP', (time.perf_counter() - t0) / %d, sim.model.element_count)\n"
            "    print('CHOSE', *[t['chose'] for t in (sim._second.report()['trials'] if sim._second else [])])") % (
        str(Path(__file__).parent), SHIPPED_P0, steps, steps)
    out = {"steps": steps}
    for key, pre, threads in (("one_core", ["taskset", "-c", "0"], "1"), ("two_threads", [], "2")):
        r = subprocess.run([*pre, sys.executable, "-c", code, threads], capture_output=True, text=True)
        line = [ln for ln in r.stdout.splitlines() if ln.startswith("STEP")]
        if not line:
            return None
        out[key + "_s"], out["elements"] = float(line[0].split()[1]), int(line[0].split()[2])
        if threads == "2":                   # the threads each of the run's trials chose (second_thread.py)
            chose = [ln for ln in r.stdout.splitlines() if ln.startswith("CHOSE")]
            out["trials_chose"] = [int(c) for c in chose[0].split()[1:]] if chose else []
    out["speedup"] = out["one_core_s"] / out["two_threads_s"]
    return out


def markdown(rows: list[dict]) -> str:
    out = ["| case | elements | particles | steps | run wall [s] | 1 core [s] | element-steps/s | particle-steps/s "
           "| launches/step | step intact [ms] | step cracked [ms] |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        one = r.get("one_core_wall_s")
        one_txt = f"{one:.1f}" if one else "-"
        out.append(f"| {r['case']} | {r['elements']:,} | {r['particles']:,} | {r['steps']:,} | {r['run_wall_s']:.1f} "
                   f"| {one_txt} | {r['element_steps_per_s']:.3e} | {r['particle_steps_per_s']:.3e} "
                   f"| {r['launches_per_step']:.1f} | {r['intact_ms']['total']:.2f} | {r['cracked_ms']['total']:.2f} |")
    stages = sorted({k for r in rows for k in r["cracked_ms"] if k != "total"})
    out += ["", "Per stage [ms/step], intact start / cracked end:", "| stage | " + " | ".join(r["case"] for r in rows) + " |",
            "|---|" + "---:|" * len(rows)]
    for k in stages:
        out.append(f"| {k} | " + " | ".join(f"{r['intact_ms'].get(k, 0):.3f} / {r['cracked_ms'].get(k, 0):.3f}"
                                            for r in rows) + " |")
    return "\n".join(out)


# ----------------------------------------------------------------------------- compiled reference
def run_reference(src: Path, steps: int = 20, device: str = "cpu", rounds: int = 5) -> list[dict]:
    """Build the C++ reference in a scratch copy and compare blastfrac's CDEM and MPM kernels, and the reference's
    own algorithm in Warp (benchmarks/reference_port.py), with it, per unit-step, one thread each.

    Interleaved, so that a shared machine's changing load falls on all three alike: each of ``rounds`` rounds runs
    one repetition of the C++ program (its own timing: reset, its 50 / 20 steps), then a block of ``steps`` of
    blastfrac's steps, then one repetition of the port; each round gives its ratios, and a row holds their median
    and range. (Timed one after the other, five repetitions each, two runs on the same VM gave Warp ÷ g++ of 1.25
    and 0.96 for the same MPM loop, benchmarks/RESULTS.md, stop 32.)"""
    sys.path.insert(0, str(Path(__file__).parent))
    import bench_cdem
    import bench_mpm
    import reference_port

    dst = reference_port.build(src)
    problems = [("CDEM", ["cdem"], "colour", lambda: bench_cdem.timer(200_000, device), "cdem", 0)]
    problems += [("MPM", ["mpm", str(n)], "private", lambda n=n: bench_mpm.timer(n, device), "mpm", n)
                 for n in (100_000, 400_000)]
    rows = []
    try:
        for loop, cpp_args, scatter, make_blastfrac, kind, n in problems:
            b_info, b_block = make_blastfrac()
            p_info, p_block, p_checks = reference_port.port_timer(dst, kind, n, device)
            per_unit = {"cpp": [], "blastfrac": [], "port": []}     # seconds per unit-step, each round
            rel = None
            for r in range(rounds):
                cpp = reference_port.cpp_once(dst, cpp_args, scatter)
                per_unit["cpp"].append(1.0 / cpp["units_steps_per_s"])
                per_unit["blastfrac"].append(b_block(steps) / steps / b_info["units"])
                nst = int(cpp["nsteps"])
                per_unit["port"].append(p_block(nst) / nst / p_info["units"])
                if r == 0:                       # the port's state after one repetition against the C++ run's
                    chk, ref = p_checks(), cpp["checks"]
                    rel = max(abs(chk[k] - ref[k]) / max(abs(ref[k]), 1e-300) for k in chk)
            t = {k: np.array(v) for k, v in per_unit.items()}
            for who, size in (("blastfrac", b_info["units"]), ("port", p_info["units"])):
                ratio = t[who] / t["cpp"]
                rows.append({"loop": loop if who == "blastfrac" else f"{loop}, the reference's algorithm in Warp",
                             "size": size, "blastfrac_per_s": 1.0 / float(np.median(t[who])),
                             "reference_per_s": 1.0 / float(np.median(t["cpp"])),
                             "ratio_time_per_unit": float(np.median(ratio)),
                             "ratio_range": [float(ratio.min()), float(ratio.max())],
                             "algorithm_ratio": float(np.median(t["blastfrac"] / t["port"])), "rounds": rounds,
                             "reference": {"checks_max_rel_diff": rel, "cpp_last": cpp}})
    finally:
        shutil.rmtree(dst.parent, ignore_errors=True)
    return rows


def reference_markdown(rows: list[dict]) -> str:
    out = [("| loop | blastfrac size | blastfrac units-steps/s | C++ f64 1 thread units-steps/s "
            "| blastfrac ÷ C++ per unit-step: median (range) of the rounds |"),
           "|---|---:|---:|---:|---:|"]
    for r in rows:
        lo, hi = r["ratio_range"]
        out.append(f"| {r['loop']} | {r['size']:,} | {r['blastfrac_per_s']:.3e} | {r['reference_per_s']:.3e} "
                   f"| {r['ratio_time_per_unit']:.2f} ({lo:.2f}–{hi:.2f}) |")
    out.append("")
    out.append(f"Interleaved: each of {rows[0]['rounds']} rounds runs one repetition of the C++ program, a block of "
               "blastfrac's steps and one repetition of the port, and gives its own ratios (run_reference).")
    for loop, unit in (("CDEM", "element"), ("MPM", "particle")):
        fulls = [r for r in rows if r["loop"] == loop]
        ports = [r for r in rows if r["loop"].startswith(f"{loop}, the reference")]
        for full, port in zip(fulls, ports):
            out.append(f"{loop} ({full['size']:,}) per {unit}-step: blastfrac ÷ C++ {full['ratio_time_per_unit']:.2f}; "
                       f"blastfrac's algorithm ÷ the reference's, both in Warp, {full['algorithm_ratio']:.2f}; "
                       f"Warp ÷ g++ on one algorithm {port['ratio_time_per_unit']:.2f} (the port's state after one "
                       f"repetition matches the C++ run's checks to {port['reference']['checks_max_rel_diff']:.1e}, "
                       "relative)")
    return "\n".join(out)
