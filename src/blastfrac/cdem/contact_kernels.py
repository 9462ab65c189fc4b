"""Block contact, the contact force of a node and the per-node kernel that finds its edge, applies the penalty
and friction forces and keeps the contact history (cdem/contact.py)."""

from __future__ import annotations

import warp as wp

from ..model.model import CONTACT_DISSIPATED
from .contact_data import ContactCache, ContactHash, ContactHistory, ContactMesh, ContactParams, ContactRecords
from .contact_fan import held_search, node_faces, node_woken
from .contact_geometry import (
    KC_CAP,
    LOSS_PENALTY,
    LOSS_SLIP,
    coulomb_update,
    edge_coords,
    fan_exclusions,
    penalty_overlap,
    release_overlap,
    slot_end,
    vec5d,
)
from .contact_hash import hash_search

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


@wp.func
def add_contact(n: wp.int32, ia: wp.int32, ib: wp.int32, force: wp.vec2d, xi: wp.float64, pen: wp.float64,
                slip: wp.float64, f: wp.array(dtype=wp.vec2d), energy_acc: wp.array(dtype=wp.float64),
                loss_acc: wp.array(dtype=wp.float64)):
    """Add a node's contact force to it (n ≥ 0) and the reactions (1 − ξ, ξ) to the edge's nodes ia, ib (linear
    momentum is conserved to round-off), and the penalty energy dropped and the slip work [J/m] (where not 0)."""
    if n >= 0:
        wp.atomic_add(f, n, force)
        wp.atomic_add(f, ia, -(wp.float64(1.0) - xi) * force)
        wp.atomic_add(f, ib, -xi * force)
    if pen != wp.float64(0.0):
        wp.atomic_add(energy_acc, CONTACT_DISSIPATED, pen)
        wp.atomic_add(loss_acc, LOSS_PENALTY, pen)
    if slip != wp.float64(0.0):
        wp.atomic_add(energy_acc, CONTACT_DISSIPATED, slip)
        wp.atomic_add(loss_acc, LOSS_SLIP, slip)


@wp.func
def record_contact(n: wp.int32, ia: wp.int32, ib: wp.int32, force: wp.vec2d, xi: wp.float64, pen: wp.float64,
                   slip: wp.float64, item: wp.int32, rec: ContactRecords, f: wp.array(dtype=wp.vec2d),
                   energy_acc: wp.array(dtype=wp.float64), loss_acc: wp.array(dtype=wp.float64)):
    """A node's contact (add_contact's arguments; n −1: no force): added now (item < 0, one pass over the list in
    one thread, or a GPU), or kept in record item for apply_contact_records (a pass in two parts). The rock's forces
    and energies are not read in the pass, so both add the same terms in the same order: the same sums."""
    if item < 0:
        add_contact(n, ia, ib, force, xi, pen, slip, f, energy_acc, loss_acc)
    else:
        rec.nodes[item] = wp.vec3i(n, ia, ib)
        rec.force[item] = force
        rec.xi[item] = xi
        rec.energy[item] = wp.vec2d(pen, slip)


@wp.func
def contact_force(
    n: wp.int32,
    trib: wp.float64,
    st: vec5d,
    mesh: ContactMesh,
    prm: ContactParams,
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    dt: wp.float64,
    hist: ContactHistory,
    item: wp.int32,
    rec: ContactRecords,
    f: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
):
    """Contact force of candidate node n (trib: its tributary length [m]) from its search state st (hash_search or
    held_search) and its contact history (see the module doc), added to f and the energy accounts, or with item ≥ 0
    kept in record ``item`` of rec (the force, where it acts, the energies dropped) for apply_contact_records to add
    (record_contact)."""
    zero = wp.float64(0.0)
    one = wp.float64(1.0)
    half = wp.float64(0.5)
    xn = x[n]
    best = int(st[0])
    near_inside = st[4] > zero
    prev = hist.slot[n]
    h = hist.state[n]                             # (Fs, d0, p, Kc) of the last step: one load
    fs_prev = h[0]
    d0_prev = h[1]
    p_prev = h[2]
    kc_prev = h[3]
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
            record_contact(n, -1, -1, wp.vec2d(), zero, half * fs_prev * fs_prev / kc_prev, zero, item, rec, f,
                           energy_acc, hist.loss_acc)
        hist.slot[n] = -1
        hist.state[n] = wp.vec4d()
        return
    ia = edge
    ib = slot_end(edge)
    cg = edge_coords(xn, x[ia], x[ib])
    xi = wp.clamp(cg[0], zero, one)
    ab_c = x[ib] - x[ia]
    t_hat = ab_c / wp.length(ab_c)
    n_hat = wp.vec2d(t_hat[1], -t_hat[0])
    # penalty Kc = kn·A_node [Pa = N/m per m of overlap], capped at KC_CAP·m_min/Δt² (see module doc)
    m_min = wp.min(mesh.node_mass[n], wp.min(mesh.node_mass[ia], mesh.node_mass[ib]))
    kc = wp.min(prm.kn_area * trib, KC_CAP * m_min / (dt * dt))
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
        p_raw = pen - d0_prev
        if p_raw < zero and p_prev > zero:        # separation within the step: release force (module doc)
            q = release_overlap(p_prev, p_raw)
            fn = kc_prev * q
            # a sliding contact's friction impulse is corrected the same way (below); a sticking one is not
            released = wp.abs(fs_prev) >= (one - wp.float64(1.0e-9)) * prm.mu_f * kc_prev * p_prev
            fs_release = fs_prev * q / p_prev
            d0 = pen
            lost = half * fs_prev * fs_prev / kc_prev
        elif history == 3:                        # lost while still overlapping (slid off the edge's end)
            lost = half * kc_prev * p_raw * p_raw + half * fs_prev * fs_prev / kc_prev
        if history == 3:
            keep = False
        elif p_raw >= zero or p_prev == zero:     # ordinary contact on the same edge (or resting at p = 0)
            ov = penalty_overlap(1, pen, d0_prev, p_prev, kc_prev, kc)
            p = ov[0]
            d0 = ov[1]
            lost = ov[2]
            fs = fs_prev
            fn = kc * p
    else:
        ov2 = penalty_overlap(history, pen, d0_prev, p_prev, kc_prev, kc)
        p = ov2[0]
        d0 = ov2[1]
        lost = ov2[2]
        if history == 2:
            lost = lost + half * fs_prev * fs_prev / kc_prev      # friction history reset on a new edge
        fn = kc * p
    pen_lost = wp.where(lost > zero, lost, zero)  # (only a positive loss is booked)
    slip = zero
    vt = wp.dot(v[n] - ((one - xi) * v[ia] + xi * v[ib]), t_hat)
    if fn > zero:
        cu = coulomb_update(fs, kc, vt, dt, prm.mu_f * fn)
        fs = cu[0]
        slip = wp.where(cu[1] > zero, cu[1], zero)
    elif released:
        # the same first-order correction of the last step's tangential impulse (|Fs| ≤ μ|Fn| still holds);
        # its work is taken off the slip loss booked in the steps before
        fs = fs_release
        slip = -fs * vt * dt
    else:
        fs = zero
    if keep:
        hist.slot[n] = edge
        hist.state[n] = wp.vec4d(fs, d0, p, kc)
    else:
        hist.slot[n] = -1
        hist.state[n] = wp.vec4d()
    record_contact(n, ia, ib, fn * n_hat + fs * t_hat, xi, pen_lost, slip, item, rec, f, energy_acc, hist.loss_acc)



# inline: out of line, each call copied the node's ~40 arrays of the six structs onto the stack (LLVM left this one
# function out, for its size); inlined, the demo's cracked pass costs 0.53 against 0.63 ms, to the bit
@wp.func(inline=True)
def node_contact(
    n: wp.int32,
    use_cache: wp.int32,
    mesh: ContactMesh,
    hsh: ContactHash,
    cache: ContactCache,
    hist: ContactHistory,
    prm: ContactParams,
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    step: wp.int32,
    dt: wp.float64,
    item: wp.int32,
    rec: ContactRecords,
    f: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
):
    """The contact of node n at this step (its search, then contact_force; item: contact_force's)."""
    zero = wp.float64(0.0)
    nf = wp.vec2d()
    if use_cache != 0:
        nf = cache.node_face[n]
    else:
        nf = node_faces(n, mesh.slot_iface, mesh.slot_l0, pair_mode, pair_dropped)
    if nf[0] == zero:
        return                                    # no exposed edge at the node (listed nodes always have one)
    is_open = nf[1] != zero
    woken = node_woken(n // 3, cache.elem_near, step, prm.near_window)
    if not (is_open or woken) and prm.held_faces == 0 and hist.slot[n] < 0:
        return                                    # held broken faces not searched (BlockContact.held_faces)
    excl = wp.int64(0)
    if use_cache != 0:
        # the mask serves the hash search and a fan walk only: a held node with its fan cached leaves it unread
        if is_open or woken or cache.fan_count[n] < 0:
            excl = cache.fan_excl[n]
    else:
        excl = fan_exclusions(n, mesh.node_pairs, mesh.fan_index, mesh.pair_i, mesh.pair_j, pair_mode, pair_dropped)
    st = vec5d(wp.float64(-1.0), zero, zero, wp.float64(1.0e300), zero)
    if is_open:
        # the edges at its own vertex from its fan (as a held node), every step; the others through the hash,
        # unless it is quiet (its last search saw no such edge within wake_dist, BlockContact doc)
        st = held_search(n, excl, use_cache, mesh, pair_mode, x, prm, cache, True, step)
        if woken or step >= cache.query_after[n] or hist.slot[n] >= 0:
            st = hash_search(n, True, True, st, excl, use_cache, hsh, mesh, pair_mode, x, prm, step, cache)
        elif st[0] < zero:
            return
    elif woken:
        st = hash_search(n, False, False, st, excl, use_cache, hsh, mesh, pair_mode, x, prm, step, cache)
    elif prm.held_faces != 0:
        # broken faces still held by their springs, not woken: only the other blocks at the node's vertex
        st = held_search(n, excl, use_cache, mesh, pair_mode, x, prm, cache, False, step)
        # nothing found and no contact to end: contact_force would only rewrite the zeros of a node without one
        if st[0] < zero and hist.slot[n] < 0:
            return
    contact_force(n, nf[0], st, mesh, prm, x, v, dt, hist, item, rec, f, energy_acc)


@wp.kernel
def eval_block_contact(
    node_list: wp.array(dtype=wp.int32),
    counts: wp.array(dtype=wp.int32),
    part: wp.int32,
    stride: wp.int32,
    use_cache: wp.int32,
    mesh: ContactMesh,
    hsh: ContactHash,
    cache: ContactCache,
    hist: ContactHistory,
    prm: ContactParams,
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    clock: wp.array(dtype=wp.int32),
    dt: wp.float64,
    rec: ContactRecords,
    f: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
):
    """Contact of each listed node (select_contact_nodes, counts[1] of them), added to f and energy_acc. The tests
    that listed it are made again here. Thread i takes items i, i + stride, ...: one thread on a CPU (the list in
    order, whatever its length, and no per-thread copy of the structs for the items past its end), one item per
    thread on a GPU.

    part: 0 the whole list, 1 its first half, 2 its second half (two threads on a CPU; each item then goes into its
    record, which apply_contact_records adds in list order once both halves have run). A node reads the state of the
    pass's start only (positions, velocities, spring states, caches; a wake keeps the woken state it replaces) and
    writes its own history, query window and record, so the halves are independent, and the sums are those of one
    pass in list order."""
    n = counts[1]
    lo = wp.int32(0)
    hi = n
    if part == 1:
        hi = n / 2
    elif part == 2:
        lo = n / 2
    i = lo + wp.tid()
    step = clock[0]
    while i < hi:
        item = wp.int32(-1)
        if part != 0:
            item = i
            rec.nodes[i] = wp.vec3i(-1, -1, -1)  # nothing to add unless contact_force says otherwise
            rec.energy[i] = wp.vec2d()
        node_contact(node_list[i], use_cache, mesh, hsh, cache, hist, prm, pair_mode, pair_dropped, x, v, step, dt,
                     item, rec, f, energy_acc)
        i += stride


@wp.kernel
def apply_contact_records(counts: wp.array(dtype=wp.int32), rec: ContactRecords, f: wp.array(dtype=wp.vec2d),
                          energy_acc: wp.array(dtype=wp.float64), loss_acc: wp.array(dtype=wp.float64),
                          stride: wp.int32):
    """Add the records of a pass in parts (eval_block_contact) to the rock (add_contact), item by item in list order
    in one thread (stride 1): the sums of one pass over the list in one thread. Thread i takes items i, i + stride,
    ... (eval_block_contact)."""
    i = wp.tid()
    while i < counts[1]:
        nd = rec.nodes[i]
        e = rec.energy[i]
        add_contact(nd[0], nd[1], nd[2], rec.force[i], rec.xi[i], e[0], e[1], f, energy_acc, loss_acc)
        i += stride


@wp.kernel
def flag_any_dropped(pair_dropped: wp.array(dtype=wp.int32), flag: wp.array(dtype=wp.int32)):
    """flag[0] = 1 when a spring has dropped (BlockContact.any_dropped; flag zeroed before; every writer writes 1)."""
    if pair_dropped[wp.tid()] != 0:
        flag[0] = 1
