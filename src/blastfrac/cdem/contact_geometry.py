"""Block contact, geometry and contact law of one node against one edge: exposure of element edges, the fan of
blocks around a vertex and its exclusions, edge coordinates, the penalty overlap with its allowance and release,
Coulomb friction, and the candidate test (cdem/contact.py explains the scheme; constants of the scheme here)."""

from __future__ import annotations

import warp as wp

XI_TOL = wp.constant(wp.float64(1.0e-9))     # ξ range tolerance: a node exactly at an edge's end (flush corners)
WEDGE_TOL = wp.constant(wp.float64(0.01))    # sine of the least angle (0.6°) the node's element must face the edge
vec5d = wp.types.vector(length=5, dtype=wp.float64)
vec6d = wp.types.vector(length=6, dtype=wp.float64)
MAX_FAN = wp.constant(64)                     # bound on the pairs walked around one vertex (a fan has ~6)
KC_CAP = wp.constant(wp.float64(0.25))        # Kc ≤ KC_CAP·m_min/Δt²: ω_c·Δt ≤ 0.71, node against edge
FAN_CACHE = wp.constant(8)                    # cached fan candidates of a node (≤ 4 seen in the demo; more: walk)

HIST_FS, HIST_D0, HIST_P, HIST_KC = 0, 1, 2, 3   # BlockContact.contact_state columns: Fs, d0, p, Kc

LOSS_SLIP = 0          # BlockContact.loss_acc slots: Coulomb slip work [J/m]
LOSS_PENALTY = 1       # penalty and tangential elastic energy dropped when a contact ends or changes edge [J/m]



@wp.func
def slot_exposed(slot: wp.int32, slot_iface: wp.array(dtype=wp.int32), pair_mode: wp.array(dtype=wp.int32)):
    """True if element edge slot is exposed (METHOD §1.4): a mesh-boundary edge or an interface whose two
    springs have both broken (dropped or not)."""
    q = slot_iface[slot]
    if q < 0:
        return True
    return pair_mode[2 * q] != 0 and pair_mode[2 * q + 1] != 0


@wp.func
def slot_open(slot: wp.int32, slot_iface: wp.array(dtype=wp.int32), pair_dropped: wp.array(dtype=wp.int32)):
    """True if element edge slot is a mesh-boundary edge or an interface with a dropped pair."""
    q = slot_iface[slot]
    if q < 0:
        return True
    return pair_dropped[2 * q] != 0 or pair_dropped[2 * q + 1] != 0


@wp.func
def slot_end(slot: wp.int32):
    """Node at the far end of element-local edge slot 3e+k (local vertex (k+1) mod 3)."""
    return 3 * (slot // 3) + (slot % 3 + 1) % 3


@wp.func
def slot_prev(node: wp.int32):
    """Element edge slot that ends at node 3e+k (the slot starting at local vertex (k+2) mod 3)."""
    return 3 * (node // 3) + (node % 3 + 2) % 3


@wp.func
def pair_other(p: wp.int32, node: wp.int32, pair_i: wp.array(dtype=wp.int32), pair_j: wp.array(dtype=wp.int32)):
    """The node of pair p that is not node."""
    o = pair_j[p]
    if o == node:
        o = pair_i[p]
    return o


@wp.func
def next_pair(p: wp.int32, node: wp.int32, node_pairs: wp.array(dtype=wp.vec2i)):
    """The pair of node other than p (−1 if none): the next step of a walk around the node's vertex."""
    pp = node_pairs[node]
    q = pp[0]
    if q == p:
        q = pp[1]
    return q


@wp.func
def fan_exclusions(
    n: wp.int32,
    node_pairs: wp.array(dtype=wp.vec2i),
    fan_index: wp.array(dtype=wp.int32),
    pair_i: wp.array(dtype=wp.int32),
    pair_j: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
):
    """Bit mask over the nodes at n's original vertex (bit fan_index[m]) of those whose element's edges at the
    vertex n may not contact: one *undropped* pair away (the spring stage carries that contact), or joined
    to n by a chain of *intact* pairs (same block). Each node has at most two pairs, so the pairs at a vertex
    form a chain (boundary vertex) or a cycle (interior vertex); walk it both ways from n, up to the first
    broken pair after the first step."""
    mask = wp.int64(0)
    for side in range(2):
        cur = wp.int32(n)
        p = wp.int32(node_pairs[n][side])
        k = wp.int32(0)
        intact = bool(True)
        while p >= 0 and k < MAX_FAN:
            k = k + 1
            nxt = wp.int32(-1)
            if pair_dropped[p] == 0:
                nxt = pair_other(p, cur, pair_i, pair_j)
                intact = intact and pair_mode[p] == 0
            if nxt >= 0 and nxt != n and (k == 1 or intact):
                mask = mask | (wp.int64(1) << wp.int64(fan_index[nxt]))
            if nxt < 0 or nxt == n or not intact:
                p = -1                                  # beyond a broken pair nothing more is excluded
            else:
                p = next_pair(p, nxt, node_pairs)
                cur = nxt
    return mask


@wp.func
def in_mask(mask: wp.int64, node: wp.int32, fan_index: wp.array(dtype=wp.int32)):
    """True if node's bit is set in a fan_exclusions mask."""
    return ((mask >> wp.int64(fan_index[node])) & wp.int64(1)) != wp.int64(0)


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


@wp.func
def penalty_overlap(
    history: wp.int32, pen: wp.float64, d0_prev: wp.float64, p_prev: wp.float64,
    kc_prev: wp.float64, kc: wp.float64,
):
    """Overlap p [m] the penalty acts on, the new allowance d0 [m] and the penalty energy dropped [J/m].

    pen = −g > 0 is the geometric overlap. history: 0 new contact, 1 same edge as the last step,
    2 another edge than the last step (p_prev, kc_prev: overlap and stiffness of the last step).
    """
    zero = wp.float64(0.0)
    half = wp.float64(0.5)
    p = zero
    d0 = pen
    lost = zero
    if history == 1:
        d0 = wp.min(d0_prev, pen)                      # the allowance follows a node that moves back out
        p = pen - d0
        if kc > kc_prev and p > zero:                  # stiffer now: keep the force, not the overlap
            p_new = p * kc_prev / kc
            lost = half * kc_prev * p * p - half * kc * p_new * p_new
            p = p_new
            d0 = pen - p
    elif history == 2:
        pc = p_prev * wp.min(wp.float64(1.0), kc_prev / kc)   # force carried over, never larger
        p = wp.min(pen, pc)
        d0 = pen - p
        lost = half * kc_prev * p_prev * p_prev - half * kc * p * p
    return wp.vec3d(p, d0, lost)


@wp.func
def release_overlap(p_prev: wp.float64, p_raw: wp.float64):
    """Signed overlap [m] of the step in which a contact separates (p_prev > 0 last step, p_raw < 0 now).

    Leapfrog conserves ½v^{n−½}·M·v^{n+½} + ½Kc·p_n² exactly while the contact holds; cutting the force
    to zero at the first step with p_raw < 0 gains ½Kc·p_prev·|p_raw| (up to (ω_cΔt)²/4 of the impact
    energy, 11 % at ω_cΔt = 0.8). A pull Kc·q with q = ½·p_raw·p_prev/(p_prev − p_raw) < 0 for this one
    step takes the same energy back to first order (0.3 % left at ω_cΔt = 0.8, checked on a 1D impact).
    """
    return wp.float64(0.5) * p_raw * p_prev / (p_prev - p_raw)


@wp.func
def coulomb_update(fs: wp.float64, kc: wp.float64, slip_rate: wp.float64, dt: wp.float64, cap: wp.float64):
    """Incremental tangential force Fs ← Fs − Kc·v_t·Δt capped at |Fs| ≤ cap; returns (Fs, slip work [J/m])."""
    f = fs - kc * slip_rate * dt
    work = wp.float64(0.0)
    if wp.abs(f) > cap:
        work = (wp.abs(f) - cap) * cap / kc
        f = wp.sign(f) * cap
    return wp.vec2d(f, work)


@wp.func
def consider_edge(
    s: wp.int32, c: wp.vec3d, corner_other: wp.int32, corner_exposed: wp.int32, xn: wp.vec2d, u1: wp.vec2d,
    u2: wp.vec2d, x: wp.array(dtype=wp.vec2d), slot_iface: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32), st: vec5d, max_depth: wp.float64, touch_tol: wp.float64,
):
    """Update the search state st = (best edge, its ξ, its g, distance to the nearest edge, 1 if the node is
    behind that nearest edge) with edge slot s, c = edge_coords of the node against it (module doc, "Which
    edge"). corner_other: −1, or for an edge ending at the node's own vertex, the other edge of its element
    at that vertex; corner_exposed: 1 or 0 if the caller knows whether that edge is exposed (the fan cache's
    codes do), −1 to look it up in the spring states."""
    zero = wp.float64(0.0)
    s_end = slot_end(s)
    on_edge = c[0] >= -XI_TOL and c[0] <= wp.float64(1.0) + XI_TOL
    dist = c[2]
    if not on_edge:
        dist = dist * wp.float64(1.000000001)        # an edge's interior wins ties with its ends
    best = st[0]
    best_xi = st[1]
    best_g = st[2]
    near_d = st[3]
    near_inside = st[4]
    valid = bool(False)
    if on_edge and c[1] < zero and c[1] > -max_depth:
        ab = x[s_end] - x[s]
        nrm = wp.vec2d(ab[1], -ab[0]) / wp.length(ab)
        valid = wp.max(wp.dot(u1, nrm), wp.dot(u2, nrm)) > WEDGE_TOL
    if corner_other < 0:
        # inside test: the nearest exposed edge must not have the node in front of it
        if dist < near_d:
            near_d = dist
            near_inside = zero
            if on_edge and c[1] <= touch_tol:
                near_inside = wp.float64(1.0)
    else:
        # an edge touching the node at its end says nothing about the inside test unless the node is inside
        # that element's corner: behind this edge and behind the other exposed edge of the corner
        if valid:
            exposed = corner_exposed != 0
            if corner_exposed < 0:
                exposed = slot_exposed(corner_other, slot_iface, pair_mode)
            if exposed:
                valid = edge_coords(xn, x[corner_other], x[slot_end(corner_other)])[1] <= touch_tol
        if valid and dist < near_d:
            near_d = dist
            near_inside = wp.float64(1.0)
    # contact candidate: keep the shallowest
    if valid and (best < zero or c[1] > best_g):
        best = wp.float64(s)
        best_xi = c[0]
        best_g = c[1]
    return vec5d(best, best_xi, best_g, near_d, near_inside)
