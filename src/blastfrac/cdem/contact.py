"""Node-to-edge frictional contact between separated blocks (METHOD §1.5).

Targets are *free* element edges: mesh-boundary edges and interfaces whose two springs have
both separated ("dropped"). Broken springs that have not separated still act as unilateral
contacts in the spring stage, so they are excluded here to avoid counting a contact twice.
Candidate nodes are the nodes on a free edge; they are matched to nearby free edges of other
blocks through a spatial hash of edge midpoints (cost linear in the number of nodes).

A node never contacts an edge of its own block or an edge that ends at the node's original
mesh vertex (such corner contacts are degenerate and are carried by the springs).
Normal force Fn = Kc·(−g) with Kc = kn·L_edge/2; tangential force incremental with history
per node, capped at μ·Fn (μ = tan φ_r). Reactions go to the edge's nodes with weights
(1 − ξ, ξ), so momentum is conserved.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp


@wp.func
def slot_free(slot: wp.int32, slot_iface: wp.array(dtype=wp.int32), pair_dropped: wp.array(dtype=wp.int32)):
    q = slot_iface[slot]
    if q < 0:
        return True
    return pair_dropped[2 * q] != 0 and pair_dropped[2 * q + 1] != 0


@wp.func
def slot_end(slot: wp.int32):
    """Node at the far end of element-local edge slot 3e+k (local vertex (k+1) mod 3)."""
    return 3 * (slot // 3) + (slot % 3 + 1) % 3


@wp.kernel
def compute_edge_midpoints(x: wp.array(dtype=wp.vec2d), points: wp.array(dtype=wp.vec3d)):
    s = wp.tid()
    m = wp.float64(0.5) * (x[s] + x[slot_end(s)])
    points[s] = wp.vec3d(m[0], m[1], wp.float64(0.0))


@wp.kernel
def eval_block_contact(
    grid: wp.uint64,
    slot_iface: wp.array(dtype=wp.int32),
    node_vertex: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    kc_area: wp.float64,
    mu_f: wp.float64,
    search_radius: wp.float64,
    max_depth: wp.float64,
    dt: wp.float64,
    contact_slot: wp.array(dtype=wp.int32),
    contact_fs: wp.array(dtype=wp.float64),
    f: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
):
    n = wp.tid()
    e = n // 3
    k = n % 3
    zero = wp.float64(0.0)
    one = wp.float64(1.0)
    if not (slot_free(n, slot_iface, pair_dropped) or slot_free(3 * e + (k + 2) % 3, slot_iface, pair_dropped)):
        contact_slot[n] = -1
        return
    xn = x[n]
    vtx = node_vertex[n]
    best = int(-1)
    best_g = wp.float64(0.0)
    best_xi = wp.float64(0.0)
    query = wp.hash_grid_query(grid, wp.vec3d(xn[0], xn[1], zero), search_radius)
    s = int(0)
    while wp.hash_grid_query_next(query, s):
        if s // 3 == e:
            continue
        b = slot_end(s)
        if node_vertex[s] == vtx or node_vertex[b] == vtx:
            continue
        if not slot_free(s, slot_iface, pair_dropped):
            continue
        d = x[b] - x[s]
        L = wp.length(d)
        tt = d / L
        nn = wp.vec2d(tt[1], -tt[0])
        r = xn - x[s]
        xi = wp.dot(r, tt) / L
        g = wp.dot(r, nn)
        if xi >= zero and xi <= one and g < zero and g > -max_depth:
            if best < 0 or g < best_g:
                best = s
                best_g = g
                best_xi = xi
    if best < 0:
        contact_slot[n] = -1
        contact_fs[n] = zero
        return
    b = slot_end(best)
    d = x[b] - x[best]
    L = wp.length(d)
    tt = d / L
    nn = wp.vec2d(tt[1], -tt[0])
    kc = kc_area * wp.float64(0.5) * L
    fn = -kc * best_g
    fs = wp.float64(0.0)
    if contact_slot[n] == best:
        fs = contact_fs[n]
    vrel = v[n] - ((one - best_xi) * v[best] + best_xi * v[b])
    fs = fs - kc * wp.dot(vrel, tt) * dt
    cap = mu_f * fn
    if wp.abs(fs) > cap:
        wp.atomic_add(energy_acc, 3, (wp.abs(fs) - cap) * cap / kc)
        fs = wp.sign(fs) * cap
    contact_slot[n] = best
    contact_fs[n] = fs
    force = fn * nn + fs * tt
    wp.atomic_add(f, n, force)
    wp.atomic_add(f, best, -(one - best_xi) * force)
    wp.atomic_add(f, b, -best_xi * force)


class BlockContact:
    """Preallocated spatial hash and per-node contact history; ``apply`` runs once per step."""

    def __init__(self, model):
        self.model = model
        d = model.device
        n = model.node_count
        h = model.host
        lengths = model.mesh.edge_lengths()                       # [E, 3]
        self.l_max = float(lengths.max())
        self.h_min = float(np.min(2.0 * h["elem_area0"] / lengths.max(axis=1)))
        self.kc_area = float(np.mean(h["pair_kn_area"])) if len(h["pair_kn_area"]) else 0.0
        self.mu_f = model.tan_phi_r
        # about one hash cell per node keeps the bucket occupancy constant as meshes grow
        dim = int(min(4096, max(16, math.sqrt(n))))
        self.grid = wp.HashGrid(dim, dim, 1, device=d, dtype=wp.float64)
        self.points = wp.zeros(n, dtype=wp.vec3d, device=d)
        self.slot_iface = wp.array(model.topology.slot_iface.astype(np.int32), dtype=wp.int32, device=d)
        self.node_vertex = wp.array(model.topology.node_vertex.astype(np.int32), dtype=wp.int32, device=d)
        self.contact_slot = wp.full(n, -1, dtype=wp.int32, device=d)
        self.contact_fs = wp.zeros(n, dtype=wp.float64, device=d)
        self.active = False
        # The hash of edge midpoints is rebuilt every REBUILD_INTERVAL steps and queried with a margin of
        # h_min/2: correct while no edge midpoint moves more than h_min/4 between rebuilds, i.e. for speeds
        # below h_min/(4·10·Δt) ≈ 0.1·c_p/β^½, far above rock fragment speeds in blasts.
        self.rebuild_interval = 10
        self._since_build = self.rebuild_interval

    def apply(self, state, dt: float) -> None:
        if not self.active or self.kc_area == 0.0:
            return
        m = self.model
        radius = 0.5 * self.l_max + self.h_min
        if self._since_build >= self.rebuild_interval:
            wp.launch(compute_edge_midpoints, dim=m.node_count, inputs=[state.x], outputs=[self.points], device=m.device)
            self.grid.build(self.points, radius)
            self._since_build = 0
        self._since_build += 1
        wp.launch(eval_block_contact, dim=m.node_count,
                  inputs=[self.grid.id, self.slot_iface, self.node_vertex, state.pair_dropped, state.x, state.v,
                          wp.float64(self.kc_area), wp.float64(self.mu_f), wp.float64(radius),
                          wp.float64(0.5 * self.h_min), wp.float64(dt)],
                  outputs=[self.contact_slot, self.contact_fs, state.f, state.energy_acc], device=m.device)
