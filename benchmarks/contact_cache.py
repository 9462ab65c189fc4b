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
                                       [--where]          # also each kernel, and the contact pass by node class
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


def kernel_times(sim, snap: dict, steps: int) -> dict[str, float]:
    """ms per step of each kernel of the rock step (forces + integrate) from the state ``snap``, each launch timed
    on its own (a CPU launch returns once its kernel has run; on a GPU these would be launch times, not kernel
    times)."""
    from collections import defaultdict

    import warp as wp

    from blastfrac import _warp as bw

    _restore(sim, snap)
    sim.cdem.contact.active = True
    _time_steps(sim, 3, warm=0)                  # the records and the hash of this state, untimed
    acc: dict[str, float] = defaultdict(float)
    replay0, launch0 = bw.Launcher._replay, wp.launch

    def replay(self, rec):
        t = time.perf_counter()
        replay0(self, rec)
        acc[rec[0].kernel.key] += time.perf_counter() - t

    def launch(kernel, *a, **k):
        t = time.perf_counter()
        out = launch0(kernel, *a, **k)
        if not k.get("record_cmd"):
            acc[kernel.key] += time.perf_counter() - t
        return out

    bw.Launcher._replay, wp.launch = replay, launch
    try:
        _time_steps(sim, steps, warm=0)
    finally:
        bw.Launcher._replay, wp.launch = replay0, launch0
    return {k: v / steps * 1e3 for k, v in sorted(acc.items(), key=lambda kv: -kv[1])}


def _woken(elem_near: np.ndarray, step: int, window: int) -> np.ndarray:
    """contact_fan.node_woken of every element, in NumPy."""
    from blastfrac.cdem.contact_fan import WAKE_FLAG

    v = elem_near.astype(np.int64)
    flagged = v >= WAKE_FLAG
    base = np.where(flagged, v - WAKE_FLAG, v)
    return np.where(flagged & (base == step), True,
                    np.where(~flagged & (v == step), False, (base >= step - window) & (base < step)))


PASS_ARRAYS = ("contact_slot", "contact_state", "elem_near", "query_after", "loss_acc")


def pass_by_class(sim, snap: dict, reps: int = 30) -> list[tuple[str, int, float]]:
    """The contact pass (eval_block_contact) of the state ``snap`` over its listed nodes, all and by what each
    does (contact_kernels.node_contact): an open node searching the hash, an open one that is quiet (its own
    vertex only), a held node whose block is woken (a hash search over every edge near it), a held one in
    contact, a held one listed without contact. Each class is run as a list of its own, ``reps`` times from the
    same contact history; (class, nodes, median ms a pass less that of an empty list, the launch's own cost,
    which is the first row)."""
    import warp as wp

    from blastfrac.cdem.contact_kernels import eval_block_contact

    _restore(sim, snap)
    c, st = sim.cdem.contact, sim.state
    c.active = True
    # the last of these steps' passes is timed again, from the contact history it left (its quiet windows too, so
    # the classes below are what the timed passes do)
    _time_steps(sim, 3, warm=0)
    listed = c._node_list.numpy()[: int(c._counts.numpy()[1])].copy()
    step = int(c._clock.numpy()[0])
    flag = c.node_flag.numpy()[listed]
    in_contact = c.contact_slot.numpy()[listed] >= 0
    woken = _woken(c.elem_near.numpy(), step, int(c.near_window))[listed // 3]
    searching = woken | (c.query_after.numpy()[listed] <= step) | in_contact
    classes = [("none (the launch itself)", np.zeros(len(listed), bool)),
               ("all listed", np.ones(len(listed), bool)),
               ("open, searching the hash", (flag == 2) & searching),
               ("open, quiet", (flag == 2) & ~searching),
               ("held, block woken", (flag == 1) & woken),
               ("held, in contact", (flag == 1) & ~woken & in_contact),
               ("held, no contact", (flag == 1) & ~woken & ~in_contact)]
    keep = {k: getattr(c, k).numpy().copy() for k in PASS_ARRAYS}
    f0, e0 = st.f.numpy().copy(), st.energy_acc.numpy().copy()
    prm = c._params()
    out = []
    for name, mask in classes:
        sub = wp.array(listed[mask].astype(np.int32), dtype=wp.int32, device=st.x.device)
        counts = wp.array([0, int(mask.sum())], dtype=wp.int32, device=st.x.device)
        times = []
        for _ in range(reps):
            for k, a in keep.items():
                getattr(c, k).assign(a)
            wp.synchronize()
            t = time.perf_counter()
            wp.launch(eval_block_contact, dim=1, inputs=[sub, counts, 0, 1, 1, c.s_mesh, c.s_hash, c.s_cache,
                                                         c.s_hist, prm, st.pair_mode, st.pair_dropped, st.x, st.v,
                                                         c._clock, float(sim.dt), c.s_rec, st.f, st.energy_acc],
                      device=st.x.device)
            wp.synchronize()
            times.append(time.perf_counter() - t)
        ms = float(np.median(times)) * 1e3
        out.append((name, int(mask.sum()), ms - (out[0][2] if out else 0.0)))
    st.f.assign(f0)
    st.energy_acc.assign(e0)
    _restore(sim, snap)
    return out


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
        device: str = "cpu", baseline: str | None = None, where: bool = False) -> dict:
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
    split = {}
    if where and device == "cpu":                # where the cracked step's extra time goes (CPU only)
        split = {"kernels": {"intact": kernel_times(intact, snap_i, steps),
                             "cracked": kernel_times(cracked, snap_c, steps)},
                 "pass_classes": pass_by_class(cracked, snap_c)}
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
            "load_before": load0, "load_after": os.getloadavg(), "cpus": os.cpu_count(), **split}


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", default="examples/circular_rock/demo.toml")
    p.add_argument("--steps", type=int, default=200)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--device", default="cpu")
    p.add_argument("--baseline", default=None, metavar="REV",
                   help="also time contact.py as it is at git revision REV (e.g. the commit before the cache)")
    p.add_argument("--where", action="store_true",
                   help="also time each kernel of the intact and the cracked rock step, and the cracked state's "
                        "contact pass by what its listed nodes do (CPU only)")
    a = p.parse_args(argv)
    r = run(a.scenario, a.steps, a.rounds, a.device, a.baseline, a.where)
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
    if "kernels" in r:
        ki, kc = r["kernels"]["intact"], r["kernels"]["cracked"]
        print(f"each kernel of the rock step, {r['steps']} steps, each launch timed [ms/step]: intact, cracked, "
              "cracked - intact")
        for k in sorted(set(ki) | set(kc), key=lambda k: -kc.get(k, 0.0)):
            a_, b_ = ki.get(k, 0.0), kc.get(k, 0.0)
            if max(a_, b_) >= 0.001:
                print(f"  {k:32s} {a_:7.3f} {b_:7.3f} {b_ - a_:+7.3f}")
        print(f"  {'sum':32s} {sum(ki.values()):7.3f} {sum(kc.values()):7.3f} "
              f"{sum(kc.values()) - sum(ki.values()):+7.3f}")
        print("the cracked state's contact pass by what its listed nodes do (each class alone, median, less the "
              "launch's own cost in the first row) [ms/pass]:")
        for name, count, ms in r["pass_classes"]:
            per = f"{1e6 * ms / count:7.0f} ns a node" if count else ""
            print(f"  {name:28s} {count:6,d} nodes {ms:7.3f} ms {per}")
    print(f"load average {r['load_before'][0]:.2f} before, {r['load_after'][0]:.2f} after ({r['cpus']} CPUs)")


if __name__ == "__main__":
    main()
