"""Warp kernels of the gas–rock coupling: exposed-element collection and particle–edge contact forces."""

from __future__ import annotations

import warp as wp

from blastfrac.cdem.contact_hash import cell_wrap, hash_cell, mark_cell_range, query_cells
from blastfrac.mpm.bodies import MAT_GAS

from .particle_edge import (CONTACT_HISTORY, contact_force, edge_overlap, initial_overlap, normal_force_cap,
                            pressure_offset, vertex_overlap)

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated

# slots of the coupling's energy accumulator
ACC_ABSORBED = wp.constant(0)   # work absorbed by the contacts since the start, −∫(P_gas + P_rock) dt [J/m]
ACC_STORED = wp.constant(1)     # penalty energy ½k_c·δ² stored in the contacts at this step [J/m]
ACC_CONTACTS = wp.constant(2)   # number of particle–element contacts at this step [-]
ACC_DISS = wp.constant(3)       # Σ over gas points of the contacts' dissipation rate at this step [W/m]
ACC_HEATED = wp.constant(4)     # contact dissipation handed to the gas as heat since the start [J/m]
ACC_HEAT_NEW = wp.constant(5)   # heat handed over at the last step, booked at the next (heat_gas_from_contacts) [J/m]
ACC_SIZE = 6


@wp.func
def slot_exposed(s: wp.int32, slot_iface: wp.array(dtype=wp.int32), pair_mode: wp.array(dtype=wp.int32)):
    """Edge slot s is exposed when it is on the mesh boundary or both springs of its interface broke."""
    q = slot_iface[s]
    if q < 0:
        return True
    return pair_mode[2 * q] > 0 and pair_mode[2 * q + 1] > 0


@wp.func
def contact_power(f: wp.vec2d, M: wp.mat22d, v: wp.vec2d, L: wp.mat22d):
    """f·v + M:L [W/m]: the power of a contact force f [N/m] applied with moment M [N] (mpm.kernels_p2g.p2g) on a
    particle moving at v [m/s] with velocity gradient L [1/s]."""
    return wp.dot(f, v) + M[0, 0] * L[0, 0] + M[0, 1] * L[0, 1] + M[1, 0] * L[1, 0] + M[1, 1] * L[1, 1]


#: the coupler's reach statistics (GasRockCoupler.reach): largest reach, sum of the reaches, elements listed [m, m, -]
REACH_MAX = 0
REACH_SUM = 1
REACH_COUNT = 2
#: the listed elements' size classes, each with its own hash: small (reach + margin within the coupler's split, found
#: by a search that wide) and large (found by a search of the largest reach); GasRockCoupler.note_reach
SMALL = 0
LARGE = 1


@wp.kernel
def collect_exposed_elements(
    slot_iface: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    elem_reach: wp.array(dtype=wp.float64),
    box_lo: wp.vec2d,
    box_hi: wp.vec2d,
    margin: wp.float64,
    split: wp.float64,
    count: wp.array(dtype=wp.int32),
    elems: wp.array(dtype=wp.int32),
    cls_count: wp.array(dtype=wp.int32),
    cls_elems: wp.array(dtype=wp.int32),
    cls_points: wp.array(dtype=wp.vec3d),
    reach: wp.array(dtype=wp.float64),
):
    """Compact list of the elements with an exposed edge (elems, count[0] of them), and the same elements by size
    class (cls_elems[c], cls_count[c]; SMALL: reach + margin ≤ split [m], else LARGE) with their centroids and reach as
    z [m] (cls_points[c]: a hash one cell deep files every z in its one layer, and a search reads the reach with the
    centroid), and the list's reach statistics (reach[REACH_MAX, REACH_SUM, REACH_COUNT]).

    Only elements that a particle inside the box box_lo..box_hi [m] (the MPM grid, which particles never
    leave) can reach are listed: centroid within reach + margin [m] of the box. Large far-field boundary
    elements would otherwise set the search radius of every particle.
    """
    e = wp.tid()
    s = 3 * e
    if not (slot_exposed(s, slot_iface, pair_mode) or slot_exposed(s + 1, slot_iface, pair_mode)
            or slot_exposed(s + 2, slot_iface, pair_mode)):
        return
    c = (x[s] + x[s + 1] + x[s + 2]) / wp.float64(3.0)
    re = elem_reach[e]
    r = re + margin
    if c[0] < box_lo[0] - r or c[0] > box_hi[0] + r or c[1] < box_lo[1] - r or c[1] > box_hi[1] + r:
        return
    k = wp.atomic_add(count, 0, 1)
    elems[k] = e
    cls = wp.where(r <= split, SMALL, LARGE)
    j = cls * elem_reach.shape[0] + wp.atomic_add(cls_count, cls, 1)      # class c from c·(elements) on
    cls_elems[j] = e
    cls_points[j] = wp.vec3d(c[0], c[1], re)
    wp.atomic_max(reach, REACH_MAX, re)
    wp.atomic_add(reach, REACH_SUM, re)
    wp.atomic_add(reach, REACH_COUNT, wp.float64(1.0))


@wp.struct
class ListedHash:
    """The listed elements' hashes, one per size class (GasRockCoupler): cell grids of their centroids in
    wp.HashGrid's cells and order (dim × dim cells, coordinates wrapped, each cell's points in list order), which a
    CUDA graph replays like any kernel (a captured wp.HashGrid build is not: coupled_graph.py). Class c's sorted
    list positions are values[c·stride + j], its cells' ranges starts/ends[c·dim² + cell]."""

    values: wp.array(dtype=wp.int32)     # list positions, sorted by cell (class c from c·stride on)
    starts: wp.array(dtype=wp.int32)     # first sorted position of each cell (class c from c·dim² on)
    ends: wp.array(dtype=wp.int32)       # one past its last
    cell_inv: wp.vec2d                   # 1 / cell width of each class [1/m]
    dim: wp.int32                        # cells along x and y
    stride: wp.int32                     # values per class


@wp.kernel
def listed_element_keys(cls_count: wp.array(dtype=wp.int32), cls: wp.int32, cls_elems: wp.array(dtype=wp.int32),
                        first: wp.int32, sentinel: wp.int32, keys: wp.array(dtype=wp.int32),
                        values: wp.array(dtype=wp.int32)):
    """keys[k], values[k] for the sort of class ``cls``'s list by element: element k and k; past the list's length
    ``sentinel`` (the element count), after every element. collect_exposed_elements appends in the order its threads
    arrive, which on a GPU changes from run to run; sorted, the list (and so the order in which a particle meets its
    elements, and which CONTACT_HISTORY of them it keeps) is the same on every device, as a CPU fills it."""
    k = wp.tid()
    key = sentinel
    if k < cls_count[cls]:
        key = cls_elems[first + k]
    keys[k] = key
    values[k] = k


@wp.kernel
def gather_listed(order: wp.array(dtype=wp.int32), cls_count: wp.array(dtype=wp.int32), cls: wp.int32,
                  first: wp.int32, cls_elems: wp.array(dtype=wp.int32), cls_points: wp.array(dtype=wp.vec3d),
                  out_elems: wp.array(dtype=wp.int32), out_points: wp.array(dtype=wp.vec3d)):
    """Class ``cls``'s listed elements and points in the sorted order ``order`` (copied back by the caller)."""
    k = wp.tid()
    if k < cls_count[cls]:
        j = first + order[k]
        out_elems[k] = cls_elems[j]
        out_points[k] = cls_points[j]


@wp.kernel
def hash_listed_points(cls_count: wp.array(dtype=wp.int32), cls: wp.int32, cls_points: wp.array(dtype=wp.vec3d),
                       first: wp.int32, cell_inv: wp.float64, dim: wp.int32, keys: wp.array(dtype=wp.int32),
                       values: wp.array(dtype=wp.int32)):
    """keys[k], values[k] for the sort of class ``cls``'s listed points by cell: the cell wp.HashGrid files centroid
    k in (its row-major index) and k; past the list's length (a captured rebuild covers the capacity) dim², after
    every cell."""
    k = wp.tid()
    key = dim * dim
    if k < cls_count[cls]:
        c = cls_points[first + k]
        key = hash_cell(c[0], c[1], cell_inv, dim)
    keys[k] = key
    values[k] = k


@wp.kernel
def listed_cell_ranges(keys: wp.array(dtype=wp.int32), count: wp.int32, dim: wp.int32, cbase: wp.int32,
                       starts: wp.array(dtype=wp.int32), ends: wp.array(dtype=wp.int32)):
    """After the stable sort by cell (keys, count of them): each cell's range of sorted positions."""
    j = wp.tid()
    if keys[j] < dim * dim:                             # (not past the list's length)
        mark_cell_range(keys, j, count, cbase, starts, ends)


@wp.kernel
def eval_particle_edge_contact(
    hsh: ListedHash,
    cls_count: wp.array(dtype=wp.int32),
    cls_elems: wp.array(dtype=wp.int32),
    cls_points: wp.array(dtype=wp.vec3d),
    slot_iface: wp.array(dtype=wp.int32),
    pair_mode: wp.array(dtype=wp.int32),
    x_rock: wp.array(dtype=wp.vec2d),
    v_rock: wp.array(dtype=wp.vec2d),
    m_rock: wp.array(dtype=wp.float64),
    x_p: wp.array(dtype=wp.vec2d),
    v_p: wp.array(dtype=wp.vec2d),
    grad_v: wp.array(dtype=wp.mat22d),
    m_p: wp.array(dtype=wp.float64),
    vol_p: wp.array(dtype=wp.float64),
    p_p: wp.array(dtype=wp.float64),
    rho_p: wp.array(dtype=wp.float64),
    active: wp.array(dtype=wp.int32),
    kc: wp.float64,
    kappa: wp.float64,
    zeta: wp.float64,
    mu: wp.float64,
    r_max: wp.float64,
    reach: wp.array(dtype=wp.float64),
    query_margin: wp.float64,
    split: wp.float64,
    dt: wp.float64,
    surface: wp.float64,
    preload: wp.float64,
    w_old: wp.float64,
    w_new: wp.float64,
    heat: wp.float64,
    mat_kind: wp.array(dtype=wp.int32),
    hist_e_in: wp.array(dtype=wp.int32),
    hist_d_in: wp.array(dtype=wp.float64),
    hist_x_in: wp.array(dtype=wp.float64),
    f_p: wp.array(dtype=wp.vec2d),
    fm_p: wp.array(dtype=wp.mat22d),
    f_react: wp.array(dtype=wp.vec2d),
    acc: wp.array(dtype=wp.float64),
    hist_e_out: wp.array(dtype=wp.int32),
    hist_d_out: wp.array(dtype=wp.float64),
    hist_x_out: wp.array(dtype=wp.float64),
    diss_p: wp.array(dtype=wp.float64),
):
    """Contact force on each particle (assigned to f_p) and its reactions on the rock nodes (added to f_react,
    which the step adds to the rock's forces: coupler.add_reactions), METHOD §3.

    cls_points, cls_elems, cls_count: the listed elements by size class (collect_exposed_elements): centroids at the
    last rebuild with their reach as z [m], elements, counts. Two searches through ``hsh`` (ListedHash): the small
    elements' hash within ``split`` [m] (their reach + query_margin is within it) or the largest search radius where
    that is less (split = ∞: one class), then, where there are any, the large ones' within reach[REACH_MAX] +
    query_margin [m] (the list's largest reach, read here, so that a rebuild reads nothing back): the few large
    blocks of a coarse far mesh no longer widen every particle's search. A hash built over the list's whole capacity
    (a captured step, GasRockCoupler) files the points past its length after every cell, so a search meets the
    listed points of a hash of those alone, in the same order.
    hist_*_in / hist_*_out: the particle's contacts of the previous / this step, CONTACT_HISTORY slots
    each (8·element + feature, ignored initial overlap δ₀ [m], effective overlap δ − δ₀ [m]); feature 0–2:
    edge k, 3–5: vertex k; −1 marks an empty slot.

    The contact-work book (GasRockCoupler.energies) of the gas side is kept here too: acc[ABSORBED] −=
    w_old·P(last step's f, M) + w_new·P(this step's f, M), with P = contact_power at the particle's present v and L
    (w = ½Δt of each step: each step's work with the mean of the velocities before and after it).
    """
    p = wp.tid()
    zero = wp.float64(0.0)
    one = wp.float64(1.0)
    fsum = wp.vec2d(zero, zero)
    msum = wp.mat22d(zero, zero, zero, zero)
    h0 = p * CONTACT_HISTORY
    for h in range(CONTACT_HISTORY):
        hist_e_out[h0 + h] = -1
    if active[p] == 0:
        f_p[p] = fsum
        fm_p[p] = msum
        if heat > zero:
            diss_p[p] = zero          # a point that left the grid holds no share of the contacts' heat
        return
    xp = x_p[p]
    vp = v_p[p]
    mp = m_p[p]
    Lp = grad_v[p]
    work = w_old * contact_power(f_p[p], fm_p[p], vp, Lp)          # the last step's forces, their second half
    rp = wp.min(wp.float64(0.5) * wp.sqrt(vol_p[p]), r_max)
    rc = rp + preload * pressure_offset(p_p[p], rp, kc)
    stored = wp.float64(0.0)
    qsum = wp.float64(0.0)
    ncon = int(0)
    for cls in range(2):
        if cls_count[cls] == 0:                   # (an empty class's hash may hold an older list)
            continue
        first = cls * (cls_points.shape[0] // 2)       # class c from c·(elements) on
        query_radius = reach[REACH_MAX] + query_margin
        if cls == SMALL:
            query_radius = wp.min(split, query_radius)
        # the cells wp.HashGrid's search would visit, in its order, each cell's points in list order
        dim = hsh.dim
        inv = hsh.cell_inv[cls]
        cr = query_cells(xp, query_radius, inv, dim)
        for cy in range(cr[2], cr[3] + 1):
            row = cls * dim * dim + cell_wrap(cy, dim) * dim
            for cx in range(cr[0], cr[1] + 1):
                cc = row + cell_wrap(cx, dim)
                for j in range(hsh.starts[cc], hsh.ends[cc]):
                    idx = hsh.values[cls * hsh.stride + j]
                    # the hash holds whole cells: skip elements whose reach (from the centroid listed at the last
                    # rebuild, with the same allowance for motion as the search radius; the point's z) cannot meet
                    # the particle's contact disk, before loading anything else of them
                    c = cls_points[first + idx]
                    dx = xp[0] - c[0]
                    dy = xp[1] - c[1]
                    lim = c[2] + rc
                    if dx * dx + dy * dy > lim * lim:
                        continue
                    e = cls_elems[first + idx]
                    best = wp.float64(-1.0)
                    bn = wp.vec2d(zero, zero)
                    ia = int(-1)
                    ib = int(-1)
                    bk = int(-1)
                    bxi = wp.float64(0.0)
                    for k in range(3):
                        s = 3 * e + k
                        if slot_exposed(s, slot_iface, pair_mode):
                            b = 3 * e + (k + 1) % 3
                            de, ne, xie = edge_overlap(xp, rc, x_rock[s], x_rock[b])
                            if de > best:
                                best = de
                                bn = ne
                                ia = s
                                ib = b
                                bk = k
                                bxi = xie
                    for k in range(3):
                        a = 3 * e + k
                        if slot_exposed(a, slot_iface, pair_mode) or \
                                slot_exposed(3 * e + (k + 2) % 3, slot_iface, pair_mode):
                            dv, nv = vertex_overlap(xp, rc, x_rock[a])
                            if dv > best:
                                best = dv
                                bn = nv
                                ia = a
                                ib = a
                                bk = 3 + k
                                bxi = zero
                    if best > zero:
                        wa = one - bxi
                        mc = wa * m_rock[ia] + bxi * m_rock[ib]
                        vc = wa * v_rock[ia] + bxi * v_rock[ib]
                        cn = wp.float64(2.0) * zeta * wp.sqrt(kc * mp * mc / (mp + mc))
                        arm = -surface * rp * bn            # contact point (disk surface) − particle centre [m]
                        vrel = vp + Lp * arm - vc           # gas velocity at the contact point − wall velocity
                        # initial overlap δ₀ (ignored part of the overlap): kept from the last step's contact with
                        # element e, else what a new contact cannot explain. The deepest feature of an element (edge
                        # or vertex bk) can change, e.g. for a particle an element rotated over; δ₀ belonged to the
                        # old feature, so it is re-based to keep the force continuous, δ₀ = δ − (δ − δ₀)_last.
                        # (Reusing it against the new feature made the force jump by k_c times the difference,
                        # 140 µm once in a single-hole blast, and the run went unstable; treating the switch as a new
                        # contact gave the slack k_c·0.1r_p for free at every switch.)
                        key = 8 * e + bk
                        d0 = wp.float64(-1.0)
                        for h in range(CONTACT_HISTORY):
                            he = hist_e_in[h0 + h]
                            if he == key:
                                d0 = wp.min(hist_d_in[h0 + h], best)
                            elif he >= 0 and he // 8 == e:
                                d0 = wp.max(best - hist_x_in[h0 + h], zero)
                        if d0 < zero:
                            d0 = initial_overlap(best, wp.dot(vrel, bn), dt, rp)
                        if ncon < CONTACT_HISTORY:
                            hist_e_out[h0 + ncon] = key
                            hist_d_out[h0 + ncon] = d0
                            hist_x_out[h0 + ncon] = best - d0
                        best = best - d0
                        fcap = wp.float64(0.0)
                        if kappa > zero:
                            fcap = normal_force_cap(kappa, p_p[p], rho_p[p], wp.dot(vrel, bn), rp)
                        f, pw = contact_force(best, bn, vrel, kc, cn, mu, fcap)
                        qsum = qsum + pw
                        fsum = fsum + f
                        msum = msum + wp.outer(f, arm)
                        wp.atomic_add(f_react, ia, -wa * f)
                        wp.atomic_add(f_react, ib, -bxi * f)
                        stored = stored + wp.float64(0.5) * kc * best * best
                        ncon = ncon + 1
    f_p[p] = fsum
    fm_p[p] = msum
    work = work + w_new * contact_power(fsum, msum, vp, Lp)         # this step's forces, their first half
    if heat > zero:                                   # this step's dissipation rate, the weight of the gas's heat
        q = zero
        if mat_kind[p] == MAT_GAS:
            q = qsum
        diss_p[p] = q
        if q > zero:
            wp.atomic_add(acc, ACC_DISS, q)
    if work != zero:
        wp.atomic_add(acc, ACC_ABSORBED, -work)
    if ncon > 0:
        wp.atomic_add(acc, ACC_STORED, stored)
        wp.atomic_add(acc, ACC_CONTACTS, wp.float64(ncon))


@wp.kernel
def accumulate_gas_contact_work(
    f_p: wp.array(dtype=wp.vec2d),
    fm_p: wp.array(dtype=wp.mat22d),
    v_p: wp.array(dtype=wp.vec2d),
    grad_v: wp.array(dtype=wp.mat22d),
    active: wp.array(dtype=wp.int32),
    w: wp.float64,
    acc: wp.array(dtype=wp.float64),
):
    """acc[ABSORBED] −= w·(f·v + M:L) [J/m]: work the contact forces f [N/m], applied with moment M [N] (see
    mpm.kernels_p2g.p2g), do on the gas moving with velocity v [m/s] and velocity gradient L [1/s] over a time w [s]."""
    p = wp.tid()
    if active[p] == 0:
        return
    pw = contact_power(f_p[p], fm_p[p], v_p[p], grad_v[p])
    if pw != wp.float64(0.0):
        wp.atomic_add(acc, ACC_ABSORBED, -w * pw)


@wp.func
def listed_node(elems: wp.array(dtype=wp.int32), i: int):
    """The i-th node of the listed elements' nodes, in the list's order (each block has its own three nodes,
    3e … 3e + 2, so the nodes of the list are distinct)."""
    return 3 * elems[i / 3] + i % 3


@wp.kernel
def account_rock_work_and_clear(
    elems: wp.array(dtype=wp.int32),
    count: wp.array(dtype=wp.int32),
    f_react: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    w: wp.float64,
    acc: wp.array(dtype=wp.float64),
):
    """acc[ABSORBED] −= w·f·v for the last step's reactions f [N/m] at the rock's present velocities v [m/s] (their
    second half, w = ½Δt [s]), then f_react = 0 for this step's; and the per-step books acc[STORED] and
    acc[CONTACTS] start again from 0 (thread 0: the contact kernel fills them after this one). Thread 0 also books
    the heat the last step handed to the gas (acc[HEAT_NEW], heat_gas_from_contacts): it leaves the contacts' book
    (absorbed −= it, atomically, beside the other threads' adds) into acc[HEATED], so the budget is unchanged.

    Only the nodes of the listed elements (elems, the list the last step's contact kernel searched; count[0] its
    length) can carry a reaction, so the launch covers them (at least one thread, for the books) and not the whole
    rock: on a CPU the list is in element order, so the sum is the one over all nodes, whose other terms are 0. A
    launch over more threads (a captured step: the list's capacity) does the same; the extra ones return."""
    i = wp.tid()
    if i == 0:
        acc[ACC_STORED] = wp.float64(0.0)
        acc[ACC_CONTACTS] = wp.float64(0.0)
        acc[ACC_DISS] = wp.float64(0.0)
        q = acc[ACC_HEAT_NEW]
        if q != wp.float64(0.0):
            wp.atomic_add(acc, ACC_ABSORBED, -q)
            acc[ACC_HEATED] = acc[ACC_HEATED] + q
            acc[ACC_HEAT_NEW] = wp.float64(0.0)
    if i >= 3 * count[0]:
        return
    n = listed_node(elems, i)
    f = f_react[n]
    if f[0] != wp.float64(0.0) or f[1] != wp.float64(0.0):
        if w != wp.float64(0.0):
            wp.atomic_add(acc, ACC_ABSORBED, -w * wp.dot(f, v[n]))
        f_react[n] = wp.vec2d(wp.float64(0.0), wp.float64(0.0))


@wp.kernel
def add_reactions_with_work(
    elems: wp.array(dtype=wp.int32),
    count: wp.array(dtype=wp.int32),
    f: wp.array(dtype=wp.vec2d),
    f_react: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    w: wp.float64,
    acc: wp.array(dtype=wp.float64),
):
    """f += f_react [N/m] (the gas loads on the rock nodes, after the rock's own forces) and acc[ABSORBED] −= w·f·v,
    their work at the velocities v [m/s] before the step over w = ½Δt [s] (the first half); one thread per node of
    the listed elements (elems, count[0] of them), the only nodes the contact kernel loads; threads beyond them (a
    launch over the list's capacity) return."""
    i = wp.tid()
    if i >= 3 * count[0]:
        return
    n = listed_node(elems, i)
    a = f_react[n]
    if a[0] != wp.float64(0.0) or a[1] != wp.float64(0.0):
        f[n] = f[n] + a
        if w != wp.float64(0.0):
            wp.atomic_add(acc, ACC_ABSORBED, -w * wp.dot(a, v[n]))


@wp.func
def contact_heat(acc: wp.array(dtype=wp.float64)):
    """Q [J/m]: what the contacts have dissipated and not yet handed on, max(absorbed − stored, 0), when some gas
    point's contacts dissipate this step (else 0: it waits)."""
    q = acc[ACC_ABSORBED] - acc[ACC_STORED]
    if q <= wp.float64(0.0) or acc[ACC_DISS] <= wp.float64(0.0):
        return wp.float64(0.0)
    return q


@wp.kernel
def heat_gas_from_contacts(acc: wp.array(dtype=wp.float64), diss_p: wp.array(dtype=wp.float64),
                           ie: wp.array(dtype=wp.float64)):
    """ie_p += Q·q_p / Σq [J/m]: the contacts' dissipation Q (:func:`contact_heat`) heats the gas points in contact,
    in proportion to their contacts' dissipation rates q_p [W/m] this step (coupling.contact_heating). Each share
    is added to acc[HEAT_NEW] (read by no thread here), which the next step's account_rock_work_and_clear books:
    one launch fewer than a one-thread booking kernel, and no thread writes what another reads."""
    p = wp.tid()
    q = diss_p[p]
    if q <= wp.float64(0.0):
        return
    Q = contact_heat(acc)
    if Q > wp.float64(0.0):
        share = Q * (q / acc[ACC_DISS])
        ie[p] = ie[p] + share
        wp.atomic_add(acc, ACC_HEAT_NEW, share)
