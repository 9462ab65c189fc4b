"""Block contact with its caches (BlockContact.fan_cache, cdem/contact.py "Cost") against the uncached full search.

A cracked block: 40 % of the interfaces broken (a few of them dropped), every element moving with its own random
velocity so that broken faces held by their springs slide into the other blocks of their vertex fan. Two states
of the same model are stepped side by side, one with the fan cache and the listing of the nodes to evaluate,
one with every held node walking its fan every step (the search as it was before the cache); more springs are
broken from outside between steps, so the caches are rebuilt from changes they did not see coming. The contact
forces, the contact history and the motion must be the same to the last bit on a CPU (same operations in the
same order); on a GPU the order of the force sums is not fixed, so there they must agree to round-off.
"""

import numpy as np

from blastfrac.cdem.solver import CDEMSolver
from blastfrac.model.builder import ModelBuilder
from conftest import scenario

HISTORY = ("contact_slot", "contact_state", "elem_near", "query_after",
           "loss_acc")


def _cracked(seed: int = 3):
    sc = scenario(rock={"unbreakable": False, "tensile_strength": 5e6, "cohesion": 20e6},
                  geometry={"domain": {"type": "rectangle", "width": 0.06, "height": 0.06}, "mesh_size": 0.004,
                            "boreholes": [{"radius": 0.005}]})
    m = ModelBuilder(sc).finalize("cpu")
    rng = np.random.default_rng(seed)
    n_if = m.interface_count
    broken = rng.random(n_if) < 0.4
    dropped = broken & (rng.random(n_if) < 0.05)
    mode = np.repeat(np.where(broken, 1 + (rng.random(n_if) < 0.5), 0), 2).astype(np.int32)
    drop = np.repeat(dropped, 2).astype(np.int32)
    v = np.repeat(rng.normal(0.0, 20.0, (m.element_count, 2)), 3, axis=0)   # a random rigid velocity per block
    return m, mode, drop, v


def _state(m, mode, drop, v):
    st = m.state()
    st.pair_mode.assign(mode)
    st.pair_dropped.assign(drop)
    st.v.assign(v)
    return st


def _equal(a: np.ndarray, b: np.ndarray, cpu: bool) -> bool:
    if cpu:
        return np.array_equal(a, b)
    return np.allclose(a, b, rtol=1e-9, atol=1e-12 * max(1.0, float(np.abs(a).max(initial=0.0))))


def test_cached_contact_equals_full_search():
    m, mode, drop, v = _cracked()
    cpu = m.device == "cpu"
    runs = []
    for cached in (True, False):
        solver = CDEMSolver(m, block_contact=True)
        solver.contact.fan_cache = cached
        runs.append((solver, _state(m, mode, drop, v)))
    (sa, st_a), (sb, st_b) = runs
    ca, cb = sa.contact, sb.contact
    dt = 0.5 * m.stable_dt
    rng = np.random.default_rng(11)
    held_contacts, listed, candidates = 0, [], []
    for k in range(240):
        if k in (60, 150):                    # springs broken from outside: the caches must follow
            extra = np.repeat(rng.random(m.interface_count) < 0.15, 2)
            for st in (st_a, st_b):
                pm = st.pair_mode.numpy().copy()
                pm[extra & (pm == 0)] = 2
                st.pair_mode.assign(pm)
            ca.rescan_springs()               # not listed by the spring kernel: said so
        for solver, st in runs:
            solver.forces(st, dt, k * dt)
        # every change of a spring's state has been seen (the spring kernel lists the springs it breaks or drops,
        # and the pass reads that list instead of every spring)
        assert np.array_equal(ca.seen_mode.numpy(), st_a.pair_mode.numpy()), f"a mode change missed at step {k}"
        assert np.array_equal(ca.seen_dropped.numpy(), st_a.pair_dropped.numpy()), f"a drop missed at step {k}"
        assert _equal(st_a.f.numpy(), st_b.f.numpy(), cpu), f"contact forces differ at step {k}"
        for name in HISTORY:
            assert _equal(getattr(ca, name).numpy(), getattr(cb, name).numpy(), cpu), f"{name} differs at step {k}"
        # the case is not trivial: nodes whose broken faces are all held carry contacts, and the cache lists fewer
        # nodes than the full search goes into
        face = ca.node_face.numpy()
        on = ca.contact_slot.numpy() >= 0
        held_contacts = max(held_contacts, int(np.count_nonzero(on & (face[:, 0] > 0) & (face[:, 1] == 0))))
        listed.append(int(ca._counts.numpy()[1]))
        candidates.append(int(np.count_nonzero(face[:, 0] > 0)))     # the nodes the full search goes into
        for solver, st in runs:
            solver.integrate(st, dt)
    for name in ("x", "v", "energy_acc", "pair_mode", "pair_dropped"):
        assert _equal(getattr(st_a, name).numpy(), getattr(st_b, name).numpy(), cpu), f"state {name} differs"
    print(f"held nodes in contact (most at once) {held_contacts}, nodes evaluated per step "
          f"{np.mean(listed):.0f} cached against {np.mean(candidates):.0f} uncached")
    assert held_contacts >= 10
    assert np.mean(listed) < 0.7 * np.mean(candidates)


def test_every_spring_change_reaches_the_contact_pass():
    """After the first pass, block contact reads only the springs the spring kernel listed as broken or dropped
    (kernels_spring.list_change) instead of every spring's state, and merges the nodes it flags for the first time
    into its candidate list instead of scanning every node's flag (merge_candidates): after each pass the states it
    has seen must be the springs' own and the list every flagged node in order, while springs break and drop
    during the run, on one thread and with the springs in two halves (two lists)."""
    m, mode, drop, _ = _cracked(seed=5)
    rng = np.random.default_rng(7)
    v = np.repeat(rng.normal(0.0, 400.0, (m.element_count, 2)), 3, axis=0)   # fast enough to open and drop faces
    dt = 0.5 * m.stable_dt
    for halves in (False, True):
        solver = CDEMSolver(m, block_contact=True)
        if halves:                             # the two halves in order on this thread: two slots, two lists
            solver.splits = lambda stage, n: stage == "springs"
            solver.pool = _InOrder()
            solver._split_ready.add("springs")
        st = _state(m, mode, drop, v)
        c = solver.contact
        c.active = True
        merged = 0
        for k in range(450):                   # faces open past L0 and drop from step ~400
            solver.forces(st, dt, k * dt)
            assert np.array_equal(c.seen_mode.numpy(), st.pair_mode.numpy()), f"a break missed at step {k}"
            assert np.array_equal(c.seen_dropped.numpy(), st.pair_dropped.numpy()), f"a drop missed at step {k}"
            assert solver.pair_change_count.numpy().sum() == 0          # each pass empties the lists
            # the candidate list, merged from the newly flagged nodes (merge_candidates), is every flagged node
            cand = c._cand_list.numpy()[: c._cand_count.numpy()[0]]
            assert np.array_equal(cand, np.flatnonzero(c.node_flag.numpy())), f"candidate list wrong at step {k}"
            merged = max(merged, int(c.new_count.numpy()[0]))
            solver.integrate(st, dt)
        broke = int(np.count_nonzero((st.pair_mode.numpy() > 0) & (mode == 0)))
        dropped = int(np.count_nonzero(st.pair_dropped.numpy() > drop))
        assert broke > 0 and dropped > 0, (broke, dropped)       # both lists were exercised
        assert merged > 1                                        # and merges of several new candidates


class _InOrder:
    """A stand-in for the solver's thread pool that runs what it is given at once, on this thread."""

    def submit(self, f, *a, **k):
        class Done:
            def __init__(self, r):
                self.r = r

            def result(self):
                return self.r
        return Done(f(*a, **k))


def test_hash_rebuilt_on_displacement_finds_what_a_fresh_hash_finds():
    """The hash is rebuilt when a node has moved rebuild_skin = h_min/4 since the last build (checked every
    rebuild_check steps), not at a fixed interval: with blocks flying at a few hundred m/s (a tenth of the contact
    pass's speed bound h_min/(20Δt)), the contact forces and the motion must be those of a hash rebuilt at every
    step, to the last bit on a CPU."""
    m, mode, drop, _ = _cracked()
    rng = np.random.default_rng(5)
    solvers = [CDEMSolver(m, block_contact=True) for _ in range(2)]
    fresh = solvers[1].contact
    fresh.rebuild_check, fresh.rebuild_skin = 1, 0.0            # rebuilt at every step
    dt = 0.5 * m.stable_dt
    bound = solvers[0].contact.h_min / (20.0 * dt)
    v = np.repeat(rng.normal(0.0, 0.1 * bound, (m.element_count, 2)), 3, axis=0)
    states = [_state(m, mode, drop, v) for _ in solvers]
    cpu = m.device == "cpu"
    steps, contacts = 200, 0
    for k in range(steps):
        for solver, st in zip(solvers, states):
            solver.forces(st, dt, k * dt)
        assert _equal(states[0].f.numpy(), states[1].f.numpy(), cpu), f"contact forces differ at step {k}"
        contacts = max(contacts, solvers[0].contact.active_count())
        for solver, st in zip(solvers, states):
            solver.integrate(st, dt)
    for name in ("x", "v", "energy_acc"):
        assert _equal(getattr(states[0], name).numpy(), getattr(states[1], name).numpy(), cpu), name
    n_built = solvers[0].contact.rebuilds
    print(f"hash rebuilds: {n_built} of {steps} steps (every step: {fresh.rebuilds}); contacts (most at once) "
          f"{contacts}")
    assert fresh.rebuilds == steps
    assert 2 <= n_built <= steps // 5          # it is rebuilt as the blocks move, and far less often than each step
    assert contacts >= 10
