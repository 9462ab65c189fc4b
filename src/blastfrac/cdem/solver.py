"""CDEM solver: the ordered rock stages of one explicit step. Holds no physical state."""

from __future__ import annotations

import time

import numpy as np
import warp as wp

from .._warp import Launcher
from ..model.model import Model, State
from .boundary import launch_edge_loads
from .contact import BlockContact
from .kernels_element import launch_element_forces
from .kernels_integrate import launch_integrate
from .kernels_spring import change_lists, launch_spring_forces, spring_model, spring_scalars, spring_state


#: per stage, the items from which two threads split it, in units of CDEMSolver.split_min interfaces: a stage is split
#: where it costs more than ~0.5 ms (per item at 234k triangles on one core: 53 ns a spring interface, 15 ns a CST
#: block (now with its nodes' spring forces, which a separate gather pass added at 4 ns a node), 10 ns an integrated
#: block; two hand-offs of ~85 µs must be paid for)
#: block contact: ~2 ns a spring for the scan of every spring's change (first pass), ~0.5 µs a node of its pass over
#: the listed nodes (at 113k blocks, one core; from 1,500 of them). Its displacement check (every 5th step, a stream
#: over two position arrays) is not split: in two halves it took longer (stop 28)
SPLIT_SCALE = {"springs": 1, "blocks": 3, "integrate": 5, "pair_changes": 20, "contact": 0.15}


class CDEMSolver:
    """Rock forces and integration for a :class:`Model`; scratch buffers are allocated once here."""

    def __init__(self, model: Model, block_contact: bool | None = None):
        self.model = model
        n = max(1, len(model.pulses))
        # pageable, not pinned: a copy from pageable memory to a GPU is staged before wp.copy returns, so the next
        # step may rewrite the buffer; from pinned memory the copy would read it when the stream gets there, after
        # the host had written a later step's values (the launches do not wait for the GPU between steps)
        self._pulse_host = wp.zeros(n, dtype=wp.float64, device="cpu")
        use_contact = model.breakable == 1 if block_contact is None else block_contact
        self.contact = BlockContact(model) if use_contact else None
        self.dt_prev = 0.0
        self.launch = Launcher()                  # recorded launches of the rock stages (_warp.Launcher)
        self.clock = wp.zeros(1, dtype=wp.float64, device=model.device)   # time at the start of the step [s]
        self._clock_host = self.clock.numpy() if model.device == "cpu" else None
        # Captured rock step (step_captured): None, or (key, graph); graph_steps counts its replays
        self._graph = None
        self.graph_steps = 0
        # Two threads (Simulation with simulation.threads = 2 sets pool): the springs, the CST blocks (with the
        # gather of the spring forces) and the integration each run in two halves, the second in the pool's thread
        # (each item keeps its own energy accounts, so nothing is shared and the result is one thread's to the
        # bit). A hand-off costs ~85 µs here, so a stage is split only from SPLIT_SCALE[stage]·split_min items on
        # (split_min interfaces: ~0.5 ms of springs; the other stages cost less per item)
        self.pool = None
        self.split_min = 10000
        self._split_ready: set = set()           # the stages whose module has loaded (the first call is serial)
        self._share: dict[str, float] = {}        # a stage's first share where it runs beside another (_in_parts_beside)
        self._capturing = False
        if self.contact is not None:
            self.contact.in_halves = self._in_halves     # block contact's scans over the whole rock, likewise
        self.ppv_out: wp.array | None = None     # peak speed per node [m/s] the integration updates (Simulation sets
                                                 # it to its PeakVelocity array; not saved twice by a checkpoint)
        # the spring kernel's structs (kernels_spring.SpringModel, SpringState): one model, one per State
        self._spring_model = spring_model(model)
        self._spring_scalars = spring_scalars(model)
        self._spring_states: dict = {}
        # the springs whose mode or dropped flag changed since block contact's last pass, listed by the spring
        # kernel (kernels_spring.list_change, a slot per half of the interfaces); the contact pass reads them and
        # clears the counts
        self.pair_changes, self.pair_change_count = change_lists(model.spring_count, model.device)
        if self.contact is not None:
            self.contact.changes = (self.pair_changes, self.pair_change_count)

    def _springs(self, state: State) -> tuple:
        """(SpringModel, SpringState) for ``state``, the model's scalars as they are now."""
        sc = spring_scalars(self.model)
        if sc != self._spring_scalars:
            spring_model(self.model, self._spring_model)
            self._spring_scalars = sc
        ss = self._spring_states.get(id(state))
        if ss is None or ss[0] is not state:
            ss = self._spring_states[id(state)] = (state, spring_state(state, (self.pair_changes,
                                                                                self.pair_change_count)))
        return self._spring_model, ss[1]

    def _set_clock(self, t: float) -> None:
        if self._clock_host is not None:
            self._clock_host[0] = t                 # a view of the CPU array: no launch
        elif not self._capturing:                   # a captured step's clock is set before each replay
            self.clock.fill_(t)

    def eval_pulses(self, t: float) -> None:
        """Evaluate every pressure pulse at time t [s] into the host buffer that set_pulses copies."""
        host = self._pulse_host.numpy()
        for i, p in enumerate(self.model.pulses):
            host[i] = p(t)

    def set_pulses(self, state: State, t: float) -> None:
        """Evaluate every pressure pulse at time t [s] and copy the values to the device."""
        if not self.model.pulses:
            return
        self.eval_pulses(t)
        wp.copy(state.pulse_values, self._pulse_host)

    def forces(self, state: State, dt: float, t: float) -> None:
        """Stage 3 of a step: element stresses and forces, springs with failure, loads, block contact."""
        self.forces_springs(state, dt, t)
        self.forces_rest(state, dt, t)

    def forces_springs(self, state: State, dt: float, t: float) -> None:
        """3a: springs, failure, broken-pair contact (after it, pair_mode holds this step's failures). With a pool
        (two threads), the second half of the interfaces runs in its thread: each interface writes only its own
        springs and their energy accounts (dashpot work included), so the result is one thread's to the bit."""
        self._set_clock(t)
        m = self.model
        self._in_halves("springs", m.interface_count, launch_spring_forces, m, state, dt, self.clock, self.launch,
                        structs=self._springs(state))

    def forces_springs_blocks(self, state: State, dt: float, t: float) -> None:
        """3a then 3b: the springs with failure, then the CST blocks with their nodes' spring forces (f = f_int +
        f_springs; the blocks read the pair forces of every interface, so the springs finish first, in both halves
        where they split). ``forces_rest(..., blocks_done=True)`` then skips 3b."""
        self.forces_springs(state, dt, t)
        self._in_halves("blocks", self.model.element_count, launch_element_forces, self.model, state, dt, self.launch)

    def _in_halves(self, stage: str, n: int, launch, *args, **kwargs) -> None:
        """``launch(*args, first=…, count=…, key=…, **kwargs)`` over items 0 … n − 1: in two halves, the second in the
        pool's thread, where there is a pool (two threads), n ≥ SPLIT_SCALE[stage]·split_min, the device is a CPU,
        no graph is being captured and the stage has run once (its first call loads its module, which Warp does not
        guard against two threads); else in one launch."""
        if not self.splits(stage, n):
            if self.pool is not None:
                self._split_ready.add(stage)
            launch(*args, **kwargs)
            return
        half = n // 2
        fut = self.pool.submit(launch, *args, first=half, count=n - half, key="b", **kwargs)
        try:
            launch(*args, first=0, count=half, key="a", **kwargs)
        finally:
            fut.result()

    def _in_parts_beside(self, stage: str, n: int, launch, beside, *args, **kwargs) -> None:
        """``_in_halves`` with ``beside`` (an independent stage group: the gas's advance) run in the pool's thread
        before its part, the split point set so that both threads finish together: the first part takes the share
        ``_share[stage]`` (½ … 0.9, in steps of 1/64) of the items, renewed after every call from the two threads'
        times. Every item is computed alike wherever the split falls, so the results do not depend on it."""
        share = self._share.get(stage, 0.5)
        k = min(n - 1, max(n // 2, int(round(share * 64)) * n // 64))

        def second() -> tuple[float, float]:
            t0 = time.perf_counter()
            beside()
            t1 = time.perf_counter()
            launch(*args, first=k, count=n - k, key="b", **kwargs)
            return t1 - t0, time.perf_counter() - t1

        fut = self.pool.submit(second)
        try:
            t0 = time.perf_counter()
            launch(*args, first=0, count=k, key="a", **kwargs)
            t_a = time.perf_counter() - t0
        finally:
            t_beside, t_b = fut.result()
        per_item = (t_a + t_b) / n
        if per_item > 0.0:                          # the share that would have balanced this call, half-way there
            target = (t_beside + per_item * n) / (2.0 * per_item * n)
            self._share[stage] = min(0.9, max(0.5, 0.5 * share + 0.5 * target))

    def splits(self, stage: str, n: int) -> bool:
        """True when ``_in_halves`` runs ``stage`` over n items in two threads (see there)."""
        return not (self.pool is None or n < SPLIT_SCALE[stage] * self.split_min or self.model.device != "cpu" or
                    self._capturing or stage not in self._split_ready)

    def forces_rest(self, state: State, dt: float, t: float, beside=None, blocks_done: bool = False) -> None:
        """3b–3e: CST stresses and f = f_int + f_springs, loads, block contact (writes f, reads pair_mode).

        ``beside``: a stage group independent of these (the gas's forces) to run in the pool's thread meanwhile. It is
        handed over where the pool is free for it: at once when the group's first stage that could split (the CST
        blocks, or with ``blocks_done`` block contact's scan of every spring, which only its first pass and one after
        ``rescan_springs`` make) runs in one launch, else after the last of the stages that run in two halves before
        block contact's serial rest (the CST, that scan), so that it overlaps the serial rest instead of holding up a
        half (the shipped confined P0: the rock's rest 8.5 ms with the gas handed over first, the CST's second half
        waiting behind it). Block contact's pass over its list, which splits too, then runs its second half in the
        pool's thread after the gas. Without a pool it runs here, last.
        ``blocks_done``: 3b ran already (``forces_springs_blocks``)."""
        m = self.model
        fut = []
        scans = self.contact is not None and self.contact.active and self.contact.kn_area != 0.0 and \
            self.contact.full_scan_due()
        first = ("blocks", m.element_count) if not blocks_done else \
            ("pair_changes", m.spring_count if scans else 0)

        def hand_over() -> None:
            if beside is not None and not fut:
                fut.append(self.pool.submit(beside))

        try:
            if beside is not None and self.pool is not None and not self.splits(*first):
                hand_over()
            if not blocks_done:                                   # 3b-c f = f_int + springs
                self._in_halves("blocks", m.element_count, launch_element_forces, m, state, dt, self.launch)
            self.set_pulses(state, t)
            launch_edge_loads(self.model, state, self.dt_prev, self.launch)   # 3d pressure pulses, in-situ tractions
            if self.contact is not None:                          # 3e node-to-edge block contact
                self.contact.apply(state, dt, hand_over=hand_over if self.pool is not None else None)
            if self.pool is not None:
                hand_over()
        finally:
            if fut:
                fut[0].result()
        if beside is not None and self.pool is None:
            beside()

    def integrate(self, state: State, dt: float, alpha: float = 0.0, beside=None) -> None:
        """Stage 4: central difference with damping, constraints and dashpots (and the PPV, if ``ppv_out`` is set).
        ``beside``: an independent stage group (the gas's advance), run in the pool's thread before its share of the
        blocks where the integration splits (``_in_parts_beside``), else here after it."""
        n = self.model.element_count
        args = (self.model, state, dt, alpha, self.launch)
        if beside is not None and self.splits("integrate", n):
            self._in_parts_beside("integrate", n, launch_integrate, beside, *args, ppv=self.ppv_out)
        else:
            self._in_halves("integrate", n, launch_integrate, *args, ppv=self.ppv_out)
            if beside is not None:
                beside()
        self.dt_prev = dt

    # ------------------------------------------------------------------ captured rock step
    def step_captured(self, state: State, dt: float, t: float, alpha: float, after=None) -> bool:
        """One rock step (stages 3 and 4, then ``after()``, e.g. the PPV update) replayed from a captured graph
        (``wp.capture_begin``: a CUDA graph on a GPU, Warp's C++ replay of the recorded operations on a CPU); the
        clock (a device array the springs read) and the pulses are set before each replay. The same kernels on
        the same arrays as ``forces`` + ``integrate``, so the same results to the bit
        (tests/unit/test_rock_graph.py). Block contact reads nothing back (``BlockContact.apply``). Returns False, having done nothing,
        where a graph cannot stand for the step: block contact not yet built (its first pass builds its caches on
        the host) or without its fan cache, the step not yet repeating (dt_prev ≠ dt), or pulses on a GPU (their
        host buffer is rewritten before an asynchronous replay has read it). The graph is captured again whenever
        a scalar it holds (dt, alpha, breakable, the contact's settings), the state or ``after`` changes."""
        m = self.model
        c = self.contact
        if (c is not None and c.active and not c.capturable()) or self.dt_prev != dt or \
                (m.pulses and m.device != "cpu"):
            return False
        key = (id(state), dt, alpha, m.breakable, after, None if c is None else c.graph_key())
        if self._graph is None or self._graph[0] != key:
            self._set_clock(t)
            wp.capture_begin(device=m.device)
            self._capturing = True
            try:
                launch_spring_forces(m, state, dt, self.clock, self.launch, structs=self._springs(state))
                self.forces_rest(state, dt, t)
                self.integrate(state, dt, alpha)
                if after is not None:
                    after()
            finally:
                self._capturing = False
                graph = wp.capture_end(device=m.device)
            self._graph = (key, graph)
        self._set_clock(t)                           # the graph's springs read the clock when it runs
        if m.pulses:
            self.eval_pulses(t)                      # and its copy this buffer
        wp.capture_launch(self._graph[1])
        self.graph_steps += 1
        return True

    def initialise_stress(self, state: State, sxx: float, syy: float, sxy: float) -> None:
        """Uniform initial stress σ⁰ in all blocks and consistent spring forces (METHOD §1.8)."""
        m = self.model
        sig = np.array([[sxx, sxy], [sxy, syy]])
        state.sigma.assign(np.tile([sxx, syy, sxy], (m.element_count, 1)))
        nrm = np.repeat(m.host["iface_normal"], 2, axis=0)
        tan = np.stack([-nrm[:, 1], nrm[:, 0]], 1)
        traction = nrm @ sig                                  # σ·n (σ symmetric)
        ac = m.host["pair_ac"]
        fn = -np.einsum("ij,ij->i", nrm, traction) * ac
        fs = -np.einsum("ij,ij->i", tan, traction) * ac
        state.pair_F.assign(np.stack([fn, fs], 1))
        state.pair_g0.assign(fn / m.host["pair_kn"])
        # the springs start loaded: their stored energy is work done on them, so work − stored (pair_inelastic,
        # the fracture energy of an intact spring, analysis/energy.py) starts at 0
        state.pair_inelastic.zero_()

    def rebase_spring_work(self, state: State) -> float:
        """Start the spring energy books of a new stage [J/m]: each intact spring's work beyond its stored energy
        (pair_inelastic) becomes 0 and each broken one's its fracture energy (no fracture or friction carried over),
        and return the fracture energy of the springs already broken, which the stage's
        budget must count as supplied (it stays in ``pair_efrac`` and in the fracture term)."""
        broken = state.pair_mode.numpy() > 0
        efrac = state.pair_efrac.numpy()
        state.pair_inelastic.assign(np.where(broken, efrac, 0.0))
        return float(efrac[broken].sum())

