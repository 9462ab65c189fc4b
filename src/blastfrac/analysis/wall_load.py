"""Borehole-wall load of a coupled run: the mean normal pressure the gas puts on each borehole wall [Pa].

Each step the particle–edge reactions on the wall nodes (coupler.f_react) are projected on the outward radial
direction of the node's reference position about the hole centre and accumulated as an impulse Σ Δt f·r̂
[N·s/m]. The wall nodes are all the block nodes at the wall's mesh vertices, not only those of the blocks with
an edge on it: once the wall ring is crushed, the gas also pushes the blocks that meet the wall at a vertex
(10–60 % of the load in the examples, examples/crack_gas/README.md). A sample divides the impulse since the
last one by the interval and by G = Σ_e L_e·½(n̂_e·r̂_a + n̂_e·r̂_b) (edges e = a→b of the meshed wall, n̂_e their
normal away from the centre): a uniform pressure p on the polygon gives the wall nodes radial forces summing to
p·G exactly (tests/verification/test_coupling_wall_load.py). The time mean removes the chatter of the penalty contacts between samples. Written to ``borehole_pressure.csv``:
the history that drives a rock-only run with the same wall load (a ``table`` pulse in
``[[borehole_pressure]]``, docs/explosive.md, "Gas in cracks"). The gas inside cracks is not part of it: it
loads the crack faces, not the wall.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from .._warp import Launcher

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


@wp.kernel
def accumulate_wall_impulse(nodes: wp.array(dtype=wp.int32), hole: wp.array(dtype=wp.int32),
                            rhat: wp.array(dtype=wp.vec2d), f: wp.array(dtype=wp.vec2d), dt: wp.float64,
                            acc: wp.array(dtype=wp.float64)):
    """acc[hole] += dt·f·r̂ over the wall nodes [N·s/m]."""
    i = wp.tid()
    wp.atomic_add(acc, hole[i], dt * wp.dot(f[nodes[i]], rhat[i]))


class WallLoad:
    """Mean gas pressure on each borehole wall between samples; ``boreholes``: the scenario's list."""

    def __init__(self, model, boreholes, device: str):
        topo, X = model.topology, model.host["node_X"]
        nodes, holes, rhat = [], [], []
        self.perimeter = np.zeros(len(boreholes))    # G of each hole [m] (module docstring)
        for k, b in enumerate(boreholes):
            tag = f"hole{k}"
            slots = np.array([s for s, t in zip(topo.boundary_slots, topo.boundary_slot_tags) if t == tag], np.int64)
            if len(slots) == 0:
                continue
            s1 = 3 * (slots // 3) + (slots % 3 + 1) % 3
            c = np.asarray(b.center)
            xa, xb = X[slots] - c, X[s1] - c
            t = xb - xa
            L = np.linalg.norm(t, axis=1)
            n = np.stack([-t[:, 1], t[:, 0]], 1) / L[:, None]
            n *= np.sign(np.einsum("ij,ij->i", n, xa + xb))[:, None]
            ra = xa / np.linalg.norm(xa, axis=1)[:, None]
            rb = xb / np.linalg.norm(xb, axis=1)[:, None]
            self.perimeter[k] = float(np.sum(L * 0.5 * (np.einsum("ij,ij->i", n, ra) + np.einsum("ij,ij->i", n, rb))))
            # every node at a wall vertex: once the wall ring crushes, the gas also pushes the blocks that meet
            # the wall only at a vertex (10–60 % of the load, examples/crack_gas/README.md)
            wall_v = np.unique(topo.node_vertex[np.r_[slots, s1]])
            ids = np.flatnonzero(np.isin(topo.node_vertex, wall_v))
            d = X[ids] - c
            nodes.append(ids)
            holes.append(np.full(len(ids), k))
            rhat.append(d / np.linalg.norm(d, axis=1)[:, None])
        self.n_holes = len(boreholes)
        self.names = [f"hole{k}" for k in range(self.n_holes)]
        n = np.concatenate(nodes) if nodes else np.zeros(0, np.int64)
        self.count = len(n)
        self.nodes = wp.array(n.astype(np.int32), dtype=wp.int32, device=device)
        self.hole = wp.array((np.concatenate(holes) if holes else np.zeros(0)).astype(np.int32), dtype=wp.int32,
                             device=device)
        self.rhat = wp.array(np.concatenate(rhat) if rhat else np.zeros((0, 2)), dtype=wp.vec2d, device=device)
        self.acc = wp.zeros(max(1, self.n_holes), dtype=wp.float64, device=device)
        self.device = device
        self._t_last = 0.0
        self._launch = Launcher()                    # a recorded launch, replayed each step (_warp.Launcher)

    def accumulate(self, f_react, dt: float) -> None:
        if self.count:
            self._launch(accumulate_wall_impulse, dim=self.count,
                         inputs=[self.nodes, self.hole, self.rhat, f_react, wp.float64(dt)], outputs=[self.acc],
                         device=self.device)

    def sample(self, t: float) -> list[float]:
        """Mean wall pressure of each hole since the last sample [Pa] (0 at the first); resets the impulse."""
        span = t - self._t_last
        imp = self.acc.numpy()[: self.n_holes]
        with np.errstate(divide="ignore", invalid="ignore"):
            p = np.where((span > 0) & (self.perimeter > 0), imp / (max(span, 1e-300) * self.perimeter), 0.0)
        self.acc.zero_()
        self._t_last = t
        return [float(v) for v in p]
