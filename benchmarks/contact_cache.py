"""Rock step at the cracked end state of the demo against the intact rock step (issue 14 item 2).

Runs the ``make demo`` scenario (examples/circular_rock/demo.toml) to its end time with the Python step loop (no
outputs), then times the rock step — ``CDEMSolver.forces`` + ``CDEMSolver.integrate``, gas frozen — from that
cracked state, with the block-contact fan cache on (default) and off (``BlockContact.fan_cache = False``: every
held broken face walks its vertex fan each step, the search before the cache), against the same step of a fresh,
intact Simulation of the same mesh in the same process. Block contact is on in the intact run too
(``contact.active``: a run switches it on at its first dropped spring), so that both sides pay the same terms;
the intact step without contact is printed as well.

Each configuration restarts from the same saved state, takes a few untimed steps, then ``--steps`` timed ones;
the configurations are interleaved and repeated ``--rounds`` times, and the least time per step of each is
kept, which is the least disturbed by other load on the machine. Usage::

    python benchmarks/contact_cache.py [--steps 200] [--rounds 3] [--scenario examples/circular_rock/demo.toml]
                                       [--baseline REV]   # also contact.py as it is at git revision REV
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
STATE_ARRAYS = ("x", "v", "f", "sigma", "pair_F", "pair_force", "pair_str", "pair_mode", "pair_dropped", "pair_g0",
                "pair_tbreak", "pair_inelastic", "pair_efrac", "pair_damp", "elem_damp", "elem_absorbed", "ledge_fprev",
                "pulse_values",
                "energy_acc")
CONTACT_ARRAYS = ("contact_slot", "contact_state", "elem_near", "query_after",
                  "loss_acc")


def _save(sim) -> dict:
    st, c = sim.state, sim.cdem.contact
    snap = {k: getattr(st, k).numpy().copy() for k in STATE_ARRAYS}
    snap.update({"c_" + k: getattr(c, k).numpy().copy() for k in CONTACT_ARRAYS})
    snap.update(time=sim.time, dt_prev=sim.cdem.dt_prev, clock=c._clock.numpy().copy(), active=c.active)
    return snap


def _restore(sim, snap: dict) -> None:
    st, c = sim.state, sim.cdem.contact
    for k in STATE_ARRAYS:
        getattr(st, k).assign(snap[k])
    for k in CONTACT_ARRAYS:
        getattr(c, k).assign(snap["c_" + k])
    sim.time, sim.cdem.dt_prev = snap["time"], snap["dt_prev"]
    c._clock.assign(snap["clock"])
    c.active = snap["active"]
    c._built = False                             # the hash is rebuilt at the first step


def _time_steps(sim, steps: int, warm: int = 3, graph: bool = False) -> tuple[float, float]:
    """(wall, CPU) ms per rock step (forces + integrate), after warm untimed steps. On a CPU device the kernels
    run in this thread, so the process CPU time is the cost of the step itself, little disturbed by other load.
    With ``graph`` the timed steps are replayed from a captured graph (``CDEMSolver.step_captured``; the graph is
    captured in the last warm step)."""
    import warp as wp

    st, dt, cdem = sim.state, sim.dt, sim.cdem
    for k in range(warm):
        if not (graph and k == warm - 1 and cdem.step_captured(st, dt, sim.time, sim.alpha)):
            cdem.forces(st, dt, sim.time)
            cdem.integrate(st, dt, sim.alpha)
        sim.time += dt
    wp.synchronize()
    t0, c0 = time.perf_counter(), time.process_time()
    for _ in range(steps):
        if graph:
            if not cdem.step_captured(st, dt, sim.time, sim.alpha):
                raise RuntimeError("the rock step could not be captured")
        else:
            cdem.forces(st, dt, sim.time)
            cdem.integrate(st, dt, sim.alpha)
        sim.time += dt
    wp.synchronize()
    return (time.perf_counter() - t0) / steps * 1e3, (time.process_time() - c0) / steps * 1e3


def held_counts(sim) -> dict:
    """Candidate nodes (an exposed edge at the node) of the current state, split as the contact pass sees them."""
    m, st, c = sim.model, sim.state, sim.cdem.contact
    si = m.topology.slot_iface
    mode, dropped = st.pair_mode.numpy(), st.pair_dropped.numpy()
    n = np.arange(m.node_count)
    sp = 3 * (n // 3) + (n % 3 + 2) % 3

    def exposed(s):
        q = si[s]
        qq = np.maximum(q, 0)
        return (q < 0) | ((mode[2 * qq] != 0) & (mode[2 * qq + 1] != 0))

    def is_open(s):
        q = si[s]
        qq = np.maximum(q, 0)
        return (q < 0) | (dropped[2 * qq] != 0) | (dropped[2 * qq + 1] != 0)

    cand = exposed(n) | exposed(sp)
    op = cand & (is_open(n) | is_open(sp))
    return {"nodes": int(m.node_count), "candidates": int(cand.sum()), "open": int(op.sum()),
            "held": int((cand & ~op).sum()), "contacts": int(c.active_count())}


def load_baseline(rev: str):
    """BlockContact of src/blastfrac/cdem/contact.py at git revision rev (e.g. the commit before the cache), as a
    module of the package so that its relative imports work."""
    import importlib.util
    import subprocess
    import tempfile

    src = subprocess.run(["git", "show", f"{rev}:src/blastfrac/cdem/contact.py"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    path = Path(tempfile.mkdtemp()) / "contact_baseline.py"
    path.write_text(src)
    name = "blastfrac.cdem._contact_baseline"
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    import sys

    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod.BlockContact


def run(scenario: str = "examples/circular_rock/demo.toml", steps: int = 200, rounds: int = 3,
        device: str = "cpu", baseline: str | None = None) -> dict:
    import tempfile

    import warp as wp

    from blastfrac.scenario.load import load_scenario
    from blastfrac.simulation import Simulation

    # the rock step on one thread; the demo on the 6 mm far mesh it shipped until 2026-12-02 (the reference problem)
    extra = ["geometry.mesh_size=0.006"] if scenario.endswith("circular_rock/demo.toml") else []
    sc = load_scenario(ROOT / scenario, ["simulation.threads=1", *extra])
    load0 = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        cracked = Simulation(sc, out_dir=tmp, device=device)
        t0 = time.perf_counter()
        end = sc.simulation.end_time
        while cracked.time < end * (1 - 1e-12):
            cracked.step()
        wp.synchronize()
        demo_wall = time.perf_counter() - t0
        demo_steps = cracked.steps
        counts = held_counts(cracked)
        snap_c = _save(cracked)
        intact = Simulation(sc, out_dir=tmp, device=device)
        intact.cdem.contact.active = True
        intact.dt = cracked.dt                      # the same Δt on both sides
        snap_i = _save(intact)
    # (name, simulation, its BlockContact, snapshot, fan_cache, contact active, captured graph)
    cfgs = [("intact", intact, intact.cdem.contact, snap_i, True, True, False),
            ("intact_no_contact", intact, intact.cdem.contact, snap_i, True, False, False),
            ("cracked_uncached", cracked, cracked.cdem.contact, snap_c, False, True, False),
            ("cracked_cached", cracked, cracked.cdem.contact, snap_c, True, True, False),
            ("intact_graph", intact, intact.cdem.contact, snap_i, True, True, True),
            ("cracked_graph", cracked, cracked.cdem.contact, snap_c, True, True, True)]
    if baseline:
        base = load_baseline(baseline)
        cfgs += [("baseline_intact", intact, base(intact.model), snap_i, True, True, False),
                 ("baseline_cracked", cracked, base(cracked.model), snap_c, True, True, False)]
    wall = {c[0]: np.inf for c in cfgs}
    cpu = dict(wall)
    for _ in range(rounds):
        for key, sim, contact, snap, cached, active, graph in cfgs:
            sim.cdem.contact = contact
            _restore(sim, snap)
            contact.active = active
            contact.fan_cache = cached
            w, u = _time_steps(sim, steps, graph=graph)
            wall[key], cpu[key] = min(wall[key], w), min(cpu[key], u)
    for sim, contact in ((intact, cfgs[0][2]), (cracked, cfgs[2][2])):
        sim.cdem.contact, contact.fan_cache = contact, True
    ratios = {"cached": ("cracked_cached", "intact"), "uncached": ("cracked_uncached", "intact"),
              "graph": ("cracked_graph", "intact_graph")}
    if baseline:
        ratios["baseline"] = ("baseline_cracked", "baseline_intact")
    return {"scenario": scenario, "device": device, "demo_steps": demo_steps, "demo_wall_s": demo_wall,
            "elements": cracked.model.element_count, "steps": steps, "rounds": rounds, "baseline": baseline,
            "broken_fraction": float(np.mean(snap_c["pair_mode"] != 0)),
            "dropped_fraction": float(np.mean(snap_c["pair_dropped"] != 0)), **counts,
            "ms_per_step": wall, "cpu_ms_per_step": cpu,
            "ratio": {k: wall[a] / wall[b] for k, (a, b) in ratios.items()},
            "cpu_ratio": {k: cpu[a] / cpu[b] for k, (a, b) in ratios.items()},
            "load_before": load0, "load_after": os.getloadavg(), "cpus": os.cpu_count()}


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", default="examples/circular_rock/demo.toml")
    p.add_argument("--steps", type=int, default=200)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--device", default="cpu")
    p.add_argument("--baseline", default=None, metavar="REV",
                   help="also time contact.py as it is at git revision REV (e.g. the commit before the cache)")
    a = p.parse_args(argv)
    r = run(a.scenario, a.steps, a.rounds, a.device, a.baseline)
    t, u, rw, ru = r["ms_per_step"], r["cpu_ms_per_step"], r["ratio"], r["cpu_ratio"]
    print(f"{r['scenario']}: {r['elements']:,} elements, demo {r['demo_steps']} steps in {r['demo_wall_s']:.1f} s; "
          f"end state: {100 * r['broken_fraction']:.1f} % of springs broken, {100 * r['dropped_fraction']:.2f} % "
          f"dropped; {r['candidates']:,} of {r['nodes']:,} nodes at an exposed edge, {r['held']:,} of them held, "
          f"{r['contacts']:,} in contact")
    print(f"rock step (forces + integrate), least of {r['rounds']} x {r['steps']} steps [ms/step], wall and CPU:")
    rows = [("intact, contact on", "intact", None), ("intact, contact off", "intact_no_contact", None),
            ("cracked, fan cache off", "cracked_uncached", "uncached"),
            ("cracked, fan cache on", "cracked_cached", "cached"),
            ("intact, captured graph", "intact_graph", None), ("cracked, captured graph", "cracked_graph", "graph")]
    if r["baseline"]:
        rows += [(f"intact, {r['baseline']}", "baseline_intact", None),
                 (f"cracked, {r['baseline']}", "baseline_cracked", "baseline")]
    for label, key, ratio in rows:
        line = f"  {label:28s} {t[key]:7.3f} {u[key]:7.3f}"
        if ratio:
            line += f"   cracked/intact {rw[ratio]:.2f} wall, {ru[ratio]:.2f} CPU"
        print(line)
    print(f"load average {r['load_before'][0]:.2f} before, {r['load_after'][0]:.2f} after ({r['cpus']} CPUs)")


if __name__ == "__main__":
    main()
