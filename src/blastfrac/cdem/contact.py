"""Node-to-edge frictional penalty contact between blocks (METHOD §1.4–1.5).

**Targets and candidates.** Target edges are the *exposed* element edges of METHOD §1.4: mesh-boundary
edges and interfaces whose two springs have both broken (dropped or not). A node is a candidate if one of
its own element's edges at it is exposed (the others exit at once). Nodes on an *open* face (a boundary
edge, or an interface with a dropped pair) are matched to every exposed edge near them through a spatial
hash (edges sampled at spacing ≤ ℓ_ref, see ``BlockContact``), so the cost is linear in the number of
nodes. Nodes whose broken faces are all still held by undropped springs, the bulk of a crushed zone, only
test the other blocks at their own vertex (the nodes of that vertex, a list of ~6, no hash): that is where
their broken springs can carry them into a block they are not paired with. An open face that comes within
h_min of such a block "wakes" it for ``near_window`` steps, and its held nodes search the hash too, so they
cannot enter the open block unseen either. Running over all nodes gives both passes (A→B and B→A).

**Geometry.** Node x against edge a→b of length L: ξ = (x − x_a)·t̂/L and g = (x − x_a)·n̂ [m],
with n̂ = (t_y, −t_x) the outward normal of a counter-clockwise element (TriMesh orients them so).

**Shared vertices.** The faces of a crack belong to neighbouring elements and meet at the original mesh
vertices, so a node lies at the end of the opposite face's edge. Such a node/edge pair is a genuine contact
unless the spring stage already carries it: ``fan_exclusions`` skips an edge ending at the node's own
vertex only when the node and the edge's node at that vertex are (a) one *undropped* pair apart (the broken
or intact spring between them is that contact), or (b) joined by a chain of *intact* pairs around the vertex
(same block: a degenerate corner contact). A chain through broken pairs does not exclude: broken springs
slide up to L0/2 and open up to L0 before they drop, and a node carried by them into a third block of the
fan must meet its edges. (Excluding *every* edge that ends at the node's vertex, as this module once did,
meant that crack faces never touched once their springs dropped, and fragments passed through each other;
excluding whole chains of undropped pairs left nodes 0.3·h deep in the crushed zone of a blast.)

**Which edge.**
1. Candidates: 0 ≤ ξ ≤ 1 and −h_min/2 < g < 0 (behind the edge), and the node's own element
   faces the front of the edge (one of its two edges at the node points in front by > 0.6°).
2. The contact edge is the candidate with the least penetration (largest g).
3. Inside test: the exposed edge nearest to the node (distance to the segment) must not have the
   node in front of it, else the node is outside that block. Edges that end at the node's own vertex
   touch it at their end whatever side it is on, so they take part only when the node is inside that
   element's corner (behind the edge and behind the other exposed edge of the element there); otherwise
   a block merely touching the node's vertex vetoed its contact with another block (0.16·h deep).
A node that has just crossed one face of a block is also behind its other faces within h_min/2
(2 mm behind the neighbouring face of a 1 cm block); taking the deepest of these gave forces of
Kc·2 mm on first touch. (1) stops a face that is collinear with one of the node's own faces
(flush blocks) from being taken for a round-off g < 0; (3) rejects a node outside a block near
an acute corner, which is behind one face while in front of the other.

**First contact (overlap allowance).** A contact may be *found* already overlapping: a node of a crack face
at the end of the opposite edge, a node crossing an edge within one step, a compressed crack face handed
over by the spring stage when its pair drops. A penalty on that whole overlap releases ½Kc·g² of energy
that was never stored (Kc ≈ 10¹² N/m per m: 0.5 J/m for 1 µm, on every such node) and throws the node
out: this is what blew fractured runs up. So the penalty acts on the overlap *beyond* an allowance d0 [m]
set when the contact is found: Fn = Kc·p, p = −g − d0 ≥ 0, d0 = −g at first detection (the force starts
from zero and grows while the node keeps approaching). d0 only decreases: when the node moves back out
(−g < d0) it follows, d0 = −g, so the node leaves at p = 0, and one that returns to the surface meets the
full penalty. The potential ½Kc·p² is zero whenever d0 changes, so this is never a source of energy. The
price is that an overlap present at detection is kept, not pushed out (at most the approach of one step
for an ordinary contact); the blast test checks that blocks do not end up inside each other.
When the contact moves to another edge (sliding across a vertex) the overlap p is carried over (scaled by
Kc_old/Kc_new if Kc grew) so the normal force is continuous; when Kc grows on the same edge (Δt fell) p is
scaled the same way.

**Release.** Leapfrog conserves ½v^{n−½}·M·v^{n+½} + ½Kc·p_n² exactly while a contact holds, and entry at
p = 0 is exact, but cutting the force at the first step with p < 0 gains ½Kc·p_prev·|p| (up to (ω_cΔt)²/4
of the normal impact energy: 11 % at ω_cΔt = 0.8). That step applies a pull Kc·q, q = ½p·p_prev/(p_prev − p)
(``release_overlap``), which takes the gain back to first order; a sliding contact's last friction impulse
is corrected by the same factor. With Kc ≤ KC_CAP·m_min/Δt² (ω_cΔt ≤ 0.71) the elastic rebound tests
close to 1 %.

**Forces** (per unit thickness). Normal Fn = Kc·p [N/m] with Kc = kn·A_node [Pa], kn [Pa/m] the interface
stiffness per area and A_node [m] half the reference length of the node's own exposed edges, capped at
KC_CAP·m_min/Δt² (m_min the smallest of the three node masses [kg/m]). Tangential Fs is incremental,
Fs ← Fs − Kc·(v_rel·t̂)·Δt, capped at μ·Fn with μ = tan φ_r; its history is kept per node and reset when
the contact edge changes. Reactions go to the edge's nodes with weights (1 − ξ, ξ), so linear momentum is
conserved to round-off. The slip work and the penalty energy that disappears (contact lost while p > 0,
carried overlap smaller, friction spring reset) go to energy_acc[CONTACT_DISSIPATED], so the energy budget
still closes; ``BlockContact.losses()`` keeps them apart and ``stored_energy()`` gives the energy held by
active contacts.

**Cost.** The hash holds sample points of every edge (rebuilt every 10 steps); an open node that found nothing
within h_min skips the next 10 searches (the same speed bound as the rebuild). Held broken faces, the bulk of a
crushed zone, would make every step cost what its cracking made (7,000 of 11,900 nodes walking their fan at the
end of the demo), so the pass works from caches that change only when a spring does (``BlockContact.fan_cache``):

- per node, its tributary length and open flag, its fan_exclusions mask and its fan candidates: the nodes at its
  vertex of other blocks, not excluded, with an exposed edge there (at most FAN_CACHE; more: walk the fan). They
  depend on spring states only; mark_pair_changes compares those with the last step's and refresh_fan_cache
  rebuilds the caches of the nodes at both vertices of a changed spring's interface;
- select_contact_nodes lists the nodes the contact pass has anything to do for, from the caches: a held node
  without contact only if one of its candidates passes the corner sign test and one of that corner's exposed
  edges may pass consider_edge (edge_may_take, a conservative ξ and wedge test). At the demo's end ~200 of
  ~5,000 such nodes are listed. eval_block_contact runs over the list in node order and makes every decision
  again, so the result is that of one pass over all nodes, to the last bit on a CPU;
- the hash is a cell grid of our own with the cells and the point order of wp.HashGrid (the same points met in the
  same order), each cell's points stored together with the exposure of their edge (kept by mark_pair_changes):
  a query reads memory in sequence and loads no spring state;
- the launches are recorded once and replayed (``BlockContact._launch``): packing ~50 arguments costs more than a
  pass over the nodes of a small mesh.

With ``fan_cache`` off every node is evaluated as before (wp.HashGrid, every held node walks its fan; ~15 %
slower than the code before the cache, a reference only). Demo end state (3,966 blocks, 36 % of the springs
broken, benchmarks/contact_cache.py, CPU): the rock step costs ×2.1–2.8 the intact one (×3.6–4.1 before the
cache, the intact step unchanged); what is left is mostly the contact of ~1,200 held nodes in contact and the
hash search of ~300 open ones. Before the cache, on 59k elements (CPU): ×1.35 per step on nearly intact rock,
×2.9 with 17 % of the springs broken (×1.4 with ``held_faces`` off, at the price of 0.3·h overlaps in the
crushed zone).

**Stable step** (METHOD §1.7). ModelBuilder doubles the spring row sums of a breakable model, an allowance
of 2·K_c per contact with K_c = kn·A_node of a node whose edges are all exposed (the springs of those edges
had the same total stiffness). ``BlockContact.stable_dt()`` is the Gershgorin bound with every spring intact
*and* every node in one such contact; model.stable_dt is below it (checked in the tests), and the cap keeps
single contacts stable at nodes with little spring allowance (mesh-boundary corners).
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from ..model.model import CONTACT_DISSIPATED

XI_TOL = wp.constant(wp.float64(1.0e-9))     # ξ range tolerance: a node exactly at an edge's end (flush corners)
WEDGE_TOL = wp.constant(wp.float64(0.01))    # sine of the least angle (0.6°) the node's element must face the edge
vec5d = wp.types.vector(length=5, dtype=wp.float64)
vec6d = wp.types.vector(length=6, dtype=wp.float64)
MAX_FAN = wp.constant(64)                     # bound on the pairs walked around one vertex (a fan has ~6)
KC_CAP = wp.constant(wp.float64(0.25))        # Kc ≤ KC_CAP·m_min/Δt²: ω_c·Δt ≤ 0.71, node against edge
FAN_CACHE = wp.constant(8)                    # cached fan candidates of a node (≤ 4 seen in the demo; more: walk)

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
    s: wp.int32, c: wp.vec3d, corner_other: wp.int32, xn: wp.vec2d, u1: wp.vec2d, u2: wp.vec2d,
    x: wp.array(dtype=wp.vec2d), slot_iface: wp.array(dtype=wp.int32), pair_mode: wp.array(dtype=wp.int32),
    st: vec5d, max_depth: wp.float64, touch_tol: wp.float64,
):
    """Update the search state st = (best edge, its ξ, its g, distance to the nearest edge, 1 if the node is
    behind that nearest edge) with edge slot s, c = edge_coords of the node against it (module doc, "Which
    edge"). corner_other: −1, or for an edge ending at the node's own vertex, the other edge of its element
    at that vertex."""
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
        if valid and slot_exposed(corner_other, slot_iface, pair_mode):
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


@wp.kernel
def compute_edge_samples(
    x: wp.array(dtype=wp.vec2d),
    sample_slot: wp.array(dtype=wp.int32),
    sample_frac: wp.array(dtype=wp.float64),
    points: wp.array(dtype=wp.vec3d),
):
    """Hash points: each element edge is sampled at fixed fractions, at most ℓ_ref apart (see BlockContact)."""
    i = wp.tid()
    s = sample_slot[i]
    xa = x[s]
    m = xa + sample_frac[i] * (x[slot_end(s)] - xa)
    points[i] = wp.vec3d(m[0], m[1], wp.float64(0.0))


@wp.func
def cell_coord(v: wp.float64):
    """Cell coordinate of a scaled position, as wp.HashGrid computes it (floor, clamped to the int range)."""
    c = wp.floor(v)
    out = wp.int32(0)                                 # NaN
    if c >= wp.float64(2147483646.0):
        out = wp.int32(2147483646)
    elif c >= wp.float64(-2147483648.0):
        out = wp.int32(c)
    elif c < wp.float64(-2147483648.0):
        out = wp.int32(-2147483647) - wp.int32(1)
    return out


@wp.func
def cell_wrap(c: wp.int32, dim: wp.int32):
    """Physical cell of virtual cell coordinate c: non-negative modulo, as wp.HashGrid."""
    r = c
    if r < 0 or r >= dim:
        r = c % dim
        if r < 0:
            r = r + dim
    return r


@wp.func
def cell_end(start: wp.int32, end: wp.int32, dim: wp.int32):
    """Last cell coordinate of a query, at most one pass over a dimension (as wp.HashGrid)."""
    out = end
    if wp.int64(end) - wp.int64(start) >= wp.int64(dim):
        out = start + (dim - 1)
    return out


@wp.kernel
def compute_sample_cells(
    x: wp.array(dtype=wp.vec2d),
    sample_slot: wp.array(dtype=wp.int32),
    sample_frac: wp.array(dtype=wp.float64),
    slot_iface: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    cell_inv: wp.float64,
    dim: wp.int32,
    sample_xy: wp.array(dtype=wp.vec2d),
    sample_code: wp.array(dtype=wp.int32),
    keys: wp.array(dtype=wp.int32),
    values: wp.array(dtype=wp.int32),
):
    """Hash points of the cell grid (BlockContact "Hash"): the same points as compute_edge_samples, their code
    (slot + 1 on an exposed edge, −(slot + 1) on another) and their cell (its row-major index, the cell
    wp.HashGrid puts them in) for the sort."""
    i = wp.tid()
    s = sample_slot[i]
    xa = x[s]
    m = xa + sample_frac[i] * (x[slot_end(s)] - xa)
    sample_xy[i] = m
    code = -(s + 1)
    if slot_exposed(s, slot_iface, pair_mode):
        code = s + 1
    sample_code[i] = code
    keys[i] = cell_wrap(cell_coord(m[1] * cell_inv), dim) * dim + cell_wrap(cell_coord(m[0] * cell_inv), dim)
    values[i] = i


@wp.kernel
def gather_sample_cells(
    keys: wp.array(dtype=wp.int32),
    values: wp.array(dtype=wp.int32),
    count: wp.int32,
    sample_xy: wp.array(dtype=wp.vec2d),
    sample_code: wp.array(dtype=wp.int32),
    cell_starts: wp.array(dtype=wp.int32),
    cell_ends: wp.array(dtype=wp.int32),
    sorted_xy: wp.array(dtype=wp.vec2d),
    sorted_code: wp.array(dtype=wp.int32),
    sample_pos: wp.array(dtype=wp.int32),
):
    """After the (stable) sort by cell: each cell's range and its points in order, stored contiguously, with
    their codes (mark_pair_changes keeps the sign of sorted_code up to date)."""
    j = wp.tid()
    c = keys[j]
    i = values[j]
    sorted_xy[j] = sample_xy[i]
    sorted_code[j] = sample_code[i]
    sample_pos[i] = j
    if j == 0:
        cell_starts[c] = j
    elif keys[j - 1] != c:
        cell_starts[c] = j
    if j == count - 1:
        cell_ends[c] = j + 1
    elif keys[j + 1] != c:
        cell_ends[c] = j + 1


@wp.func
def corner_inside(
    xn: wp.vec2d, other: wp.int32, ex1: bool, ex2: bool, x: wp.array(dtype=wp.vec2d), touch_tol: wp.float64,
):
    """True if xn is behind both exposed edges of other's element at other's vertex (within touch_tol): the
    cheap sign test of the held-face search, done before the full evaluation (module doc, "Cost")."""
    zero = wp.float64(0.0)
    sb = slot_prev(other)
    xc = x[other]
    t1 = x[slot_end(other)] - xc
    t2 = xc - x[sb]
    r1 = xn - xc
    r2 = xn - x[sb]
    c1 = t1[1] * r1[0] - t1[0] * r1[1]
    c2 = t2[1] * r2[0] - t2[0] * r2[1]
    tol2 = touch_tol * touch_tol
    inside1 = (not ex1) or c1 <= zero or c1 * c1 <= tol2 * wp.dot(t1, t1)
    inside2 = (not ex2) or c2 <= zero or c2 * c2 <= tol2 * wp.dot(t2, t2)
    return inside1 and inside2


@wp.func
def edge_may_take(xn: wp.vec2d, xa: wp.vec2d, xb: wp.vec2d, e1: wp.vec2d, e2: wp.vec2d):
    """False only if consider_edge certainly rejects edge a→b for a node at xn whose element's edges at the node
    are e1, e2 (not normalised): xn projects outside the edge (ξ beyond XI_TOL) or the node's element faces away
    from it (wedge test). Without square roots or divisions; its margins (1e-12 of |r|·|ab|, 1e-6 of the wedge
    threshold) are far above the round-off of either form, so it never rejects what consider_edge would take."""
    ab = xb - xa
    r = xn - xa
    l2 = wp.dot(ab, ab)
    slack = wp.float64(1.0e-12) * (wp.dot(r, r) + l2)           # ≥ 1e-12·|r|·|ab|
    d = wp.dot(r, ab)                                            # ξ·|ab|²
    if d < -XI_TOL * l2 - slack or d > (wp.float64(1.0) + XI_TOL) * l2 + slack:
        return False
    nrm = wp.vec2d(ab[1], -ab[0])                                # outward normal times |ab|
    w2 = WEDGE_TOL * WEDGE_TOL * (wp.float64(1.0) - wp.float64(1.0e-6)) * l2
    w1 = wp.dot(e1, nrm)
    if w1 > wp.float64(0.0) and w1 * w1 > w2 * wp.dot(e1, e1):
        return True
    w = wp.dot(e2, nrm)
    return w > wp.float64(0.0) and w * w > w2 * wp.dot(e2, e2)


@wp.func
def corner_consider(
    other: wp.int32, ex1: bool, ex2: bool, xn: wp.vec2d, u1: wp.vec2d, u2: wp.vec2d,
    x: wp.array(dtype=wp.vec2d), slot_iface: wp.array(dtype=wp.int32), pair_mode: wp.array(dtype=wp.int32),
    st: vec5d, max_depth: wp.float64, touch_tol: wp.float64,
):
    """consider_edge for the exposed edges of other's element at the vertex (a node inside that corner)."""
    sb = slot_prev(other)
    xc = x[other]
    out = st
    if ex1:
        out = consider_edge(other, edge_coords(xn, xc, x[slot_end(other)]), sb, xn, u1, u2,
                            x, slot_iface, pair_mode, out, max_depth, touch_tol)
    if ex2:
        out = consider_edge(sb, edge_coords(xn, x[sb], xc), other, xn, u1, u2, x,
                            slot_iface, pair_mode, out, max_depth, touch_tol)
    return out


@wp.func
def fan_cache_build(
    n: wp.int32,
    excl: wp.int64,
    node_vertex: wp.array(dtype=wp.int32),
    vertex_start: wp.array(dtype=wp.int32),
    vertex_nodes: wp.array(dtype=wp.int32),
    fan_index: wp.array(dtype=wp.int32),
    slot_iface: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    fan_cand: wp.array2d(dtype=wp.int32),
    fan_count: wp.array(dtype=wp.int32),
):
    """Cache the fan candidates of node n: the nodes at its vertex, in vertex order, of another element, not in
    its exclusion mask excl and with an exposed edge at the vertex, as 4·node + (1 if its edge 'node' is
    exposed) + (2 if its edge ending at the node is); fan_count −1 if more than FAN_CACHE (walk the fan)."""
    e = n // 3
    vtx = node_vertex[n]
    k = wp.int32(0)
    for j in range(vertex_start[vtx], vertex_start[vtx + 1]):
        other = vertex_nodes[j]
        if other // 3 != e:
            if not in_mask(excl, other, fan_index):
                code = wp.int32(0)
                if slot_exposed(other, slot_iface, pair_mode):
                    code = code + 1
                if slot_exposed(slot_prev(other), slot_iface, pair_mode):
                    code = code + 2
                if code != 0:
                    if k < FAN_CACHE:
                        fan_cand[n, k] = 4 * other + code
                    k = k + 1
    if k > FAN_CACHE:
        k = wp.int32(-1)
    fan_count[n] = k


@wp.func
def held_search(
    n: wp.int32,
    excl: wp.int64,
    use_cache: wp.int32,
    node_vertex: wp.array(dtype=wp.int32),
    vertex_start: wp.array(dtype=wp.int32),
    vertex_nodes: wp.array(dtype=wp.int32),
    fan_index: wp.array(dtype=wp.int32),
    slot_iface: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    max_depth: wp.float64,
    touch_tol: wp.float64,
    fan_cand: wp.array2d(dtype=wp.int32),
    fan_count: wp.array(dtype=wp.int32),
):
    """Search state (consider_edge) of held node n: the other blocks at its own vertex only (module doc). With
    use_cache, over its cached fan candidates (fan_cache_build: the same nodes in the same order, so the same
    result); otherwise, or if the fan overflowed the cache, by walking the vertex's node list."""
    e = n // 3
    zero = wp.float64(0.0)
    xn = x[n]
    st = vec5d(wp.float64(-1.0), zero, zero, wp.float64(1.0e300), zero)
    # the node's element wedge (unit vectors along its two edges at the node), only once a corner test passes
    have_u = bool(False)
    u1 = wp.vec2d(zero, zero)
    u2 = wp.vec2d(zero, zero)
    cnt = wp.int32(-1)
    if use_cache != 0:
        cnt = fan_count[n]
    if cnt >= 0:
        for k in range(cnt):
            code = fan_cand[n, k]
            other = code >> 2
            ex1 = (code & 1) != 0
            ex2 = (code & 2) != 0
            if corner_inside(xn, other, ex1, ex2, x, touch_tol):
                if not have_u:
                    u1 = wp.normalize(x[slot_end(n)] - xn)
                    u2 = wp.normalize(x[slot_prev(n)] - xn)
                    have_u = True
                st = corner_consider(other, ex1, ex2, xn, u1, u2, x, slot_iface, pair_mode, st, max_depth, touch_tol)
    else:
        vtx = node_vertex[n]
        for j in range(vertex_start[vtx], vertex_start[vtx + 1]):
            other = vertex_nodes[j]
            if other // 3 != e:
                if not in_mask(excl, other, fan_index):
                    ex1 = slot_exposed(other, slot_iface, pair_mode)
                    ex2 = slot_exposed(slot_prev(other), slot_iface, pair_mode)
                    # only a node inside the corner (behind both exposed edges) can be a contact: a cheap sign
                    # test first, the full evaluation for the few that pass
                    if ex1 or ex2:
                        if corner_inside(xn, other, ex1, ex2, x, touch_tol):
                            if not have_u:
                                u1 = wp.normalize(x[slot_end(n)] - xn)
                                u2 = wp.normalize(x[slot_prev(n)] - xn)
                                have_u = True
                            st = corner_consider(other, ex1, ex2, xn, u1, u2, x, slot_iface, pair_mode, st,
                                                 max_depth, touch_tol)
    return st


@wp.kernel
def mark_pair_changes(
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
    pair_vertex: wp.array(dtype=wp.int32),
    step: wp.int32,
    seen_mode: wp.array(dtype=wp.int32),
    seen_dropped: wp.array(dtype=wp.int32),
    vertex_stamp: wp.array(dtype=wp.int32),
    counts: wp.array(dtype=wp.int32),
    dirty_vertices: wp.array(dtype=wp.int32),
    iface_slots: wp.array(dtype=wp.vec2i),
    slot_samples: wp.array(dtype=wp.vec2i),
    sample_pos: wp.array(dtype=wp.int32),
    sorted_code: wp.array(dtype=wp.int32),
):
    """List (once each, counts[0] of them) the vertices whose fan caches a change of spring p's state since the
    last call makes stale: both ends of p's interface (the exposure of its edges counts at both vertices, the
    exclusion chains at p's own); and the sorted_code sign of the hash points on the interface's two edges."""
    p = wp.tid()
    mode = pair_mode[p]
    dropped = pair_dropped[p]
    if mode != seen_mode[p] or dropped != seen_dropped[p]:
        seen_mode[p] = mode
        seen_dropped[p] = dropped
        q = p // 2
        for k in range(2):
            vtx = pair_vertex[2 * q + k]
            if wp.atomic_exch(vertex_stamp, vtx, step) != step:
                dirty_vertices[wp.atomic_add(counts, 0, 1)] = vtx
        exposed = pair_mode[2 * q] != 0 and pair_mode[2 * q + 1] != 0
        for k in range(2):
            sl = iface_slots[q][k]
            code = -(sl + 1)
            if exposed:
                code = sl + 1
            rng = slot_samples[sl]
            for i in range(rng[0], rng[0] + rng[1]):
                sorted_code[sample_pos[i]] = code


@wp.func
def node_faces(
    n: wp.int32,
    slot_iface: wp.array(dtype=wp.int32),
    slot_l0: wp.array(dtype=wp.float64),
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
):
    """(tributary length [m], 1 if open) of node n. The tributary length is half of each exposed edge of the
    node's own element at the node; 0: not a candidate (edges only ever become exposed, so such a node never
    had a contact). Open: one of those edges is a mesh-boundary edge or an interface with a dropped pair."""
    zero = wp.float64(0.0)
    half = wp.float64(0.5)
    sp = slot_prev(n)
    trib = zero
    if slot_exposed(n, slot_iface, pair_mode):
        trib = trib + half * slot_l0[n]
    if slot_exposed(sp, slot_iface, pair_mode):
        trib = trib + half * slot_l0[sp]
    is_open = zero
    if trib != zero:
        if slot_open(n, slot_iface, pair_dropped) or slot_open(sp, slot_iface, pair_dropped):
            is_open = wp.float64(1.0)
    return wp.vec2d(trib, is_open)


@wp.func
def node_woken(e: wp.int32, elem_near: wp.array(dtype=wp.int32), step: wp.int32, near_window: wp.int32):
    """True if an open face came near element e in the last near_window steps. Flags set in this step are not
    read until the next one (a block woken again earlier in this step's pass reads as not woken)."""
    return elem_near[e] >= step - near_window and elem_near[e] < step


@wp.kernel
def refresh_fan_cache(
    refresh_all: wp.int32,
    counts: wp.array(dtype=wp.int32),
    dirty_vertices: wp.array(dtype=wp.int32),
    node_vertex: wp.array(dtype=wp.int32),
    vertex_start: wp.array(dtype=wp.int32),
    vertex_nodes: wp.array(dtype=wp.int32),
    fan_index: wp.array(dtype=wp.int32),
    slot_iface: wp.array(dtype=wp.int32),
    slot_l0: wp.array(dtype=wp.float64),
    node_pairs: wp.array(dtype=wp.vec2i),
    pair_i: wp.array(dtype=wp.int32),
    pair_j: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
    node_face: wp.array(dtype=wp.vec2d),
    node_flag: wp.array(dtype=wp.int32),
    fan_excl: wp.array(dtype=wp.int64),
    fan_cand: wp.array2d(dtype=wp.int32),
    fan_count: wp.array(dtype=wp.int32),
):
    """Rebuild the caches (node_faces and node_flag, fan_exclusions mask, fan_cache_build list) of every node at
    a listed vertex (every vertex with refresh_all): each thread writes only its own vertex's nodes, from the
    spring states, so the order of the threads does not matter."""
    i = wp.tid()
    vtx = i
    if refresh_all == 0:
        if i >= counts[0]:
            return
        vtx = dirty_vertices[i]
    for j in range(vertex_start[vtx], vertex_start[vtx + 1]):
        n = vertex_nodes[j]
        nf = node_faces(n, slot_iface, slot_l0, pair_mode, pair_dropped)
        node_face[n] = nf
        flag = wp.int32(0)                        # 0 no exposed edge, 1 held, 2 open
        if nf[0] != wp.float64(0.0):
            flag = 1
            if nf[1] != wp.float64(0.0):
                flag = 2
        node_flag[n] = flag
        ex = fan_exclusions(n, node_pairs, fan_index, pair_i, pair_j, pair_mode, pair_dropped)
        fan_excl[n] = ex
        fan_cache_build(n, ex, node_vertex, vertex_start, vertex_nodes, fan_index, slot_iface, pair_mode,
                        fan_cand, fan_count)


@wp.kernel
def list_candidates(node_flag: wp.array(dtype=wp.int32), cand_count: wp.array(dtype=wp.int32),
                    cand_list: wp.array(dtype=wp.int32)):
    """The nodes with an exposed edge at them (node_flag ≠ 0), in node order on a CPU: select_contact_nodes runs
    over them only. Rebuilt when refresh_fan_cache has changed a flag."""
    n = wp.tid()
    if node_flag[n] != 0:
        cand_list[wp.atomic_add(cand_count, 0, 1)] = n


@wp.kernel
def select_contact_nodes(
    cand_list: wp.array(dtype=wp.int32),
    cand_count: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    touch_tol: wp.float64,
    step: wp.int32,
    near_window: wp.int32,
    held_faces: wp.int32,
    elem_near: wp.array(dtype=wp.int32),
    query_after: wp.array(dtype=wp.int32),
    contact_slot: wp.array(dtype=wp.int32),
    node_flag: wp.array(dtype=wp.int32),
    fan_cand: wp.array2d(dtype=wp.int32),
    fan_count: wp.array(dtype=wp.int32),
    counts: wp.array(dtype=wp.int32),
    node_list: wp.array(dtype=wp.int32),
):
    """List (counts[1] of them, in node order on a CPU) the nodes of cand_list eval_block_contact has anything
    to do for; it would leave the others without a write (from the caches: node_flag, fan candidates). A held node without
    contact is listed only if one of its fan candidates passes the corner sign test (held_search makes the same
    test first and finds nothing otherwise) and one of that corner's exposed edges passes edge_may_take."""
    i = wp.tid()
    if i >= cand_count[0]:
        return
    n = cand_list[i]
    flag = node_flag[n]
    if flag == 0:
        return
    is_open = flag == 2
    woken = node_woken(n // 3, elem_near, step, near_window)
    if not (is_open or woken):
        if contact_slot[n] < 0:
            if held_faces == 0:
                return                            # held broken faces not searched (BlockContact.held_faces)
            cnt = fan_count[n]
            if cnt >= 0:
                xn = x[n]
                hit = bool(False)
                for k in range(cnt):
                    code = fan_cand[n, k]
                    other = code >> 2
                    ex1 = (code & 1) != 0
                    ex2 = (code & 2) != 0
                    if not hit and corner_inside(xn, other, ex1, ex2, x, touch_tol):
                        # the corner's exposed edges: can consider_edge take either? (edge_may_take)
                        e1 = x[slot_end(n)] - xn
                        e2 = x[slot_prev(n)] - xn
                        xc = x[other]
                        sb = slot_prev(other)
                        if ex1:
                            hit = edge_may_take(xn, xc, x[slot_end(other)], e1, e2)
                        if ex2 and not hit:
                            hit = edge_may_take(xn, x[sb], xc, e1, e2)
                if not hit:
                    return
    # an open node whose last search found nothing within reach skips the search (BlockContact doc)
    elif is_open and not woken and step < query_after[n] and contact_slot[n] < 0:
        return
    node_list[wp.atomic_add(counts, 1, 1)] = n


@wp.func
def hash_edge(
    s: wp.int32,
    xn: wp.vec2d,
    u1: wp.vec2d,
    u2: wp.vec2d,
    vtx: wp.int32,
    excl: wp.int64,
    is_open: bool,
    node_vertex: wp.array(dtype=wp.int32),
    fan_index: wp.array(dtype=wp.int32),
    slot_iface: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    max_depth: wp.float64,
    touch_tol: wp.float64,
    wake_dist: wp.float64,
    step: wp.int32,
    elem_near: wp.array(dtype=wp.int32),
    sr: vec6d,
):
    """hash_search for one exposed edge s of another element within the search radius: sr = (search state of
    consider_edge, distance to the closest edge). Wakes the edge's block if an open face comes near it."""
    s_end = slot_end(s)
    skip = bool(False)
    corner = wp.int32(-1)
    if node_vertex[s] == vtx:
        skip = in_mask(excl, s, fan_index)
        corner = slot_prev(s)
    elif node_vertex[s_end] == vtx:
        skip = in_mask(excl, s_end, fan_index)
        corner = s_end
    out = sr
    if not skip:
        c = edge_coords(xn, x[s], x[s_end])
        st = consider_edge(s, c, corner, xn, u1, u2, x, slot_iface, pair_mode,
                           vec5d(sr[0], sr[1], sr[2], sr[3], sr[4]), max_depth, touch_tol)
        out = vec6d(st[0], st[1], st[2], st[3], st[4], wp.min(sr[5], c[2]))
        if is_open and c[2] < wake_dist:
            elem_near[s // 3] = step          # wake the block this open face comes near
    return out


@wp.func
def hash_search(
    n: wp.int32,
    is_open: bool,
    excl: wp.int64,
    use_cache: wp.int32,
    grid: wp.uint64,
    points: wp.array(dtype=wp.vec3d),
    sample_slot: wp.array(dtype=wp.int32),
    cell_inv: wp.float64,
    cell_dim: wp.int32,
    cell_starts: wp.array(dtype=wp.int32),
    cell_ends: wp.array(dtype=wp.int32),
    sorted_xy: wp.array(dtype=wp.vec2d),
    sorted_code: wp.array(dtype=wp.int32),
    slot_iface: wp.array(dtype=wp.int32),
    node_vertex: wp.array(dtype=wp.int32),
    fan_index: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    search_radius: wp.float64,
    max_depth: wp.float64,
    touch_tol: wp.float64,
    wake_dist: wp.float64,
    step: wp.int32,
    quiet_steps: wp.int32,
    elem_near: wp.array(dtype=wp.int32),
    query_after: wp.array(dtype=wp.int32),
):
    """Search state (consider_edge) of an open or woken node n over every exposed edge near it, through the
    spatial hash; excl: its fan_exclusions mask. Wakes the blocks an open face comes near and sets the node's
    quiet period (BlockContact doc). With use_cache the points come from the cell grid (the cells wp.HashGrid
    would visit, in its order, each cell's points in its order) with their exposure in sorted_code; without,
    from wp.HashGrid itself."""
    e = n // 3
    zero = wp.float64(0.0)
    xn = x[n]
    vtx = node_vertex[n]
    # the node's element wedge: unit vectors along its two edges at the node
    u1 = wp.normalize(x[slot_end(n)] - xn)
    u2 = wp.normalize(x[slot_prev(n)] - xn)
    sr = vec6d(wp.float64(-1.0), zero, zero, wp.float64(1.0e300), zero, wp.float64(1.0e300))
    r2 = search_radius * search_radius
    if use_cache != 0:
        xs = cell_coord((xn[0] - search_radius) * cell_inv)
        xe = cell_end(xs, cell_coord((xn[0] + search_radius) * cell_inv), cell_dim)
        ys = cell_coord((xn[1] - search_radius) * cell_inv)
        ye = cell_end(ys, cell_coord((xn[1] + search_radius) * cell_inv), cell_dim)
        for cy in range(ys, ye + 1):
            row = cell_wrap(cy, cell_dim) * cell_dim
            for cx in range(xs, xe + 1):
                c = row + cell_wrap(cx, cell_dim)
                for j in range(cell_starts[c], cell_ends[c]):
                    code = sorted_code[j]
                    if code > 0:                       # an exposed edge
                        s = code - 1
                        pt = sorted_xy[j]
                        dx = pt[0] - xn[0]
                        dy = pt[1] - xn[1]
                        # whole hash cells: keep the points within the search radius
                        if s // 3 != e and dx * dx + dy * dy <= r2:
                            sr = hash_edge(s, xn, u1, u2, vtx, excl, is_open, node_vertex, fan_index, slot_iface,
                                           pair_mode, x, max_depth, touch_tol, wake_dist, step, elem_near, sr)
    else:
        query = wp.hash_grid_query(grid, wp.vec3d(xn[0], xn[1], zero), search_radius)
        i = int(0)
        while wp.hash_grid_query_next(query, i):
            s = sample_slot[i]
            p3 = points[i]
            dx = p3[0] - xn[0]
            dy = p3[1] - xn[1]
            # the query returns whole hash cells: keep the points within the search radius
            if s // 3 != e and dx * dx + dy * dy <= r2:
                if slot_exposed(s, slot_iface, pair_mode):
                    sr = hash_edge(s, xn, u1, u2, vtx, excl, is_open, node_vertex, fan_index, slot_iface, pair_mode,
                                   x, max_depth, touch_tol, wake_dist, step, elem_near, sr)
    query_after[n] = 0
    if is_open and sr[0] < zero and sr[5] >= wake_dist:
        query_after[n] = step + quiet_steps
    return vec5d(sr[0], sr[1], sr[2], sr[3], sr[4])


@wp.func
def contact_force(
    n: wp.int32,
    trib: wp.float64,
    st: vec5d,
    node_mass: wp.array(dtype=wp.float64),
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    kn_area: wp.float64,
    mu_f: wp.float64,
    dt: wp.float64,
    contact_slot: wp.array(dtype=wp.int32),
    contact_fs: wp.array(dtype=wp.float64),
    contact_d0: wp.array(dtype=wp.float64),
    contact_p: wp.array(dtype=wp.float64),
    contact_kc: wp.array(dtype=wp.float64),
    f: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
    loss_acc: wp.array(dtype=wp.float64),
):
    """Contact forces of candidate node n (trib: its tributary length [m]) from its search state st
    (hash_search or held_search) and its contact history; see the module doc."""
    zero = wp.float64(0.0)
    one = wp.float64(1.0)
    half = wp.float64(0.5)
    xn = x[n]
    best = int(st[0])
    best_g = st[2]
    near_inside = st[4] > zero
    prev = contact_slot[n]
    p_prev = contact_p[n]
    kc_prev = contact_kc[n]
    fs_prev = contact_fs[n]
    found = best >= 0 and near_inside
    # history: 0 new contact, 1 same edge as the last step, 2 another edge, 3 lost (last step's edge, p > 0)
    history = wp.int32(0)
    edge = best
    if found:
        if prev == best:
            history = 1
        elif prev >= 0:
            history = 2
    elif prev >= 0 and p_prev > zero:
        history = 3
        edge = prev
    else:
        if prev >= 0:                             # contact ends at zero overlap: only its friction spring is dropped
            lost0 = half * fs_prev * fs_prev / kc_prev
            wp.atomic_add(energy_acc, CONTACT_DISSIPATED, lost0)
            wp.atomic_add(loss_acc, LOSS_PENALTY, lost0)
        contact_slot[n] = -1
        contact_fs[n] = zero
        contact_d0[n] = zero
        contact_p[n] = zero
        contact_kc[n] = zero
        return
    ia = edge
    ib = slot_end(edge)
    cg = edge_coords(xn, x[ia], x[ib])
    xi = wp.clamp(cg[0], zero, one)
    ab_c = x[ib] - x[ia]
    t_hat = ab_c / wp.length(ab_c)
    n_hat = wp.vec2d(t_hat[1], -t_hat[0])
    # penalty Kc = kn·A_node [Pa = N/m per m of overlap], capped at KC_CAP·m_min/Δt² (see module doc)
    m_min = wp.min(node_mass[n], wp.min(node_mass[ia], node_mass[ib]))
    kc = wp.min(kn_area * trib, KC_CAP * m_min / (dt * dt))
    fn = zero
    fs = zero
    lost = zero
    keep = bool(True)                             # the node stays in contact with edge after this step
    released = bool(False)
    fs_release = zero
    pen = -cg[1]
    p = zero
    d0 = zero
    if history == 3 or history == 1:
        p_raw = pen - contact_d0[n]
        if p_raw < zero and p_prev > zero:        # separation within the step: release force (module doc)
            q = release_overlap(p_prev, p_raw)
            fn = kc_prev * q
            # a sliding contact's friction impulse is corrected the same way (below); a sticking one is not
            released = wp.abs(fs_prev) >= (one - wp.float64(1.0e-9)) * mu_f * kc_prev * p_prev
            fs_release = fs_prev * q / p_prev
            d0 = pen
            lost = half * fs_prev * fs_prev / kc_prev
        elif history == 3:                        # lost while still overlapping (slid off the edge's end)
            lost = half * kc_prev * p_raw * p_raw + half * fs_prev * fs_prev / kc_prev
        if history == 3:
            keep = False
        elif p_raw >= zero or p_prev == zero:     # ordinary contact on the same edge (or resting at p = 0)
            ov = penalty_overlap(1, pen, contact_d0[n], p_prev, kc_prev, kc)
            p = ov[0]
            d0 = ov[1]
            lost = ov[2]
            fs = fs_prev
            fn = kc * p
    else:
        ov2 = penalty_overlap(history, pen, contact_d0[n], p_prev, kc_prev, kc)
        p = ov2[0]
        d0 = ov2[1]
        lost = ov2[2]
        if history == 2:
            lost = lost + half * fs_prev * fs_prev / kc_prev      # friction history reset on a new edge
        fn = kc * p
    if lost > zero:
        wp.atomic_add(energy_acc, CONTACT_DISSIPATED, lost)
        wp.atomic_add(loss_acc, LOSS_PENALTY, lost)
    vt = wp.dot(v[n] - ((one - xi) * v[ia] + xi * v[ib]), t_hat)
    if fn > zero:
        cu = coulomb_update(fs, kc, vt, dt, mu_f * fn)
        fs = cu[0]
        if cu[1] > zero:
            wp.atomic_add(energy_acc, CONTACT_DISSIPATED, cu[1])
            wp.atomic_add(loss_acc, LOSS_SLIP, cu[1])
    elif released:
        # the same first-order correction of the last step's tangential impulse (|Fs| ≤ μ|Fn| still holds);
        # its work is taken off the slip loss booked in the steps before
        fs = fs_release
        wp.atomic_add(energy_acc, CONTACT_DISSIPATED, -fs * vt * dt)
        wp.atomic_add(loss_acc, LOSS_SLIP, -fs * vt * dt)
    else:
        fs = zero
    if keep:
        contact_slot[n] = edge
        contact_fs[n] = fs
        contact_d0[n] = d0
        contact_p[n] = p
        contact_kc[n] = kc
    else:
        contact_slot[n] = -1
        contact_fs[n] = zero
        contact_d0[n] = zero
        contact_p[n] = zero
        contact_kc[n] = zero
    force = fn * n_hat + fs * t_hat
    wp.atomic_add(f, n, force)
    wp.atomic_add(f, ia, -(one - xi) * force)
    wp.atomic_add(f, ib, -xi * force)



@wp.kernel
def eval_block_contact(
    node_list: wp.array(dtype=wp.int32),
    counts: wp.array(dtype=wp.int32),
    use_cache: wp.int32,
    grid: wp.uint64,
    points: wp.array(dtype=wp.vec3d),
    sample_slot: wp.array(dtype=wp.int32),
    cell_inv: wp.float64,
    cell_dim: wp.int32,
    cell_starts: wp.array(dtype=wp.int32),
    cell_ends: wp.array(dtype=wp.int32),
    sorted_xy: wp.array(dtype=wp.vec2d),
    sorted_code: wp.array(dtype=wp.int32),
    slot_iface: wp.array(dtype=wp.int32),
    slot_l0: wp.array(dtype=wp.float64),
    node_vertex: wp.array(dtype=wp.int32),
    vertex_start: wp.array(dtype=wp.int32),
    vertex_nodes: wp.array(dtype=wp.int32),
    fan_index: wp.array(dtype=wp.int32),
    node_mass: wp.array(dtype=wp.float64),
    node_pairs: wp.array(dtype=wp.vec2i),
    pair_i: wp.array(dtype=wp.int32),
    pair_j: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    kn_area: wp.float64,
    mu_f: wp.float64,
    search_radius: wp.float64,
    max_depth: wp.float64,
    touch_tol: wp.float64,
    wake_dist: wp.float64,
    step: wp.int32,
    near_window: wp.int32,
    quiet_steps: wp.int32,
    held_faces: wp.int32,
    dt: wp.float64,
    node_face: wp.array(dtype=wp.vec2d),
    fan_excl: wp.array(dtype=wp.int64),
    fan_cand: wp.array2d(dtype=wp.int32),
    fan_count: wp.array(dtype=wp.int32),
    elem_near: wp.array(dtype=wp.int32),
    query_after: wp.array(dtype=wp.int32),
    contact_slot: wp.array(dtype=wp.int32),
    contact_fs: wp.array(dtype=wp.float64),
    contact_d0: wp.array(dtype=wp.float64),
    contact_p: wp.array(dtype=wp.float64),
    contact_kc: wp.array(dtype=wp.float64),
    f: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
    loss_acc: wp.array(dtype=wp.float64),
):
    """Contact of each listed node (select_contact_nodes). The tests that listed it are made again here, in
    list order, so that the result is that of one pass over every node in node order (a node's woken flag can
    turn off in the pass)."""
    i = wp.tid()
    if i >= counts[1]:
        return
    n = node_list[i]
    zero = wp.float64(0.0)
    nf = wp.vec2d()
    if use_cache != 0:
        nf = node_face[n]
    else:
        nf = node_faces(n, slot_iface, slot_l0, pair_mode, pair_dropped)
    if nf[0] == zero:
        return                                    # no exposed edge at the node (listed nodes always have one)
    is_open = nf[1] != zero
    woken = node_woken(n // 3, elem_near, step, near_window)
    if not (is_open or woken) and held_faces == 0 and contact_slot[n] < 0:
        return                                    # held broken faces not searched (BlockContact.held_faces)
    if is_open and not woken and step < query_after[n] and contact_slot[n] < 0:
        return
    excl = wp.int64(0)
    if use_cache != 0:
        excl = fan_excl[n]
    else:
        excl = fan_exclusions(n, node_pairs, fan_index, pair_i, pair_j, pair_mode, pair_dropped)
    st = vec5d(wp.float64(-1.0), zero, zero, wp.float64(1.0e300), zero)
    if is_open or woken:
        st = hash_search(n, is_open, excl, use_cache, grid, points, sample_slot, cell_inv, cell_dim, cell_starts,
                         cell_ends, sorted_xy, sorted_code, slot_iface, node_vertex, fan_index, pair_mode, x,
                         search_radius, max_depth, touch_tol, wake_dist, step, quiet_steps, elem_near, query_after)
    elif held_faces != 0:
        # broken faces still held by their springs, not woken: only the other blocks at the node's vertex
        st = held_search(n, excl, use_cache, node_vertex, vertex_start, vertex_nodes, fan_index, slot_iface,
                         pair_mode, x, max_depth, touch_tol, fan_cand, fan_count)
        # nothing found and no contact to end: contact_force would only rewrite the zeros of a node without one
        if st[0] < zero and contact_slot[n] < 0:
            return
    contact_force(n, nf[0], st, node_mass, x, v, kn_area, mu_f, dt, contact_slot, contact_fs, contact_d0,
                  contact_p, contact_kc, f, energy_acc, loss_acc)


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
        # Hash points: every edge sampled at spacing ≤ ℓ_ref (its midpoint if shorter), so a query of radius
        # ½ℓ_ref·1.25 + h_min around a node finds every edge within h_min/2 of it with h_min/2 to spare, however
        # graded the mesh (midpoints alone would need a radius of ½·l_max, the *largest* edge, everywhere).
        L0 = lengths.ravel()
        self.l_ref = float(min(self.l_max, max(2.0 * self.h_min, 0.5 * float(np.median(L0)))))
        k = np.maximum(1, np.ceil(L0 / self.l_ref).astype(np.int64))
        slot = np.repeat(np.arange(len(L0)), k)
        first = np.repeat(np.cumsum(k) - k, k)
        frac = (np.arange(len(slot)) - first + 0.5) / np.repeat(k, k)
        self.sample_slot = wp.array(slot.astype(np.int32), dtype=wp.int32, device=d)
        self.slot_samples = wp.array(np.stack([np.cumsum(k) - k, k], 1).astype(np.int32), dtype=wp.vec2i, device=d)
        self.sample_frac = wp.array(frac, dtype=wp.float64, device=d)
        self.radius = 0.5 * 1.25 * self.l_ref + self.h_min       # 25 % allowance for edges that stretch
        # about one hash cell per point keeps the bucket occupancy constant as meshes grow
        dim = int(min(4096, max(16, math.sqrt(len(slot)))))
        self.grid = wp.HashGrid(dim, dim, 1, device=d, dtype=wp.float64)
        self.points = wp.zeros(len(slot), dtype=wp.vec3d, device=d)
        # The same hash as a cell grid of our own (with the fan cache): the cells wp.HashGrid would hold, each
        # cell's points stored together in its order, so that a query reads them in sequence and meets the same
        # points in the same order (the same results); their exposure is in sorted_code (no loads of the springs).
        # Built from a stable radix sort by cell, as wp.HashGrid builds its own.
        self.cell_dim = dim
        self._key_bits = max(1, int(dim * dim - 1).bit_length())     # cell keys are below 2**_key_bits
        self.cell_inv = 1.0 / self.radius                         # wp.HashGrid: cell width = query radius
        ns = len(slot)
        self._keys = wp.zeros(2 * ns, dtype=wp.int32, device=d)
        self._values = wp.zeros(2 * ns, dtype=wp.int32, device=d)
        self.sample_xy = wp.zeros(ns, dtype=wp.vec2d, device=d)
        self.sample_code = wp.zeros(ns, dtype=wp.int32, device=d)
        self.sorted_xy = wp.zeros(ns, dtype=wp.vec2d, device=d)
        self.sorted_code = wp.zeros(ns, dtype=wp.int32, device=d)
        self.sample_pos = wp.zeros(ns, dtype=wp.int32, device=d)
        self.cell_starts = wp.zeros(dim * dim, dtype=wp.int32, device=d)
        self.cell_ends = wp.zeros(dim * dim, dtype=wp.int32, device=d)
        self._grid_kind = -1                                      # which hash the last rebuild built (use_cache)
        self.slot_iface = wp.array(model.topology.slot_iface.astype(np.int32), dtype=wp.int32, device=d)
        self.slot_l0 = wp.array(lengths.ravel(), dtype=wp.float64, device=d)
        vertex = model.topology.node_vertex
        self.node_vertex = wp.array(vertex.astype(np.int32), dtype=wp.int32, device=d)
        # the nodes at each original mesh vertex (CSR): the blocks a node can meet at its own vertex
        order = np.argsort(vertex, kind="stable")
        start = np.searchsorted(vertex[order], np.arange(int(vertex.max()) + 2))
        self.vertex_start = wp.array(start.astype(np.int32), dtype=wp.int32, device=d)
        self.vertex_nodes = wp.array(order.astype(np.int32), dtype=wp.int32, device=d)
        fan = np.empty(n, np.int64)
        fan[order] = np.arange(n) - start[vertex[order]]            # position of each node in its vertex's list
        if fan.max() >= 63:
            raise ValueError(f"a mesh vertex is shared by {fan.max() + 1} triangles; block contact allows 63")
        self.fan_index = wp.array(fan.astype(np.int32), dtype=wp.int32, device=d)
        self.contact_slot = wp.full(n, -1, dtype=wp.int32, device=d)
        self.contact_fs = wp.zeros(n, dtype=wp.float64, device=d)
        self.contact_d0 = wp.zeros(n, dtype=wp.float64, device=d)     # overlap allowance [m]
        self.contact_p = wp.zeros(n, dtype=wp.float64, device=d)      # overlap the penalty acts on [m]
        self.contact_kc = wp.zeros(n, dtype=wp.float64, device=d)     # penalty stiffness in use [N/m per m]
        self.loss_acc = wp.zeros(2, dtype=wp.float64, device=d)       # LOSS_SLIP, LOSS_PENALTY [J/m]
        # on from the start: a node with no exposed edge costs one test, so an unbroken model pays little
        self.active = True
        # The hash is rebuilt every rebuild_interval steps and queried with a margin of h_min/2 beyond the depth
        # limit: correct while no node and sample point close in by more than h_min/2 between rebuilds, i.e. for
        # relative speeds below h_min/(20·Δt) (2.5 km/s on the blast test's mesh, whose wall fragments fly at
        # up to 1 km/s), far above rock fragment speeds.
        self.rebuild_interval = 10
        self._since_build = self.rebuild_interval
        # Blocks an open face has come within h_min of stay "woken" for near_window steps: their held-broken
        # nodes then search the hash too, so a node of theirs cannot enter the open block unseen (module doc).
        self.near_window = 2 * self.rebuild_interval
        self.elem_near = wp.full(model.element_count, -(1 << 30), dtype=wp.int32, device=d)
        # An open node that found no exposed edge within h_min (and no contact) skips the search for
        # rebuild_interval steps: under the speed bound above nothing can close h_min in that time. On intact
        # rock this leaves the mesh-boundary nodes one search per rebuild instead of one per step.
        self.query_after = wp.zeros(n, dtype=wp.int32, device=d)
        # Search the vertex fans of broken faces still held by their springs (the bulk of a crushed zone). Off,
        # a crushed zone costs ~2x less (17 % of springs broken: 7.5 instead of 15 ms/step on 59k elements,
        # 5.2 without contact)
        # but its blocks can slide up to ~0.3·h into their fan neighbours before their springs drop.
        self.held_faces = True
        # Fan cache (module doc, "Cost"): each node's fan_exclusions mask and its fan candidates (the nodes of the
        # other blocks at its vertex that it may meet: not excluded, an exposed edge at the vertex), rebuilt for
        # the nodes of a vertex only when a spring whose state they depend on changes (mark_pair_changes
        # compares the spring states with those of the last step). Off, every held node walks its fan every step;
        # the results are the same (tests/unit/test_contact_cache.py).
        self.fan_cache = True
        pn = model.topology.pair_nodes
        si = model.topology.slot_iface
        both = np.flatnonzero(si >= 0)                               # the two element edges of each interface
        iface_slots = both[np.argsort(si[both], kind="stable")].reshape(-1, 2)
        self.iface_slots = wp.array(iface_slots.astype(np.int32), dtype=wp.vec2i, device=d)
        self.pair_vertex = wp.array(vertex[pn[:, 0]].astype(np.int32), dtype=wp.int32, device=d)
        self.seen_mode = wp.full(len(pn), -1, dtype=wp.int32, device=d)
        self.seen_dropped = wp.full(len(pn), -1, dtype=wp.int32, device=d)
        self.vertex_stamp = wp.full(int(vertex.max()) + 1, -(1 << 30), dtype=wp.int32, device=d)
        self.node_face = wp.zeros(n, dtype=wp.vec2d, device=d)       # node_faces: (tributary length, open)
        self.node_flag = wp.zeros(n, dtype=wp.int32, device=d)       # 0 no exposed edge, 1 held, 2 open
        self.fan_excl = wp.zeros(n, dtype=wp.int64, device=d)
        self.fan_cand = wp.zeros((n, int(FAN_CACHE)), dtype=wp.int32, device=d)
        self.fan_count = wp.full(n, -1, dtype=wp.int32, device=d)     # −1: not cached, walk the fan
        self.vertex_count = int(vertex.max()) + 1
        self._dirty_vertices = wp.zeros(self.vertex_count, dtype=wp.int32, device=d)
        self._cache_fresh = False
        self._counts = wp.zeros(2, dtype=wp.int32, device=d)          # dirty vertices, listed nodes
        self._node_list = wp.zeros(n, dtype=wp.int32, device=d)       # the nodes of this step's contact pass
        self._all_nodes = wp.array(np.arange(n, dtype=np.int32), dtype=wp.int32, device=d)   # without the cache
        self._counts_all = wp.array([0, n], dtype=wp.int32, device=d)
        self._cand_list = wp.zeros(n, dtype=wp.int32, device=d)       # list_candidates
        self._cand_count = wp.zeros(1, dtype=wp.int32, device=d)
        self._n_cand = 0
        self._step = 0
        self._launches: dict = {}

    def _launch(self, kernel, dim: int, params: list) -> None:
        """wp.launch(kernel, dim, inputs=params) through a recorded launch (wp.launch(record_cmd=True)): packing
        ~45 arguments costs ~50 µs a launch on a CPU, a replay only sets the scalars that changed. Recorded
        again whenever an array argument is another object (another State)."""
        arrays = [a for a in params if isinstance(a, wp.array)]
        rec = self._launches.get(kernel.key)
        if rec is None or len(rec[1]) != len(arrays) or any(a is not b for a, b in zip(rec[1], arrays)):
            cmd = wp.launch(kernel, dim=dim, inputs=params, device=self.model.device, record_cmd=True)
            rec = (cmd, arrays, list(params))
            self._launches[kernel.key] = rec
        else:
            cmd, _, last = rec
            for i, a in enumerate(params):
                if not isinstance(a, wp.array) and a != last[i]:
                    cmd.set_param_at_index(i, a)
                    last[i] = a
            cmd.set_dim(dim)
        rec[0].launch()

    def apply(self, state, dt: float) -> None:
        """Add the contact forces of the current configuration to state.f; dt [s] drives the friction."""
        if not self.active or self.kn_area == 0.0:
            return
        m = self.model
        radius = self.radius
        use_cache = int(bool(self.fan_cache))
        # (a switch of fan_cache builds the other hash at once: only tests and benchmarks switch)
        if self._since_build >= self.rebuild_interval or use_cache != self._grid_kind:
            ns = self.points.shape[0]
            if use_cache:
                wp.launch(compute_sample_cells, dim=ns,
                          inputs=[state.x, self.sample_slot, self.sample_frac, self.slot_iface, state.pair_mode,
                                  self.cell_inv, self.cell_dim],
                          outputs=[self.sample_xy, self.sample_code, self._keys, self._values], device=m.device)
                wp.utils.radix_sort_pairs(self._keys, self._values, ns, end_bit=self._key_bits)
                self.cell_starts.zero_()
                self.cell_ends.zero_()
                wp.launch(gather_sample_cells, dim=ns,
                          inputs=[self._keys, self._values, ns, self.sample_xy, self.sample_code],
                          outputs=[self.cell_starts, self.cell_ends, self.sorted_xy, self.sorted_code,
                                   self.sample_pos], device=m.device)
            else:
                wp.launch(compute_edge_samples, dim=ns, inputs=[state.x, self.sample_slot, self.sample_frac],
                          outputs=[self.points], device=m.device)
                self.grid.build(self.points, radius)
            self._grid_kind = use_cache
            self._since_build = 0
        self._since_build += 1
        self._step += 1
        step = self._step
        cpu = wp.get_device(m.device).is_cpu
        self._counts.zero_()
        if use_cache:
            # caches of the vertices where a spring changed state since the last call (of every vertex at first)
            refresh_all = int(not self._cache_fresh)
            if m.spring_count:
                self._launch(mark_pair_changes, m.spring_count,
                             [state.pair_mode, state.pair_dropped, self.pair_vertex, step, self.seen_mode,
                              self.seen_dropped, self.vertex_stamp, self._counts, self._dirty_vertices,
                              self.iface_slots, self.slot_samples, self.sample_pos, self.sorted_code])
            # on a CPU the launches run over the listed items only; a GPU thread past a list's end leaves at once
            dim = int(self._counts.numpy()[0]) if cpu and not refresh_all else self.vertex_count
            if dim:
                self._launch(refresh_fan_cache, dim,
                             [refresh_all, self._counts, self._dirty_vertices, self.node_vertex, self.vertex_start,
                              self.vertex_nodes, self.fan_index, self.slot_iface, self.slot_l0, m.node_pairs,
                              m.pair_i, m.pair_j, state.pair_mode, state.pair_dropped, self.node_face, self.node_flag,
                              self.fan_excl, self.fan_cand, self.fan_count])
                self._cand_count.zero_()
                self._launch(list_candidates, m.node_count, [self.node_flag, self._cand_count, self._cand_list])
                self._n_cand = int(self._cand_count.numpy()[0]) if cpu else m.node_count
        self._cache_fresh = bool(use_cache)
        held, window, touch = int(bool(self.held_faces)), int(self.near_window), 1e-9 * self.h_min
        node_list, counts, dim = self._all_nodes, self._counts_all, m.node_count
        if use_cache and self._n_cand == 0:
            return                                    # no node has an exposed edge
        if use_cache:
            self._launch(select_contact_nodes, self._n_cand,
                         [self._cand_list, self._cand_count, state.x, touch, step, window, held, self.elem_near, self.query_after, self.contact_slot,
                          self.node_flag, self.fan_cand, self.fan_count, self._counts, self._node_list])
            node_list, counts = self._node_list, self._counts
            if cpu:
                dim = int(self._counts.numpy()[1])
        if dim == 0:
            return
        self._launch(eval_block_contact, dim,
                     [node_list, counts, use_cache, self.grid.id, self.points, self.sample_slot, self.cell_inv,
                      self.cell_dim, self.cell_starts, self.cell_ends, self.sorted_xy, self.sorted_code,
                      self.slot_iface, self.slot_l0, self.node_vertex, self.vertex_start, self.vertex_nodes,
                      self.fan_index, m.node_mass, m.node_pairs, m.pair_i, m.pair_j, state.pair_mode,
                      state.pair_dropped, state.x, state.v, self.kn_area, self.mu_f, radius, 0.5 * self.h_min, touch,
                      self.h_min, step, window, int(self.rebuild_interval), held, float(dt), self.node_face,
                      self.fan_excl, self.fan_cand, self.fan_count, self.elem_near, self.query_after,
                      self.contact_slot, self.contact_fs, self.contact_d0, self.contact_p, self.contact_kc, state.f,
                      state.energy_acc, self.loss_acc])

    # ------------------------------------------------------------------ diagnostics (host side, not per step)
    def stored_energy(self) -> float:
        """Energy held by the active contacts, Σ ½Kc·p² + ½Fs²/Kc [J/m] (not in rock_energies' terms)."""
        kc = self.contact_kc.numpy()
        on = (self.contact_slot.numpy() >= 0) & (kc > 0.0)
        p, fs = self.contact_p.numpy()[on], self.contact_fs.numpy()[on]
        return float(np.sum(0.5 * kc[on] * p * p + 0.5 * fs * fs / kc[on]))

    def losses(self) -> dict[str, float]:
        """Energy removed by block contact since the start [J/m]: Coulomb slip, dropped penalty energy."""
        a = self.loss_acc.numpy()
        return {"slip": float(a[LOSS_SLIP]), "penalty_dropped": float(a[LOSS_PENALTY])}

    def active_count(self) -> int:
        return int(np.count_nonzero(self.contact_slot.numpy() >= 0))

    def stable_dt(self) -> float:
        """Gershgorin bound 2/ω_max [s] with every node in one block contact of its largest Kc (METHOD §1.7):
        CST rows + 2·max(Kn, Ks) per intact spring + 2·Kc, Kc = kn·(half of each of its element's edges at it)."""
        from ..model.builder import element_row_sums

        m, h = self.model, self.model.host
        X = h["node_X"]
        row = element_row_sums(X, m.lam, m.mu).max(axis=1)
        pn = m.topology.pair_nodes
        k = 2.0 * np.maximum(h["pair_kn"], h["pair_ks"])
        np.add.at(row, pn[:, 0], k)
        np.add.at(row, pn[:, 1], k)
        lengths = m.mesh.edge_lengths().ravel()
        nodes = np.arange(m.node_count)
        trib = 0.5 * (lengths[nodes] + lengths[3 * (nodes // 3) + (nodes % 3 + 2) % 3])
        row += 2.0 * self.kn_area * trib
        return 2.0 / math.sqrt(float(np.max(row / h["node_mass_dt"])))
