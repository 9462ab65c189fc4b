"""Coupled steps replayed from captured graphs (``simulation.graph``, issue 14 item 1; docs/scenario.md, "Graphs").

A coupled step reads nothing back from the device inside it (block contact's schedule, the gas–rock coupler's list
and the crack gas's network live on the device, the burn reads a device clock), so its launches can be captured once
(a CUDA graph on a GPU, Warp's C++ replay of the recorded operations on a CPU) and replayed, with the same results
to the bit (tests/unit/test_coupled_graph.py). :class:`CoupledGraphs` keeps the graphs of a run and steps it.
"""

from __future__ import annotations

import warp as wp

#: steps a coupled step runs through the launches after Δt changed, before it is captured (Δt is re-estimated every
#: 10 steps; while the gas sets it, early in a blast, most estimates change it, and a graph captured for one value
#: would serve ~10 steps: on a CPU the 10 mm confined P0's first 300 steps took 1.27 s captured at every change,
#: against 0.57 s through the launches)
DT_SETTLED = 20


class CoupledGraphs:
    """The captured coupled steps of a Simulation: ``cache`` maps the coupler's and the crack gas's keys to graphs,
    all captured for ``key`` (the rest of what they hold); a change of ``key`` drops them."""

    def __init__(self):
        self.cache: dict = {}
        self.key = None

    def step(self, sim, dt: float) -> bool:
        """One coupled step replayed from a captured graph (a CUDA graph on a GPU, Warp's replay of the recorded
        operations on a CPU): the launches of the one-thread step (rock forces, gas forces beside them, the gas loads,
        integration, the gas's advance), which read nothing back inside it. The clocks (the time at the start of the
        step, which the springs and the burn read) and the pulses are set before the replay, and the host's side of
        the step runs beside it: the schedules and history buffers of the coupler and the crack gas (``host_step``),
        the MPM box's renewal every BOX_STEPS steps (MPMSolver.advance_box). A graph is kept for each of their keys
        (rebuild or not, history buffer: four without crack gas) and all are captured again when anything else they
        hold changes: Δt (set by the host every 10 steps; in the shipped examples it settles within their first
        250–450 steps), the MPM box, block contact's settings.

        Returns False, having done nothing, where a graph cannot stand for the step: within DT_SETTLED steps of the
        start or of a change of Δt (while the gas sets Δt, early in a blast, most of its estimates change it, and a
        graph would serve a few steps for the cost of its capture), before the first passes of block contact and
        the coupler (they build their caches on the host), with pulses on a GPU (CDEMSolver.step_captured), and
        from a failed capture on (a GPU without conditional graph nodes, CUDA < 12.4), with a warning."""
        m, c, cp, gas = sim.model, sim.cdem.contact, sim.coupler, sim.gas
        if cp.cell_size == 0.0 or sim.cdem.dt_prev != dt or sim.steps - sim._dt_since < DT_SETTLED or \
                (c is not None and c.active and not c.capturable()) or (m.pulses and m.device != "cpu"):
            return False
        rest = (id(sim.state), dt, sim.alpha, m.breakable, None if c is None else c.graph_key(), gas.grid.box,
                cp.graph_held(), sim.wall_load is not None)     # (graphs dropped on a change)
        if rest != self.key:
            self.cache, self.key = {}, rest
        cg = sim.crack_gas
        key = (cp.graph_key(), None if cg is None else cg.graph_key())
        t = sim.time
        sim.cdem.pool = None
        sim._parallel = False
        graph = self.cache.get(key)
        sim.cdem._set_clock(t)
        gas.set_clock(t)
        if graph is None:
            stages = [st for st in (cp, cg) if st is not None]
            saved = [st.host_state() for st in stages]
            try:
                graph = self._capture(sim, dt)
            except Exception as err:                 # noqa: BLE001 (the launches can always take the step)
                for st, h in zip(stages, saved):
                    st.set_host_state(h)             # as before the captured host steps
                sim.coupled_graph = False
                sim.warnings.append(f"coupled steps run through the launches: capturing one failed ({err})")
                return False
            self.cache[key] = graph
            sim.coupled_graph_captures += 1
        else:
            if m.pulses:
                sim.cdem.eval_pulses(t)             # the graph copies this host buffer
            cp.host_step(dt)                         # what the captured stages did on the host
            if cg is not None:
                cg.host_step(dt)
        wp.capture_launch(graph)
        gas.advance_box()
        sim.coupled_graph_steps += 1
        return True

    def _capture(self, sim, dt: float):
        """Capture the one-thread coupled step's launches (Simulation.step's order) as a graph, without running them."""
        st, t, d = sim.state, sim.time, sim.model.device
        stages = [s for s in (sim.coupler, sim.gas, sim.crack_gas) if s is not None]
        for s in stages:
            s.captured = True
        sim.cdem._capturing = True
        begun = False
        try:                                         # (the stages' flags go back whatever fails, begin included)
            wp.capture_begin(device=d)
            begun = True
            sim.cdem.forces_springs_blocks(st, dt, t)
            sim.cdem.forces_rest(st, dt, t, beside=lambda: sim._gas_forces(dt), blocks_done=True)
            sim.coupler.add_reactions(st)
            if sim.crack_gas is not None:
                sim.crack_gas.add_loads(st)
            sim.cdem.integrate(st, dt, sim.alpha)
            sim._gas_advance(dt)
        finally:
            for s in stages:
                s.captured = False
            sim.cdem._capturing = False
            graph = wp.capture_end(device=d) if begun else None
        return graph
