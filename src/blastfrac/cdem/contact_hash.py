"""Block contact, the spatial hash of exposed-edge samples: sample points along the edges, a cell grid in
wp.HashGrid's order with each cell's points and their edge's exposure, and the search of a node's hash cells
(cdem/contact.py)."""

from __future__ import annotations

import warp as wp

from .contact_data import ContactCache, ContactHash, ContactMesh, ContactParams
from .contact_fan import wake_block
from .contact_geometry import (
    consider_edge,
    edge_coords,
    in_mask,
    slot_end,
    slot_exposed,
    slot_prev,
    vec5d,
    vec6d,
)

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


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


@wp.kernel
def largest_displacement(first: wp.int32, count: wp.int32, serial: wp.int32, slot: wp.int32,
                         x: wp.array(dtype=wp.vec2d), x_build: wp.array(dtype=wp.vec2d),
                         moved: wp.array(dtype=wp.float64)):
    """moved[slot] = max over the nodes first … first + count − 1 of |x − x_build|² [m²]: how far the hash points may
    have moved since the hash was built (a point on an edge moves no more than the edge's nodes). Two threads each
    take half of the nodes and a slot of their own (rebuild_decision takes the larger): the maximum is exact either
    way. serial = 1 (a CPU): one thread walks the nodes with the maximum in a register (one thread per node
    read-modified-wrote moved[slot] each: 1.45 against 1.0 ms over 341k nodes); serial = 0: a thread per node."""
    if serial != 0:
        mx = moved[slot]
        for n in range(first, first + count):
            d = x[n] - x_build[n]
            mx = wp.max(mx, wp.dot(d, d))
        moved[slot] = mx
    else:
        n = first + wp.tid()
        d = x[n] - x_build[n]
        wp.atomic_max(moved, slot, wp.dot(d, d))


@wp.kernel
def contact_tick(clock: wp.array(dtype=wp.int32), check_due: wp.array(dtype=wp.int32),
                 rebuild_due: wp.array(dtype=wp.int32), rebuilds: wp.array(dtype=wp.int32), force_rebuild: wp.int32,
                 rebuild_check: wp.int32):
    """The contact pass's schedule, on the device (one thread, before the pass): clock[0] the step count, clock[1]
    the steps since the hash was built. The displacement check is due (check_due[0] = 1) every rebuild_check steps,
    a rebuild (rebuild_due[0] = 1, counted in rebuilds[0]) when forced (first build, another hash kind), otherwise
    rebuild_decision sets it.
    These flags drive ``wp.capture_if``, so the pass reads nothing back and can be captured in a graph."""
    check = wp.int32(0)
    rebuild = wp.int32(0)
    if force_rebuild != 0:
        rebuild = 1
        rebuilds[0] = rebuilds[0] + 1
        clock[1] = 0
    elif clock[1] >= rebuild_check:
        check = 1
        clock[1] = 0
    check_due[0] = check
    rebuild_due[0] = rebuild
    clock[1] = clock[1] + 1
    clock[0] = clock[0] + 1


@wp.kernel
def rebuild_decision(moved: wp.array(dtype=wp.float64), skin2: wp.float64, rebuild_due: wp.array(dtype=wp.int32),
                     rebuilds: wp.array(dtype=wp.int32)):
    """rebuild_due[0] = 1 when a node has moved more than the skin since the build (max(moved[0], moved[1]) > skin²
    [m²]), and count the rebuild (one thread)."""
    if wp.max(moved[0], moved[1]) > skin2:
        rebuild_due[0] = 1
        rebuilds[0] = rebuilds[0] + 1


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


@wp.func
def hash_cell(x: wp.float64, y: wp.float64, inv: wp.float64, dim: wp.int32):
    """Row-major index of the wrapped cell (dim × dim cells of width 1/inv [m]) that wp.HashGrid files (x, y) [m] in."""
    return cell_wrap(cell_coord(y * inv), dim) * dim + cell_wrap(cell_coord(x * inv), dim)


@wp.func
def query_cells(p: wp.vec2d, radius: wp.float64, inv: wp.float64, dim: wp.int32):
    """(first x, last x, first y, last y) cell coordinates of a query of ``radius`` [m] around p [m] in cells of
    width 1/inv [m]: the cells wp.HashGrid's query visits, each wrapped cell at most once (cell_end)."""
    xs = cell_coord((p[0] - radius) * inv)
    ys = cell_coord((p[1] - radius) * inv)
    return wp.vec4i(xs, cell_end(xs, cell_coord((p[0] + radius) * inv), dim),
                    ys, cell_end(ys, cell_coord((p[1] + radius) * inv), dim))


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
    keys[i] = hash_cell(m[0], m[1], cell_inv, dim)
    values[i] = i


@wp.func
def mark_cell_range(keys: wp.array(dtype=wp.int32), j: wp.int32, count: wp.int32, base: wp.int32,
                    cell_starts: wp.array(dtype=wp.int32), cell_ends: wp.array(dtype=wp.int32)):
    """After a stable sort by cell (keys, count of them): sorted position j opens or closes the range of its cell
    keys[j] (stored at base + cell) where its neighbours' cells differ."""
    c = keys[j]
    if j == 0:
        cell_starts[base + c] = j
    elif keys[j - 1] != c:
        cell_starts[base + c] = j
    if j == count - 1:
        cell_ends[base + c] = j + 1
    elif keys[j + 1] != c:
        cell_ends[base + c] = j + 1


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
    i = values[j]
    sorted_xy[j] = sample_xy[i]
    sorted_code[j] = sample_code[i]
    sample_pos[i] = j
    mark_cell_range(keys, j, count, 0, cell_starts, cell_ends)



@wp.func
def hash_edge(
    s: wp.int32,
    xn: wp.vec2d,
    u1: wp.vec2d,
    u2: wp.vec2d,
    vtx: wp.int32,
    excl: wp.int64,
    is_open: bool,
    skip_vertex: bool,
    mesh: ContactMesh,
    pair_mode: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    prm: ContactParams,
    step: wp.int32,
    cache: ContactCache,
    sr: vec6d,
):
    """hash_search for one exposed edge s of another element within the search radius: sr = (search state of
    consider_edge, distance to the closest edge). Wakes the edge's block if an open face comes near it. With
    skip_vertex the edges that end at the node's own vertex are left out (the fan search has them)."""
    s_end = slot_end(s)
    skip = bool(False)
    corner = wp.int32(-1)
    if mesh.node_vertex[s] == vtx:
        skip = skip_vertex or in_mask(excl, s, mesh.fan_index)
        corner = slot_prev(s)
    elif mesh.node_vertex[s_end] == vtx:
        skip = skip_vertex or in_mask(excl, s_end, mesh.fan_index)
        corner = s_end
    out = sr
    if not skip:
        c = edge_coords(xn, x[s], x[s_end])
        st = consider_edge(s, c, corner, -1, xn, u1, u2, x, mesh.slot_iface, pair_mode,
                           vec5d(sr[0], sr[1], sr[2], sr[3], sr[4]), prm.max_depth, prm.touch_tol)
        out = vec6d(st[0], st[1], st[2], st[3], st[4], wp.min(sr[5], c[2]))
        if is_open and c[2] < prm.wake_dist:
            wake_block(s // 3, cache.elem_near, step, prm.near_window)   # the block this open face comes near
    return out


@wp.func
def hash_search(
    n: wp.int32,
    is_open: bool,
    skip_vertex: bool,
    st0: vec5d,
    excl: wp.int64,
    use_cache: wp.int32,
    hsh: ContactHash,
    mesh: ContactMesh,
    pair_mode: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    prm: ContactParams,
    step: wp.int32,
    cache: ContactCache,
):
    """Search state (consider_edge) of an open or woken node n over every exposed edge near it, through the
    spatial hash, from search state st0; excl: its fan_exclusions mask. With skip_vertex, over those that do not
    end at the node's own vertex (an open node, whose fan search has those). Wakes the blocks an open face comes
    near and sets the node's quiet period (BlockContact doc): quiet if no edge it looked at is within wake_dist.
    With use_cache the points come from the cell grid (the cells wp.HashGrid would visit, in its order, each
    cell's points in its order) with their exposure in sorted_code; without, from wp.HashGrid itself."""
    e = n // 3
    zero = wp.float64(0.0)
    xn = x[n]
    vtx = mesh.node_vertex[n]
    # the node's element wedge: unit vectors along its two edges at the node
    u1 = wp.normalize(x[slot_end(n)] - xn)
    u2 = wp.normalize(x[slot_prev(n)] - xn)
    sr = vec6d(st0[0], st0[1], st0[2], st0[3], st0[4], wp.float64(1.0e300))
    radius = prm.search_radius
    r2 = radius * radius
    if use_cache != 0:
        dim = hsh.cell_dim
        cr = query_cells(xn, radius, hsh.cell_inv, dim)
        for cy in range(cr[2], cr[3] + 1):
            row = cell_wrap(cy, dim) * dim
            for cx in range(cr[0], cr[1] + 1):
                c = row + cell_wrap(cx, dim)
                for j in range(hsh.cell_starts[c], hsh.cell_ends[c]):
                    code = hsh.sorted_code[j]
                    if code > 0:                       # an exposed edge
                        s = code - 1
                        pt = hsh.sorted_xy[j]
                        dx = pt[0] - xn[0]
                        dy = pt[1] - xn[1]
                        # whole hash cells: keep the points within the search radius
                        if s // 3 != e and dx * dx + dy * dy <= r2:
                            sr = hash_edge(s, xn, u1, u2, vtx, excl, is_open, skip_vertex, mesh, pair_mode, x, prm,
                                           step, cache, sr)
    else:
        query = wp.hash_grid_query(hsh.grid, wp.vec3d(xn[0], xn[1], zero), radius)
        i = int(0)
        while wp.hash_grid_query_next(query, i):
            s = hsh.sample_slot[i]
            p3 = hsh.points[i]
            dx = p3[0] - xn[0]
            dy = p3[1] - xn[1]
            # the query returns whole hash cells: keep the points within the search radius
            if s // 3 != e and dx * dx + dy * dy <= r2:
                if slot_exposed(s, mesh.slot_iface, pair_mode):
                    sr = hash_edge(s, xn, u1, u2, vtx, excl, is_open, skip_vertex, mesh, pair_mode, x, prm, step,
                                   cache, sr)
    cache.query_after[n] = 0
    if is_open and sr[5] >= prm.wake_dist:
        cache.query_after[n] = step + prm.quiet_steps
    return vec5d(sr[0], sr[1], sr[2], sr[3], sr[4])
