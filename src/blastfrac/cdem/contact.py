"""Node-to-edge frictional penalty contact between separated blocks (METHOD §1.5).

Targets are *free* element edges: mesh-boundary edges and interfaces whose two springs have
both separated ("dropped"). Broken springs that have not separated still act as unilateral
contacts in the spring stage, so they are excluded here to avoid counting a contact twice.
Candidate nodes are the nodes on a free edge of their own element (the others exit at once);
they are matched to nearby free edges of other elements through a spatial hash of edge
midpoints, so the cost is linear in the number of nodes. Running over all nodes gives both
passes (A→B and B→A).

**Geometry.** Node x against edge a→b of length L: ξ = (x − x_a)·t̂/L and g = (x − x_a)·n̂ [m],
with n̂ = (t_y, −t_x) the outward normal of a counter-clockwise element (TriMesh orients them so).
A node never contacts an edge of its own element or an edge that ends at its original mesh
vertex (degenerate corner contacts carried by the springs).

**Which edge.**
1. Candidates: 0 ≤ ξ ≤ 1 and −h_min/2 < g < 0 (behind the edge), and the node's own element
   faces the front of the edge (one of its two edges at the node points in front by > 0.6°).
2. The contact edge is the candidate with the least penetration (largest g).
3. Inside test: the free edge nearest to the node (distance to the segment) must not have the
   node in front of it, else the node is outside that block.
A node that has just crossed one face of a block is also behind its other faces within h_min/2
(2 mm behind the neighbouring face of a 1 cm block); taking the deepest of these gave forces of
Kc·2 mm on first touch. (1) stops a face that is collinear with one of the node's own faces
(flush blocks) from being taken for a round-off g < 0; (3) rejects a node outside a block near
an acute corner, which is behind one face while in front of the other.

**Forces** (per unit thickness). Normal Fn = Kc·(−g) [N/m] with Kc = kn·A_node [Pa], kn [Pa/m]
the interface stiffness per area and A_node [m] half the reference length of the node's own free
edges; Kc is capped at m_min/Δt² (the smallest of the three node masses [kg/m]), so the contact
stays stable at nodes that get no contact allowance in the stable step (a node with no spring).
Tangential Fs is incremental, Fs ← Fs − Kc·(v_rel·t̂)·Δt, capped at μ·Fn with μ = tan φ_r; its
history is kept per node and reset when the contact edge changes; the slip work goes to
energy_acc[CONTACT_DISSIPATED]. Reactions go to the edge's nodes with weights (1 − ξ, ξ), so
linear momentum is conserved.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from ..model.model import CONTACT_DISSIPATED

XI_TOL = wp.constant(wp.float64(1.0e-9))     # ξ range tolerance: a node exactly at an edge's end (flush corners)
WEDGE_TOL = wp.constant(wp.float64(0.01))    # sine of the least angle (0.6°) the node's element must face the edge


@wp.func
def slot_free(slot: wp.int32, slot_iface: wp.array(dtype=wp.int32), pair_dropped: wp.array(dtype=wp.int32)):
    """True if element edge slot is a mesh-boundary edge or an interface with both pairs dropped."""
    q = slot_iface[slot]
    if q < 0:
        return True
    return pair_dropped[2 * q] != 0 and pair_dropped[2 * q + 1] != 0


@wp.func
def slot_end(slot: wp.int32):
    """Node at the far end of element-local edge slot 3e+k (local vertex (k+1) mod 3)."""
    return 3 * (slot // 3) + (slot % 3 + 1) % 3


@wp.func
def slot_prev(node: wp.int32):
    """Element edge slot that ends at node 3e+k (the slot starting at local vertex (k+2) mod 3)."""
    return 3 * (node // 3) + (node % 3 + 2) % 3


@wp.func
def edge_coords(xn: wp.vec2d, xa: wp.vec2d, xb: wp.vec2d):
    """(ξ, g, d) of point xn against edge a→b: ξ = (xn − xa)·t̂/L, g = (xn − xa)·n̂_out,
    d = distance from xn to the segment [m]."""
    ab = xb - xa
    length = wp.length(ab)
    tang = ab / length
    r = xn - xa
    xi = wp.dot(r, tang) / length
    g = tang[1] * r[0] - tang[0] * r[1]
    dist = wp.abs(g)
    if xi < wp.float64(0.0):
        dist = wp.length(r)
    elif xi > wp.float64(1.0):
        dist = wp.length(xn - xb)
    return wp.vec3d(xi, g, dist)


@wp.kernel
def compute_edge_midpoints(x: wp.array(dtype=wp.vec2d), points: wp.array(dtype=wp.vec3d)):
    s = wp.tid()
    m = wp.float64(0.5) * (x[s] + x[slot_end(s)])
    points[s] = wp.vec3d(m[0], m[1], wp.float64(0.0))


@wp.kernel
def eval_block_contact(
    grid: wp.uint64,
    slot_iface: wp.array(dtype=wp.int32),
    slot_l0: wp.array(dtype=wp.float64),
    node_vertex: wp.array(dtype=wp.int32),
    node_mass: wp.array(dtype=wp.float64),
    pair_dropped: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    kn_area: wp.float64,
    mu_f: wp.float64,
    search_radius: wp.float64,
    max_depth: wp.float64,
    touch_tol: wp.float64,
    dt: wp.float64,
    contact_slot: wp.array(dtype=wp.int32),
    contact_fs: wp.array(dtype=wp.float64),
    f: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
):
    n = wp.tid()
    e = n // 3
    zero = wp.float64(0.0)
    one = wp.float64(1.0)
    # tributary length [m]: half of each free edge of the node's own element at the node; 0: not a candidate
    sp = slot_prev(n)
    trib = zero
    if slot_free(n, slot_iface, pair_dropped):
        trib = trib + wp.float64(0.5) * slot_l0[n]
    if slot_free(sp, slot_iface, pair_dropped):
        trib = trib + wp.float64(0.5) * slot_l0[sp]
    if trib == zero:
        contact_slot[n] = -1
        return
    xn = x[n]
    vtx = node_vertex[n]
    # the node's element wedge: unit vectors along its two edges at the node
    u1 = wp.normalize(x[slot_end(n)] - xn)
    u2 = wp.normalize(x[sp] - xn)
    xi_lo = -XI_TOL
    xi_hi = one + XI_TOL
    near_d = wp.float64(1.0e300)
    near_inside = bool(False)
    best = int(-1)
    best_xi = wp.float64(0.0)
    best_g = wp.float64(0.0)
    query = wp.hash_grid_query(grid, wp.vec3d(xn[0], xn[1], zero), search_radius)
    s = int(0)
    while wp.hash_grid_query_next(query, s):
        if s // 3 != e:
            s_end = slot_end(s)
            if node_vertex[s] != vtx and node_vertex[s_end] != vtx:
                if slot_free(s, slot_iface, pair_dropped):
                    c = edge_coords(xn, x[s], x[s_end])
                    on_edge = c[0] >= xi_lo and c[0] <= xi_hi
                    dist = c[2]
                    if not on_edge:
                        dist = dist * wp.float64(1.000000001)        # an edge's interior wins ties with its ends
                    # inside test: the nearest free edge must not have the node in front of it
                    if dist < near_d:
                        near_d = dist
                        near_inside = on_edge and c[1] <= touch_tol
                    # contact candidate: behind the edge, own element facing its front; keep the shallowest
                    if on_edge and c[1] < zero and c[1] > -max_depth and (best < 0 or c[1] > best_g):
                        ab = x[s_end] - x[s]
                        nrm = wp.vec2d(ab[1], -ab[0]) / wp.length(ab)
                        if wp.max(wp.dot(u1, nrm), wp.dot(u2, nrm)) > WEDGE_TOL:
                            best = s
                            best_xi = c[0]
                            best_g = c[1]
    if best < 0 or not near_inside:
        contact_slot[n] = -1
        contact_fs[n] = zero
        return
    xi = wp.clamp(best_xi, zero, one)
    ia = best
    ib = slot_end(best)
    ab_c = x[ib] - x[ia]
    t_hat = ab_c / wp.length(ab_c)
    n_hat = wp.vec2d(t_hat[1], -t_hat[0])
    # penalty Kc = kn·A_node [Pa = N/m per m of overlap], capped at m_min/Δt² (explicit stability, see module doc)
    m_min = wp.min(node_mass[n], wp.min(node_mass[ia], node_mass[ib]))
    kc = wp.min(kn_area * trib, m_min / (dt * dt))
    fn = -kc * best_g
    fs = zero
    if contact_slot[n] == best:
        fs = contact_fs[n]
    vrel = v[n] - ((one - xi) * v[ia] + xi * v[ib])
    fs = fs - kc * wp.dot(vrel, t_hat) * dt
    cap = mu_f * fn
    if wp.abs(fs) > cap:
        wp.atomic_add(energy_acc, CONTACT_DISSIPATED, (wp.abs(fs) - cap) * cap / kc)
        fs = wp.sign(fs) * cap
    contact_slot[n] = best
    contact_fs[n] = fs
    force = fn * n_hat + fs * t_hat
    wp.atomic_add(f, n, force)
    wp.atomic_add(f, ia, -(one - xi) * force)
    wp.atomic_add(f, ib, -xi * force)


class BlockContact:
    """Preallocated spatial hash and per-node contact history; ``apply`` runs once per step."""

    def __init__(self, model):
        self.model = model
        d = model.device
        n = model.node_count
        h = model.host
        lengths = model.mesh.edge_lengths()                       # [E, 3], slot 3e+k has length [e, k]
        self.l_max = float(lengths.max())
        self.h_min = float(np.min(2.0 * h["elem_area0"] / lengths.max(axis=1)))
        self.kn_area = float(np.mean(h["pair_kn_area"])) if len(h["pair_kn_area"]) else 0.0
        self.mu_f = model.tan_phi_r
        # about one hash cell per node keeps the bucket occupancy constant as meshes grow
        dim = int(min(4096, max(16, math.sqrt(n))))
        self.grid = wp.HashGrid(dim, dim, 1, device=d, dtype=wp.float64)
        self.points = wp.zeros(n, dtype=wp.vec3d, device=d)
        self.slot_iface = wp.array(model.topology.slot_iface.astype(np.int32), dtype=wp.int32, device=d)
        self.slot_l0 = wp.array(lengths.ravel(), dtype=wp.float64, device=d)
        self.node_vertex = wp.array(model.topology.node_vertex.astype(np.int32), dtype=wp.int32, device=d)
        self.contact_slot = wp.full(n, -1, dtype=wp.int32, device=d)
        self.contact_fs = wp.zeros(n, dtype=wp.float64, device=d)
        self.active = False
        # The hash of edge midpoints is rebuilt every REBUILD_INTERVAL steps and queried with a margin of
        # h_min/2 beyond the depth limit: correct while no edge midpoint moves more than h_min/4 between
        # rebuilds, i.e. for speeds below h_min/(4·10·Δt) ≈ 0.1·c_p/β^½, far above rock fragment speeds.
        self.rebuild_interval = 10
        self._since_build = self.rebuild_interval

    def apply(self, state, dt: float) -> None:
        """Add the contact forces of the current configuration to state.f; dt [s] drives the friction."""
        if not self.active or self.kn_area == 0.0:
            return
        m = self.model
        radius = 0.5 * self.l_max + self.h_min
        if self._since_build >= self.rebuild_interval:
            wp.launch(compute_edge_midpoints, dim=m.node_count, inputs=[state.x], outputs=[self.points], device=m.device)
            self.grid.build(self.points, radius)
            self._since_build = 0
        self._since_build += 1
        wp.launch(eval_block_contact, dim=m.node_count,
                  inputs=[self.grid.id, self.slot_iface, self.slot_l0, self.node_vertex, m.node_mass,
                          state.pair_dropped, state.x, state.v, wp.float64(self.kn_area), wp.float64(self.mu_f),
                          wp.float64(radius), wp.float64(0.5 * self.h_min), wp.float64(1e-9 * self.h_min),
                          wp.float64(dt)],
                  outputs=[self.contact_slot, self.contact_fs, state.f, state.energy_acc], device=m.device)
