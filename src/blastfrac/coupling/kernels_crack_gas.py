"""Kernels of the crack-gas stage (coupling/crack_gas.py): gas cells in broken interfaces, their pressure on the
crack faces, the flow between them and from the MPM gas at the crack mouths.

A *cell* is one interface q of the block mesh once both its springs have broken. Its four nodes, taken in the
order (j_A, j_B, i_B, i_A) (the j nodes belong to element e2, the i nodes to e1, A and B are the interface's
two vertices), run counter-clockwise around the opening between the faces, so that the shoelace area

    V(x) = ½ Σ_k x_k × x_{k+1}                                             [m² per unit thickness]

is the cell's volume, positive when the crack opens. The gas pushes on the faces with f_k = p·∂V/∂x_k
(``quad_area_gradient``): the virtual work of the pressure, so that p·dV is exactly the work the faces receive
(the end segments j_A–i_A and j_B–i_B carry the same pressure and are shared, with opposite sense, by the
neighbouring cell of a straight crack). Units SI, per unit thickness.
"""

from __future__ import annotations

import warp as wp

from blastfrac.cdem.contact_hash import cell_wrap, hash_cell, query_cells
from blastfrac.materials.crack_flow import crack_mass_flux
from blastfrac.materials.jwl import V_FLOOR, jwl_pressure, jwl_sound_speed_sq

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated

F64 = wp.float64

#: a path moves at most this fraction of the mass that would equalise its two pressures in one step, estimated
#: from each side's pressure stiffness c²/V; this keeps the explicit flow monotone (no pressure overshoot between
#: cells) where the cubic law's diffusivity w²ρc²/(12μ) exceeds Δx²/Δt
EQUALISE = 0.25


@wp.struct
class CrackCells:
    """Static description of the candidate cells (every interface q).

    nodes: (j_A, j_B, i_B, i_A), counter-clockwise around the opening [Q] vec4i; length: reference edge length [m] [Q]
    """

    nodes: wp.array(dtype=wp.vec4i)
    length: wp.array(dtype=wp.float64)


@wp.struct
class CrackGasState:
    """Gas in the cells [Q] (force: [4Q]).

    mass [kg/m]; energy: internal energy [J/m]; vol: volume max(V, w_min·L) [m²]; pres [Pa]; cs [m/s];
    gamma: ρc²/p [-]; gap: opening at the ends A and B, ≥ 0 [m] (vec2d); force: on the 4 nodes this step [N/m];
    wet: 1 once both springs of the interface have broken, 2 once it opened wider than a material point and
    handed its gas to the MPM (release_wide_cells); p_fixed: prescribed pressure [Pa] (≥ 0) instead of the
    EOS (verification); out: outflow asked of the cell this step [kg/m]; scale: fraction of it granted [-].
    """

    mass: wp.array(dtype=wp.float64)
    energy: wp.array(dtype=wp.float64)
    vol: wp.array(dtype=wp.float64)
    pres: wp.array(dtype=wp.float64)
    cs: wp.array(dtype=wp.float64)
    gamma: wp.array(dtype=wp.float64)
    gap: wp.array(dtype=wp.vec2d)
    force: wp.array(dtype=wp.vec2d)
    wet: wp.array(dtype=wp.int32)
    p_fixed: wp.array(dtype=wp.float64)
    out: wp.array(dtype=wp.float64)
    scale: wp.array(dtype=wp.float64)


@wp.struct
class CrackGasParams:
    """JWL set of the products (rho0 [kg/m³], A, B [Pa], R1, R2, omega [-]), p_max: pressure cap [Pa] (P_CJ);
    mu: gas viscosity [Pa·s]; w_min: aperture floor of the cell volume [m]; cell_fraction, particle_fraction:
    the most a cell / a particle may give in one step [-]; particle_floor: a particle keeps at least this mass
    fraction of its own initial mass [-]."""

    rho0: wp.float64
    A: wp.float64
    B: wp.float64
    R1: wp.float64
    R2: wp.float64
    omega: wp.float64
    p_max: wp.float64
    mu: wp.float64
    w_min: wp.float64
    cell_fraction: wp.float64
    particle_fraction: wp.float64


@wp.struct
class CrackLinks:
    """Flow paths of this rebuild [capacity], the first ``count[0]`` in use.

    a: a cell; b: a cell, or −(particle + 1) for a mouth; ends: the end (0 = A, 1 = B) of a and of b where they
    meet; dx: distance over which the pressure drops [m]; dm: mass asked this step, + from a to b [kg/m];
    h: the donor's specific total enthalpy [J/kg].
    """

    a: wp.array(dtype=wp.int32)
    b: wp.array(dtype=wp.int32)
    ends: wp.array(dtype=wp.vec2i)
    dx: wp.array(dtype=wp.float64)
    dm: wp.array(dtype=wp.float64)
    h: wp.array(dtype=wp.float64)
    count: wp.array(dtype=wp.int32)


@wp.struct
class GasParticles:
    """Views of the MPM particle arrays the exchange reads and edits, plus its own per-particle scratch.

    mass0: mass at seeding [kg/m]; out: outflow asked this step [kg/m]; scale: fraction granted [-];
    touched: 1 when the step changed the particle's mass.
    """

    x: wp.array(dtype=wp.vec2d)
    v: wp.array(dtype=wp.vec2d)
    mass: wp.array(dtype=wp.float64)
    mass0: wp.array(dtype=wp.float64)
    vol: wp.array(dtype=wp.float64)
    vol0: wp.array(dtype=wp.float64)
    rho: wp.array(dtype=wp.float64)
    ie: wp.array(dtype=wp.float64)
    pres: wp.array(dtype=wp.float64)
    q: wp.array(dtype=wp.float64)
    burn: wp.array(dtype=wp.float64)
    stress: wp.array(dtype=wp.mat22d)
    active: wp.array(dtype=wp.int32)
    out: wp.array(dtype=wp.float64)
    scale: wp.array(dtype=wp.float64)
    touched: wp.array(dtype=wp.int32)


@wp.struct
class FaceLoads:
    """This step's crack-face loads and the nodes that carry them: update_crack_cells adds each wet cell's face
    forces into f and lists each node the first time it loads it (mark), so that adding them to the rock
    (add_face_loads) and clearing them for the next step (clear_face_loads) visit those nodes only, not the rock's."""

    f: wp.array(dtype=wp.vec2d)          # face load of each node [N/m]
    mark: wp.array(dtype=wp.int32)       # 1: the node is in the list
    nodes: wp.array(dtype=wp.int32)      # the loaded nodes, count[0] of them (capacity: every node)
    count: wp.array(dtype=wp.int32)


@wp.struct
class GasHash:
    """The active, fully burnt gas points filed in a cell grid, rebuilt with the network (``hash_burnt_particles``):
    wp.HashGrid's dim × dim cells of width 1/cell_inv [m], coordinates wrapped. The mouths and the wide cells look
    for their particle in the cells within their search radius instead of over every particle."""

    values: wp.array(dtype=wp.int32)     # particle indices sorted by cell (twice the particle count: the radix sort)
    starts: wp.array(dtype=wp.int32)     # first sorted position of each of the dim² cells
    ends: wp.array(dtype=wp.int32)       # one past its last (starts = ends = 0: an empty cell)
    cell_inv: wp.float64                 # 1 / cell width [1/m]
    dim: wp.int32                        # cells along x and y


# ----------------------------------------------------------------------------- functions
@wp.func
def quad_area(x0: wp.vec2d, x1: wp.vec2d, x2: wp.vec2d, x3: wp.vec2d):
    """Signed (shoelace) area of the polygon x0 → x1 → x2 → x3 [m²], positive counter-clockwise."""
    return F64(0.5) * ((x0[0] * x1[1] - x1[0] * x0[1]) + (x1[0] * x2[1] - x2[0] * x1[1])
                       + (x2[0] * x3[1] - x3[0] * x2[1]) + (x3[0] * x0[1] - x0[0] * x3[1]))


@wp.func
def quad_area_gradient(prev: wp.vec2d, nxt: wp.vec2d):
    """∂V/∂x_k = ½ (y_{k+1} − y_{k−1}, x_{k−1} − x_{k+1}) [m] of the shoelace area at a vertex between prev and nxt."""
    return wp.vec2d(F64(0.5) * (nxt[1] - prev[1]), F64(0.5) * (prev[0] - nxt[0]))


@wp.func
def products_state(m: wp.float64, e_int: wp.float64, vol: wp.float64, prm: CrackGasParams):
    """(p [Pa], c [m/s], γ = ρc²/p [-]) of a gas mass m [kg/m] with internal energy e_int [J/m] in vol [m²].

    The JWL is written per unit initial volume: V = ρ0·vol/m, E = e_int·ρ0/m (clamped ≥ 0); V ≥ V_FLOOR as in the
    MPM; 0 ≤ p ≤ p_max. An empty cell has p = c = 0.
    """
    if m <= F64(0.0) or vol <= F64(0.0):
        return wp.vec3d(F64(0.0), F64(0.0), F64(1.0))
    V = wp.max(prm.rho0 * vol / m, F64(V_FLOOR))
    E = wp.max(e_int * prm.rho0 / m, F64(0.0))
    p = jwl_pressure(V, E, prm.A, prm.B, prm.R1, prm.R2, prm.omega)
    p = wp.clamp(p, F64(0.0), prm.p_max)
    c2 = jwl_sound_speed_sq(V, E, p, prm.rho0, prm.A, prm.B, prm.R1, prm.R2, prm.omega)
    g = F64(1.0)
    if p > F64(0.0):
        g = (m / vol) * c2 / p
    return wp.vec3d(p, wp.sqrt(c2), g)


@wp.func
def nearest_burnt(hsh: GasHash, parts: GasParticles, pt: wp.vec2d, radius: wp.float64, mass_floor: wp.float64):
    """Index of the active, fully burnt particle nearest to pt [m] closer than ``radius`` [m], of mass above
    ``mass_floor``·mass0 (a negative floor: any mass); −1 if none. It reads the cells that the disc of ``radius``
    touches (3 × 3 where the cells are as wide as the radius), each at most once. Of equally near particles the
    lowest index, so the answer is that of a search over every particle in index order."""
    inv = hsh.cell_inv
    dim = hsh.dim
    cr = query_cells(pt, radius, inv, dim)
    best = int(-1)
    d2best = radius * radius
    for cy in range(cr[2], cr[3] + 1):
        row = cell_wrap(cy, dim) * dim
        for cx in range(cr[0], cr[1] + 1):
            c = row + cell_wrap(cx, dim)
            for j in range(hsh.starts[c], hsh.ends[c]):
                r = hsh.values[j]
                if parts.mass[r] <= mass_floor * parts.mass0[r]:
                    continue
                d = parts.x[r] - pt
                d2 = wp.dot(d, d)
                if d2 < d2best or (d2 == d2best and best >= 0 and r < best):
                    d2best = d2
                    best = r
    return best


@wp.func
def add_face_load(loads: FaceLoads, n: int, f: wp.vec2d):
    """loads.f[n] += f [N/m], and node n listed once (its mark taken atomically: one thread lists it)."""
    wp.atomic_add(loads.f, n, f)
    if wp.atomic_add(loads.mark, n, 1) == 0:
        loads.nodes[wp.atomic_add(loads.count, 0, 1)] = n


# ----------------------------------------------------------------------------- kernels
@wp.kernel
def hash_burnt_particles(parts: GasParticles, hsh: GasHash, keys: wp.array(dtype=wp.int32)):
    """keys[r], values[r] for the sort of the particles by cell (GasHash): the cell of an active, fully burnt
    particle, dim² (after every cell) for the others."""
    r = wp.tid()
    key = hsh.dim * hsh.dim
    if parts.active[r] != 0 and parts.burn[r] >= F64(1.0):
        x = parts.x[r]
        key = hash_cell(x[0], x[1], hsh.cell_inv, hsh.dim)
    keys[r] = key
    hsh.values[r] = r


@wp.kernel
def update_crack_cells(cells: CrackCells, gas: CrackGasState, prm: CrackGasParams,
                       pair_mode: wp.array(dtype=wp.int32), x: wp.array(dtype=wp.vec2d), v: wp.array(dtype=wp.vec2d),
                       dt_prev: wp.float64, dt: wp.float64, loads: FaceLoads):
    """Volume, openings, pressure and face forces of each wet cell; the gas pays the forces' work.

    Work: ½dt_prev·Σ f_old·v for the last step's forces (second half) and ½dt·Σ f_new·v for this step's (first
    half), both with the present velocities v^{n−½}, as the particle–edge contact does
    (coupler.GasRockCoupler.energies): the mean of the velocities before and after a step, the work the
    central-difference update receives.
    """
    q = wp.tid()
    if pair_mode[2 * q] == 0 or pair_mode[2 * q + 1] == 0 or gas.wet[q] == 2:
        return
    gas.wet[q] = 1
    n = cells.nodes[q]
    xs0 = x[n[0]]
    xs1 = x[n[1]]
    xs2 = x[n[2]]
    xs3 = x[n[3]]
    e = gas.energy[q]
    w_old = F64(0.0)
    for k in range(4):
        w_old += wp.dot(gas.force[4 * q + k], v[n[k]])
    e = e - F64(0.5) * dt_prev * w_old
    L = cells.length[q]
    area = quad_area(xs0, xs1, xs2, xs3)
    vol = wp.max(area, prm.w_min * L)
    # openings at A (i_A = n3 → j_A = n0) and B (i_B = n2 → j_B = n1) along e1's outward normal
    t = xs2 - xs3
    tl = wp.length(t)
    nrm = wp.vec2d(F64(0.0), F64(0.0))
    if tl > F64(0.0):
        nrm = wp.vec2d(t[1] / tl, -t[0] / tl)
    gap = wp.vec2d(wp.max(wp.dot(xs0 - xs3, nrm), F64(0.0)), wp.max(wp.dot(xs1 - xs2, nrm), F64(0.0)))
    s = products_state(gas.mass[q], e, vol, prm)
    p = s[0]
    if gas.p_fixed[q] >= F64(0.0):
        p = gas.p_fixed[q]
    f0 = p * quad_area_gradient(xs3, xs1)
    f1 = p * quad_area_gradient(xs0, xs2)
    f2 = p * quad_area_gradient(xs1, xs3)
    f3 = p * quad_area_gradient(xs2, xs0)
    w_new = wp.dot(f0, v[n[0]]) + wp.dot(f1, v[n[1]]) + wp.dot(f2, v[n[2]]) + wp.dot(f3, v[n[3]])
    gas.energy[q] = e - F64(0.5) * dt * w_new
    gas.force[4 * q + 0] = f0
    gas.force[4 * q + 1] = f1
    gas.force[4 * q + 2] = f2
    gas.force[4 * q + 3] = f3
    if p > F64(0.0):
        add_face_load(loads, n[0], f0)
        add_face_load(loads, n[1], f1)
        add_face_load(loads, n[2], f2)
        add_face_load(loads, n[3], f3)
    gas.vol[q] = vol
    gas.gap[q] = gap
    gas.pres[q] = p
    gas.cs[q] = s[1]
    gas.gamma[q] = s[2]
    gas.out[q] = F64(0.0)


@wp.kernel
def add_face_loads(f: wp.array(dtype=wp.vec2d), loads: FaceLoads):
    """f += this step's face loads [N/m], at the listed nodes (threads beyond the list's length return)."""
    i = wp.tid()
    if i >= loads.count[0]:
        return
    n = loads.nodes[i]
    f[n] = f[n] + loads.f[n]


@wp.kernel
def clear_face_loads(loads: FaceLoads):
    """The last step's loads and marks back to 0 at the nodes it listed (threads beyond its length return)."""
    i = wp.tid()
    if i >= loads.count[0]:
        return
    n = loads.nodes[i]
    loads.f[n] = wp.vec2d(F64(0.0), F64(0.0))
    loads.mark[n] = 0


@wp.kernel
def collect_cell_links(pairs: wp.array(dtype=wp.vec2i), ends: wp.array(dtype=wp.vec2i), dx: wp.array(dtype=wp.float64),
                       wet: wp.array(dtype=wp.int32), links: CrackLinks):
    """Append the static cell pairs (two interfaces sharing a vertex) whose cells are both wet."""
    k = wp.tid()
    c = pairs[k]
    if wet[c[0]] != 1 or wet[c[1]] != 1:
        return
    i = wp.atomic_add(links.count, 0, 1)
    links.a[i] = c[0]
    links.b[i] = c[1]
    links.ends[i] = ends[k]
    links.dx[i] = dx[k]


@wp.kernel
def collect_mouths(cand_cell: wp.array(dtype=wp.int32), cand_end: wp.array(dtype=wp.int32), cells: CrackCells,
                   wet: wp.array(dtype=wp.int32), x: wp.array(dtype=wp.vec2d), parts: GasParticles, hsh: GasHash,
                   radius: wp.float64, min_mass_fraction: wp.float64, links: CrackLinks):
    """A wet cell's end on a surface vertex (borehole wall, free face) with burnt gas within ``radius`` [m] of it
    becomes a mouth, fed by the nearest fully burnt active particle above the mass floor (``nearest_burnt``)."""
    k = wp.tid()
    q = cand_cell[k]
    if wet[q] != 1:
        return
    end = cand_end[k]
    n = cells.nodes[q]
    pt = wp.vec2d(F64(0.0), F64(0.0))
    if end == 0:
        pt = F64(0.5) * (x[n[0]] + x[n[3]])
    else:
        pt = F64(0.5) * (x[n[1]] + x[n[2]])
    best = nearest_burnt(hsh, parts, pt, radius, min_mass_fraction)
    if best < 0:
        return
    i = wp.atomic_add(links.count, 0, 1)
    links.a[i] = q
    links.b[i] = -(best + 1)
    links.ends[i] = wp.vec2i(end, 0)
    links.dx[i] = F64(0.5) * cells.length[q]


@wp.func
def _particle_gas(parts: GasParticles, r: int, prm: CrackGasParams):
    """(p, ρ, c, γ, h) of particle r: its pressure, density, JWL sound speed, ρc²/p and total enthalpy e + p/ρ + ½v²."""
    m = parts.mass[r]
    vol = parts.vol[r]
    v0 = parts.vol0[r]
    p = parts.pres[r]
    rho = m / vol
    V = wp.max(vol / v0, F64(V_FLOOR))
    E = wp.max(parts.ie[r] / v0, F64(0.0))
    c2 = jwl_sound_speed_sq(V, E, p, prm.rho0, prm.A, prm.B, prm.R1, prm.R2, prm.omega)
    g = F64(1.0)
    if p > F64(0.0):
        g = rho * c2 / p
    vv = parts.v[r]
    h = parts.ie[r] / m + p / rho + F64(0.5) * wp.dot(vv, vv)
    return wp.spatial_vectord(p, rho, wp.sqrt(c2), g, h, F64(0.0))


@wp.kernel
def crack_link_flux(links: CrackLinks, gas: CrackGasState, parts: GasParticles, prm: CrackGasParams, dt: wp.float64):
    """Mass each path asks of its donor (the higher-pressure side) this step and the donor's enthalpy."""
    k = wp.tid()
    if k >= links.count[0]:
        return
    a = links.a[k]
    b = links.b[k]
    e = links.ends[k]
    ga = gas.gap[a]
    w = ga[e[0]]
    pa = gas.pres[a]
    ma = gas.mass[a]
    rho_a = ma / gas.vol[a]
    ha = F64(0.0)
    if ma > F64(0.0):
        ha = gas.energy[a] / ma + pa / rho_a
    pb = F64(0.0)
    rho_b = F64(0.0)
    cb = F64(0.0)
    gb = F64(1.0)
    hb = F64(0.0)
    if b >= 0:
        gbp = gas.gap[b]
        w = wp.min(w, gbp[e[1]])
        mb = gas.mass[b]
        pb = gas.pres[b]
        rho_b = mb / gas.vol[b]
        cb = gas.cs[b]
        gb = gas.gamma[b]
        if mb > F64(0.0):
            hb = gas.energy[b] / mb + pb / rho_b
    else:
        r = -b - 1
        if parts.active[r] == 0 or parts.burn[r] < F64(1.0):
            links.dm[k] = F64(0.0)
            return
        s = _particle_gas(parts, r, prm)
        pb = s[0]
        rho_b = s[1]
        cb = s[2]
        gb = s[3]
        hb = s[4]
    # pressure stiffness c²/V of each side [Pa per kg/m]; an empty side takes the donor's sound speed
    ca = gas.cs[a]
    va = gas.vol[a]
    vb = F64(0.0)
    if b >= 0:
        vb = gas.vol[b]
    else:
        vb = parts.vol[-b - 1]
    dm = F64(0.0)
    h = F64(0.0)
    if pa > pb:
        dm = dt * crack_mass_flux(rho_a, ca, gas.gamma[a], w, pa - pb, prm.mu, links.dx[k])
        cr = cb
        if cr <= F64(0.0):
            cr = ca
        dm = wp.min(dm, F64(EQUALISE) * (pa - pb) / (ca * ca / va + cr * cr / vb))
        h = ha
        if dm > F64(0.0):
            wp.atomic_add(gas.out, a, dm)
    elif pb > pa:
        dm = dt * crack_mass_flux(rho_b, cb, gb, w, pb - pa, prm.mu, links.dx[k])
        cr = ca
        if cr <= F64(0.0):
            cr = cb
        dm = -wp.min(dm, F64(EQUALISE) * (pb - pa) / (cb * cb / vb + cr * cr / va))
        h = hb
        if dm < F64(0.0):
            if b >= 0:
                wp.atomic_add(gas.out, b, -dm)
            else:
                wp.atomic_add(parts.out, -b - 1, -dm)
    links.dm[k] = dm
    links.h[k] = h


@wp.kernel
def crack_donor_scale(links: CrackLinks, gas: CrackGasState, prm: CrackGasParams):
    """Fraction of its asked outflow a donor cell can give: at most ``cell_fraction`` of its mass in one step. Over
    the paths, for the cell each one draws from (only a donor's fraction is read, by crack_apply_flux): a cell
    that feeds several paths is written by each with the same value (its outflow and mass do not change in this
    kernel), which spares a pass over every interface of the rock."""
    k = wp.tid()
    if k >= links.count[0]:
        return
    dm = links.dm[k]
    q = int(-1)
    if dm > F64(0.0):
        q = links.a[k]
    elif dm < F64(0.0):
        q = links.b[k]
    if q < 0:
        return                                    # no flow, or a particle gives (crack_particle_scale)
    o = gas.out[q]
    s = F64(1.0)
    lim = prm.cell_fraction * gas.mass[q]
    if o > lim:
        s = lim / o
    gas.scale[q] = s


@wp.kernel
def crack_particle_scale(parts: GasParticles, prm: CrackGasParams, floor: wp.float64):
    """Fraction of its asked outflow a particle can give: ``particle_fraction`` of its mass in one step, never
    below ``floor``·(its initial mass)."""
    r = wp.tid()
    o = parts.out[r]
    if o <= F64(0.0):
        return
    m = parts.mass[r]
    lim = wp.max(wp.min(prm.particle_fraction * m, m - floor * parts.mass0[r]), F64(0.0))
    s = F64(1.0)
    if o > lim:
        s = lim / o
    parts.scale[r] = s


@wp.kernel
def crack_apply_flux(links: CrackLinks, gas: CrackGasState, parts: GasParticles):
    """Move the granted mass and its enthalpy from donor to receiver (mass and energy conserved exactly)."""
    k = wp.tid()
    if k >= links.count[0]:
        return
    dm = links.dm[k]
    if dm == F64(0.0):
        return
    a = links.a[k]
    b = links.b[k]
    # d: granted mass from a to b (negative: from b to a), scaled by the donor's grant
    s = F64(1.0)
    if dm > F64(0.0):
        s = gas.scale[a]
    elif b >= 0:
        s = gas.scale[b]
    else:
        s = parts.scale[-b - 1]
    d = dm * s
    de = d * links.h[k]
    wp.atomic_add(gas.mass, a, -d)
    wp.atomic_add(gas.energy, a, -de)
    if b >= 0:
        wp.atomic_add(gas.mass, b, d)
        wp.atomic_add(gas.energy, b, de)
    else:
        r = -b - 1
        wp.atomic_add(parts.mass, r, d)
        wp.atomic_add(parts.ie, r, de)
        parts.touched[r] = 1


@wp.kernel
def crack_refresh_particles(parts: GasParticles, prm: CrackGasParams):
    """A particle whose mass changed: reference volume V0 = m/ρ0, density, JWL pressure and stress −(p + q)I at
    its (unchanged) volume, so that the next P2G and EOS update see a consistent state. The rest: reset scratch."""
    r = wp.tid()
    parts.out[r] = F64(0.0)
    parts.scale[r] = F64(1.0)
    if parts.touched[r] == 0:
        return
    parts.touched[r] = 0
    m = parts.mass[r]
    v0 = m / prm.rho0
    parts.vol0[r] = v0
    parts.rho[r] = m / parts.vol[r]
    V = wp.max(parts.vol[r] / v0, F64(V_FLOOR))
    p = jwl_pressure(V, parts.ie[r] / v0, prm.A, prm.B, prm.R1, prm.R2, prm.omega)
    p = wp.max(p, F64(0.0))
    parts.pres[r] = p
    s = -(p + parts.q[r])
    parts.stress[r] = wp.mat22d(s, F64(0.0), F64(0.0), s)


@wp.kernel
def release_wide_cells(cells: CrackCells, gas: CrackGasState, parts: GasParticles, hsh: GasHash,
                       x: wp.array(dtype=wp.vec2d), v: wp.array(dtype=wp.vec2d), d_particle: wp.float64,
                       radius: wp.float64, dt_prev: wp.float64, released: wp.array(dtype=wp.int32),
                       released_total: wp.array(dtype=wp.int32)):
    """A wet cell open wider than a material point at both ends belongs to the MPM: its gas (mass, internal
    energy and volume) joins the nearest fully burnt particle within ``radius`` of its centre, and the cell is
    marked open (wet = 2) for good: particles, not crack cells, load such a crack (by contact). The last step's
    face forces get their pending half-step of work first, so the energy stays balanced. Counts the cells released
    by this call (released) and by the run (released_total)."""
    q = wp.tid()
    if gas.wet[q] != 1:
        return
    g = gas.gap[q]
    if wp.min(g[0], g[1]) <= d_particle:
        return
    n = cells.nodes[q]
    c = F64(0.25) * (x[n[0]] + x[n[1]] + x[n[2]] + x[n[3]])
    best = nearest_burnt(hsh, parts, c, radius, F64(-1.0))
    if best < 0:
        return
    w_old = F64(0.0)
    for k in range(4):
        w_old += wp.dot(gas.force[4 * q + k], v[n[k]])
        gas.force[4 * q + k] = wp.vec2d(F64(0.0), F64(0.0))
    e = gas.energy[q] - F64(0.5) * dt_prev * w_old
    m = gas.mass[q]
    if m > F64(0.0):
        wp.atomic_add(parts.mass, best, m)
        wp.atomic_add(parts.ie, best, e)
        wp.atomic_add(parts.vol, best, gas.vol[q])
        parts.touched[best] = 1
    else:
        gas.energy[q] = e            # nothing to hand over (an empty cell's work balance, kept in the books)
    if m > F64(0.0):
        gas.mass[q] = F64(0.0)
        gas.energy[q] = F64(0.0)
    gas.pres[q] = F64(0.0)
    gas.wet[q] = 2
    wp.atomic_add(released, 0, 1)
    wp.atomic_add(released_total, 0, 1)


@wp.kernel
def count_paths(count: wp.array(dtype=wp.int32), paths: wp.array(dtype=wp.int32), mouths: wp.array(dtype=wp.int32)):
    """mouths[0] = count[0] − paths[0]: the mouths of this rebuild, once they are listed after its paths (one thread),
    the flag of a captured step's mouth branches."""
    mouths[0] = count[0] - paths[0]


@wp.kernel
def note_paths(count: wp.array(dtype=wp.int32), paths: wp.array(dtype=wp.int32)):
    """paths[0] = count[0]: the cell–cell paths of this rebuild, before its mouths are listed (one thread)."""
    paths[0] = count[0]
