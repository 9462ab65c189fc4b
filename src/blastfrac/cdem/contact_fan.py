"""Block contact, the per-node fan cache of held broken faces: candidates and exclusion masks rebuilt only where a
spring changed, the search of a held node's own vertex, and the lean listing pass of the nodes with anything to
do (cdem/contact.py, "Cost")."""

from __future__ import annotations

import warp as wp

from .contact_data import ContactCache, ContactMarks, ContactMesh, ContactParams
from .contact_geometry import (
    FAN_CACHE,
    WEDGE_TOL,
    XI_TOL,
    consider_edge,
    edge_coords,
    fan_exclusions,
    in_mask,
    slot_end,
    slot_exposed,
    slot_open,
    slot_prev,
    vec5d,
)

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


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
    """consider_edge for the exposed edges of other's element at the vertex (a node inside that corner); ex1, ex2:
    whether its edges 'other' and the one ending at 'other' are exposed, which each is the other's corner edge."""
    sb = slot_prev(other)
    xc = x[other]
    out = st
    if ex1:
        out = consider_edge(other, edge_coords(xn, xc, x[slot_end(other)]), sb, wp.where(ex2, 1, 0), xn, u1, u2,
                            x, slot_iface, pair_mode, out, max_depth, touch_tol)
    if ex2:
        out = consider_edge(sb, edge_coords(xn, x[sb], xc), other, wp.where(ex1, 1, 0), xn, u1, u2, x,
                            slot_iface, pair_mode, out, max_depth, touch_tol)
    return out


@wp.func
def fan_cache_build(n: wp.int32, excl: wp.int64, mesh: ContactMesh, pair_mode: wp.array(dtype=wp.int32),
                    cache: ContactCache):
    """Cache the fan candidates of node n: the nodes at its vertex, in vertex order, of another element, not in
    its exclusion mask excl and with an exposed edge at the vertex, as 4·node + (1 if its edge 'node' is
    exposed) + (2 if its edge ending at the node is); fan_count −1 if more than FAN_CACHE (walk the fan)."""
    e = n // 3
    vtx = mesh.node_vertex[n]
    k = wp.int32(0)
    for j in range(mesh.vertex_start[vtx], mesh.vertex_start[vtx + 1]):
        other = mesh.vertex_nodes[j]
        if other // 3 != e:
            if not in_mask(excl, other, mesh.fan_index):
                code = wp.int32(0)
                if slot_exposed(other, mesh.slot_iface, pair_mode):
                    code = code + 1
                if slot_exposed(slot_prev(other), mesh.slot_iface, pair_mode):
                    code = code + 2
                if code != 0:
                    if k < FAN_CACHE:
                        cache.fan_cand[n, k] = 4 * other + code
                    k = k + 1
    if k > FAN_CACHE:
        k = wp.int32(-1)
    cache.fan_count[n] = k


@wp.func
def point_segment_distance(p: wp.vec2d, a: wp.vec2d, b: wp.vec2d):
    """Distance from point p to the segment a–b [m]."""
    ab = b - a
    t = wp.clamp(wp.dot(p - a, ab) / wp.dot(ab, ab), wp.float64(0.0), wp.float64(1.0))
    return wp.length(p - (a + t * ab))


@wp.func
def far_nodes_near(other: wp.int32, xa: wp.vec2d, xn: wp.vec2d, xb: wp.vec2d, x: wp.array(dtype=wp.vec2d),
                   wake_dist: wp.float64):
    """True if one of the two nodes of other's element that are not at the shared vertex is within wake_dist of
    the open node's element edges a–n or n–b."""
    near = bool(False)
    for k in range(2):
        q = slot_end(other)
        if k == 1:
            q = slot_prev(other)
        xq = x[q]
        if point_segment_distance(xq, xa, xn) < wake_dist or point_segment_distance(xq, xn, xb) < wake_dist:
            near = True
    return near


@wp.func
def held_search(
    n: wp.int32,
    excl: wp.int64,
    use_cache: wp.int32,
    mesh: ContactMesh,
    pair_mode: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    prm: ContactParams,
    cache: ContactCache,
    wake: bool,
    step: wp.int32,
):
    """Search state (consider_edge) of node n against the other blocks at its own vertex only (module doc): all
    a held node searches, and the edges at its vertex for an open one. With use_cache, over its cached fan
    candidates (fan_cache_build: the same nodes in the same order, so the same result); otherwise, or if the fan
    overflowed the cache, by walking the vertex's node list.

    With ``wake`` (an open node) it also wakes (wake_block) the blocks of the fan whose other two nodes come
    within wake_dist of n's element edges at the vertex: those nodes could enter n's block through an edge that
    is not at their own vertex, which their fan search does not see (cdem/contact.py, "Cost"). The edges that
    end at the vertex itself touch n there and say nothing about that, so they wake no block."""
    e = n // 3
    zero = wp.float64(0.0)
    xn = x[n]
    xa = x[slot_prev(n)]
    xb = x[slot_end(n)]
    touch_tol = prm.touch_tol
    st = vec5d(wp.float64(-1.0), zero, zero, wp.float64(1.0e300), zero)
    # the node's element wedge (unit vectors along its two edges at the node), only once a corner test passes
    have_u = bool(False)
    u1 = wp.vec2d(zero, zero)
    u2 = wp.vec2d(zero, zero)
    cnt = wp.int32(-1)
    if use_cache != 0:
        cnt = cache.fan_count[n]
    if cnt >= 0:
        for k in range(cnt):
            code = cache.fan_cand[n, k]
            other = code >> 2
            ex1 = (code & 1) != 0
            ex2 = (code & 2) != 0
            if wake:
                if far_nodes_near(other, xa, xn, xb, x, prm.wake_dist):
                    wake_block(other // 3, cache.elem_near, step, prm.near_window)
            if corner_inside(xn, other, ex1, ex2, x, touch_tol):
                if not have_u:
                    u1 = wp.normalize(x[slot_end(n)] - xn)
                    u2 = wp.normalize(x[slot_prev(n)] - xn)
                    have_u = True
                st = corner_consider(other, ex1, ex2, xn, u1, u2, x, mesh.slot_iface, pair_mode, st, prm.max_depth,
                                     touch_tol)
    else:
        vtx = mesh.node_vertex[n]
        for j in range(mesh.vertex_start[vtx], mesh.vertex_start[vtx + 1]):
            other = mesh.vertex_nodes[j]
            if other // 3 != e:
                if not in_mask(excl, other, mesh.fan_index):
                    ex1 = slot_exposed(other, mesh.slot_iface, pair_mode)
                    ex2 = slot_exposed(slot_prev(other), mesh.slot_iface, pair_mode)
                    # only a node inside the corner (behind both exposed edges) can be a contact: a cheap sign
                    # test first, the full evaluation for the few that pass
                    if wake and (ex1 or ex2):
                        if far_nodes_near(other, xa, xn, xb, x, prm.wake_dist):
                            wake_block(other // 3, cache.elem_near, step, prm.near_window)
                    if ex1 or ex2:
                        if corner_inside(xn, other, ex1, ex2, x, touch_tol):
                            if not have_u:
                                u1 = wp.normalize(x[slot_end(n)] - xn)
                                u2 = wp.normalize(x[slot_prev(n)] - xn)
                                have_u = True
                            st = corner_consider(other, ex1, ex2, xn, u1, u2, x, mesh.slot_iface, pair_mode, st,
                                                 prm.max_depth, touch_tol)
    return st


@wp.func
def mark_pair(p: wp.int32, step: wp.int32, pair_mode: wp.array(dtype=wp.int32),
              pair_dropped: wp.array(dtype=wp.int32), marks: ContactMarks, counts: wp.array(dtype=wp.int32),
              dirty_vertices: wp.array(dtype=wp.int32)):
    """If spring p's state differs from the one last seen: list (once each, counts[0] of them) the vertices whose
    fan caches the change makes stale, both ends of p's interface (the exposure of its edges counts at both
    vertices, the exclusion chains at p's own), and set the sorted_code sign of the hash points on the interface's
    two edges. Nothing for an unchanged spring, so a spring may be met twice."""
    mode = pair_mode[p]
    dropped = pair_dropped[p]
    if mode != marks.seen_mode[p] or dropped != marks.seen_dropped[p]:
        marks.seen_mode[p] = mode
        marks.seen_dropped[p] = dropped
        q = p // 2
        for k in range(2):
            vtx = marks.pair_vertex[2 * q + k]
            if wp.atomic_exch(marks.vertex_stamp, vtx, step) != step:
                dirty_vertices[wp.atomic_add(counts, 0, 1)] = vtx
        exposed = pair_mode[2 * q] != 0 and pair_mode[2 * q + 1] != 0
        for k in range(2):
            sl = marks.iface_slots[q][k]
            code = -(sl + 1)
            if exposed:
                code = sl + 1
            rng = marks.slot_samples[sl]
            for i in range(rng[0], rng[0] + rng[1]):
                marks.sorted_code[marks.sample_pos[i]] = code


@wp.kernel
def mark_pair_changes(first: wp.int32, pair_mode: wp.array(dtype=wp.int32), pair_dropped: wp.array(dtype=wp.int32),
                      clock: wp.array(dtype=wp.int32), marks: ContactMarks, counts: wp.array(dtype=wp.int32),
                      dirty_vertices: wp.array(dtype=wp.int32)):
    """mark_pair for every spring first, first + 1, … (the scan of the first pass, which finds every spring's
    state new, and of a pass after ``BlockContact.rescan_springs``; the others take the springs the spring kernel
    listed, ``mark_listed_changes``).

    Two threads may each take half of the springs, each with its own list and count (append_vertices joins them
    in order). A vertex whose springs change in both halves may then be listed twice (the two threads' stamps
    race); its caches are rebuilt twice, to the same values. Where the split falls between the two springs of one
    interface, both threads write that interface's sorted_code, and write the same value."""
    mark_pair(first + wp.tid(), clock[0], pair_mode, pair_dropped, marks, counts, dirty_vertices)


@wp.kernel
def mark_listed_changes(stride: wp.int32, changes: wp.array(dtype=wp.int32), change_count: wp.array(dtype=wp.int32),
                        pair_mode: wp.array(dtype=wp.int32), pair_dropped: wp.array(dtype=wp.int32),
                        clock: wp.array(dtype=wp.int32), marks: ContactMarks, counts: wp.array(dtype=wp.int32),
                        dirty_vertices: wp.array(dtype=wp.int32)):
    """mark_pair for the springs the spring kernel listed since the last pass (kernels_spring.list_change: slot 0's
    change_count[0] entries from changes[0], then slot 1's change_count[1] from changes[cap], cap = half the
    array): on a CPU, where one thread walks the list (thread i takes items i, i + stride, …), the springs
    mark_pair_changes' scan finds changed, in the same order, without reading the others' state (the shipped
    confined P0: 1.3 ms a step for the scan of its 340k springs)."""
    i = wp.tid()
    cap = changes.shape[0] // 2
    n0 = change_count[0]
    n = n0 + change_count[1]
    step = clock[0]
    while i < n:
        p = wp.int32(0)
        if i < n0:
            p = changes[i]
        else:
            p = changes[cap + i - n0]
        mark_pair(p, step, pair_mode, pair_dropped, marks, counts, dirty_vertices)
        i += stride


@wp.kernel
def append_vertices(counts: wp.array(dtype=wp.int32), dirty_vertices: wp.array(dtype=wp.int32),
                    counts_b: wp.array(dtype=wp.int32), dirty_b: wp.array(dtype=wp.int32)):
    """Append the second half's list of stale vertices (mark_pair_changes) to the first's, in order (one thread)."""
    n = counts[0]
    for i in range(counts_b[0]):
        dirty_vertices[n + i] = dirty_b[i]
    counts[0] = n + counts_b[0]


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


WAKE_FLAG = wp.constant(1 << 30)
"""elem_near holds a wake's step t, plus WAKE_FLAG when it was written in step t onto a block already woken then."""


@wp.func
def node_woken(e: wp.int32, elem_near: wp.array(dtype=wp.int32), step: wp.int32, near_window: wp.int32):
    """True if an open face came near element e in the near_window steps before this one, as of the start of this
    step's pass: a wake written earlier in the pass (step t = this step) carries in its WAKE_FLAG whether the block
    was woken before it (wake_block), so a node's woken state does not depend on where it stands in the pass, nor
    on which of two threads wrote the wake first."""
    v = elem_near[e]
    if v >= WAKE_FLAG:
        if v - WAKE_FLAG == step:
            return True
        v = v - WAKE_FLAG
    elif v == step:
        return False
    return v >= step - near_window and v < step


@wp.func
def wake_block(e: wp.int32, elem_near: wp.array(dtype=wp.int32), step: wp.int32, near_window: wp.int32):
    """Wake element e at this step (an open face came within wake_dist of it): elem_near[e] = step, plus WAKE_FLAG if
    it was woken at the start of the pass (node_woken). A block already woken in this pass is left as it is. Two
    threads waking one block write the same value, and a reader sees the same state before and after the write."""
    v = elem_near[e]
    if v != step and v != step + WAKE_FLAG:
        if node_woken(e, elem_near, step, near_window):
            elem_near[e] = step + WAKE_FLAG
        else:
            elem_near[e] = step


@wp.func
def refresh_vertex(vtx: wp.int32, mesh: ContactMesh, pair_mode: wp.array(dtype=wp.int32),
                   pair_dropped: wp.array(dtype=wp.int32), cache: ContactCache):
    """The caches of the nodes at vertex vtx (refresh_fan_cache)."""
    for j in range(mesh.vertex_start[vtx], mesh.vertex_start[vtx + 1]):
        n = mesh.vertex_nodes[j]
        nf = node_faces(n, mesh.slot_iface, mesh.slot_l0, pair_mode, pair_dropped)
        cache.node_face[n] = nf
        flag = wp.int32(0)                        # 0 no exposed edge, 1 held, 2 open
        if nf[0] != wp.float64(0.0):
            flag = 1
            if nf[1] != wp.float64(0.0):
                flag = 2
        if flag != 0 and cache.node_flag[n] == 0:     # a new candidate (merge_candidates)
            cache.new_nodes[wp.atomic_add(cache.new_count, 0, 1)] = n
        cache.node_flag[n] = flag
        ex = fan_exclusions(n, mesh.node_pairs, mesh.fan_index, mesh.pair_i, mesh.pair_j, pair_mode, pair_dropped)
        cache.fan_excl[n] = ex
        fan_cache_build(n, ex, mesh, pair_mode, cache)


@wp.kernel
def refresh_fan_cache(
    refresh_all: wp.int32,
    counts: wp.array(dtype=wp.int32),
    dirty_vertices: wp.array(dtype=wp.int32),
    mesh: ContactMesh,
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
    cache: ContactCache,
    vertex_count: wp.int32,
    stride: wp.int32,
):
    """Rebuild the caches (node_faces and node_flag, fan_exclusions mask, fan_cache_build list) of every node at
    a listed vertex (every vertex with refresh_all): each thread writes only its own vertex's nodes, from the
    spring states, so the order of the threads does not matter. Thread i takes items i, i + stride, ...
    (eval_block_contact)."""
    i = wp.tid()
    end = vertex_count
    if refresh_all == 0:
        end = counts[0]
    while i < end:
        vtx = i
        if refresh_all == 0:
            vtx = dirty_vertices[i]
        refresh_vertex(vtx, mesh, pair_mode, pair_dropped, cache)
        i += stride


MERGE_MAX = 512
"""merge_candidates sorts at most this many new candidates by insertion (a burst of more rescans the flags)."""


@wp.kernel
def merge_candidates(cache: ContactCache, cand_count: wp.array(dtype=wp.int32), cand_list: wp.array(dtype=wp.int32)):
    """Merge the nodes a refresh flagged for the first time (cache.new_nodes) into the candidate list, in node order
    (one thread; a CPU). A node's flag never returns to 0 (an exposed edge stays exposed: springs do not heal), so
    the list is the one list_candidates' scan of every node's flag gives, at the cost of the list's length instead
    of the nodes' (the shipped confined P0: 0.7 ms a step for the scan of its 341k nodes). More than MERGE_MAX new
    nodes at once: the scan, in this thread."""
    m = cache.new_count[0]
    if m == 0:
        return
    old = cand_count[0]
    if m > MERGE_MAX:
        c = wp.int32(0)
        for n in range(cache.node_flag.shape[0]):
            if cache.node_flag[n] != 0:
                cand_list[c] = n
                c += 1
        cand_count[0] = c
        return
    for i in range(1, m):                         # insertion sort of the few new nodes
        v = cache.new_nodes[i]
        j = i - 1
        moving = bool(True)
        while moving:
            if j >= 0:
                if cache.new_nodes[j] > v:
                    cache.new_nodes[j + 1] = cache.new_nodes[j]
                    j -= 1
                else:
                    moving = False
            else:
                moving = False
        cache.new_nodes[j + 1] = v
    i = old - 1                                   # merge from the back, in place
    j = m - 1
    k = old + m - 1
    while j >= 0:
        take_old = bool(False)
        if i >= 0:
            if cand_list[i] > cache.new_nodes[j]:
                take_old = True
        if take_old:
            cand_list[k] = cand_list[i]
            i -= 1
        else:
            cand_list[k] = cache.new_nodes[j]
            j -= 1
        k -= 1
    cand_count[0] = old + m


@wp.kernel
def list_candidates(node_flag: wp.array(dtype=wp.int32), cand_count: wp.array(dtype=wp.int32),
                    cand_list: wp.array(dtype=wp.int32)):
    """The nodes with an exposed edge at them (node_flag ≠ 0), in node order on a CPU: select_contact_nodes runs
    over them only. Rebuilt when refresh_fan_cache has changed a flag."""
    n = wp.tid()
    if node_flag[n] != 0:
        cand_list[wp.atomic_add(cand_count, 0, 1)] = n


@wp.func
def select_node(
    n: wp.int32,
    x: wp.array(dtype=wp.vec2d),
    prm: ContactParams,
    step: wp.int32,
    cache: ContactCache,
    contact_slot: wp.array(dtype=wp.int32),
    counts: wp.array(dtype=wp.int32),
    node_list: wp.array(dtype=wp.int32),
):
    """List node n (at counts[1]) if eval_block_contact has anything to do for it (select_contact_nodes)."""
    flag = cache.node_flag[n]
    if flag == 0:
        return
    is_open = flag == 2
    woken = node_woken(n // 3, cache.elem_near, step, prm.near_window)
    # open nodes are listed whenever they have a fan (its search and wake run every step), the hash search
    # when due
    if not (is_open or woken):
        if contact_slot[n] < 0:
            if prm.held_faces == 0:
                return                            # held broken faces not searched (BlockContact.held_faces)
            cnt = cache.fan_count[n]
            if cnt >= 0:
                xn = x[n]
                hit = bool(False)
                for k in range(cnt):
                    code = cache.fan_cand[n, k]
                    other = code >> 2
                    ex1 = (code & 1) != 0
                    ex2 = (code & 2) != 0
                    if not hit and corner_inside(xn, other, ex1, ex2, x, prm.touch_tol):
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
    # a quiet open node (BlockContact doc) without contact is left with its fan search: none if its fan is empty
    elif is_open and not woken and step < cache.query_after[n] and contact_slot[n] < 0 and cache.fan_count[n] == 0:
        return
    node_list[wp.atomic_add(counts, 1, 1)] = n


@wp.kernel
def select_contact_nodes(
    cand_list: wp.array(dtype=wp.int32),
    cand_count: wp.array(dtype=wp.int32),
    stride: wp.int32,
    x: wp.array(dtype=wp.vec2d),
    prm: ContactParams,
    clock: wp.array(dtype=wp.int32),
    cache: ContactCache,
    contact_slot: wp.array(dtype=wp.int32),
    counts: wp.array(dtype=wp.int32),
    node_list: wp.array(dtype=wp.int32),
):
    """List (counts[1] of them, in node order on a CPU) the nodes of cand_list eval_block_contact has anything
    to do for; it would leave the others without a write (from the caches: node_flag, fan candidates). A held node without
    contact is listed only if one of its fan candidates passes the corner sign test (held_search makes the same
    test first and finds nothing otherwise) and one of that corner's exposed edges passes edge_may_take. Thread
    i takes items i, i + stride, ... (eval_block_contact)."""
    i = wp.tid()
    step = clock[0]
    while i < cand_count[0]:
        select_node(cand_list[i], x, prm, step, cache, contact_slot, counts, node_list)
        i += stride
