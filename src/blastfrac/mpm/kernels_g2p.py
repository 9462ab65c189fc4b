"""Grid-to-particle transfers (METHOD §2.2 steps 4 and 6): gathers, one kernel per operation."""

from __future__ import annotations

import numpy as np
import warp as wp

from blastfrac.mpm.bodies import MAT_GAS
from blastfrac.mpm.kernels_p2g import particle_stencil
from blastfrac.mpm.shape import GridGeometry, wrap_index

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated

F64 = wp.float64


@wp.func
def blend_heat(m: wp.float64, v_flip: wp.vec2d, v_new: wp.vec2d):
    """½ m (|v_flip|² − |v_new|²) [J/m]: the kinetic energy a point of mass m [kg/m] loses when its FLIP velocity
    v_flip is blended towards the grid's (PIC) velocity into v_new [m/s]."""
    return F64(0.5) * m * (wp.dot(v_flip, v_flip) - wp.dot(v_new, v_new))


def blend_heat_np(m, v_flip, v_new):
    """NumPy twin of :func:`blend_heat` (arrays [n], [n, 2], [n, 2])."""
    v_flip, v_new = np.asarray(v_flip, float), np.asarray(v_new, float)
    return 0.5 * np.asarray(m, float) * ((v_flip * v_flip).sum(-1) - (v_new * v_new).sum(-1))


@wp.func
def gas_velocity(bx: int, by: int, wx: wp.vec3d, wy: wp.vec3d, geo: GridGeometry, g_vel_gas: wp.array(dtype=wp.vec2d),
                 g_dvel: wp.array(dtype=wp.vec2d)):
    """sum N (v_I^gas + dv_I) [m/s] over a point's stencil, v_I^gas = p_I^gas / m_I^gas before the update: the gas's
    own updated grid velocity (equal to v_I where no body shares the node)."""
    out = wp.vec2d()
    for i in range(3):
        ii = wrap_index(bx + i, geo.nx, geo.px)
        for j in range(3):
            n = wrap_index(by + j, geo.ny, geo.py) * geo.nx + ii
            out += (wx[i] * wy[j]) * (g_vel_gas[n] + g_dvel[n])
    return out


@wp.kernel
def g2p_velocity(
    x: wp.array(dtype=wp.vec2d),
    active: wp.array(dtype=wp.int32),
    g_vel: wp.array(dtype=wp.vec2d),
    g_dvel: wp.array(dtype=wp.vec2d),
    geo: GridGeometry,
    flip: wp.float64,
    flip_bodies: wp.float64,
    heating: int,
    mass: wp.array(dtype=wp.float64),
    mat_kind: wp.array(dtype=wp.int32),
    own: int,
    g_vel_gas: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    v_pic: wp.array(dtype=wp.vec2d),
    ie: wp.array(dtype=wp.float64),
):
    """v_p = f (v_p + sum N dv_I) + (1 - f) sum N v_I, f = ``flip`` for gas points and ``flip_bodies`` for the
    points of elastic bodies; v_pic = sum N v_I moves the particle [m/s].

    With ``own`` (gas and elastic bodies share the grid, flip < 1) a gas point's PIC share aims at the gas's own
    velocity, sum N (v_I^gas + dv_I) (:func:`gas_velocity`, :func:`~blastfrac.mpm.kernels_p2g.p2g_gas`): over the gas,
    m_p times it is the gas's FLIP momentum, so the blend moves no momentum between the gas and the bodies.

    With ``heating`` (``explosive.blend_heating``) a gas point's internal energy ie [J/m] takes the kinetic energy
    that the PIC share removes from it, ½ m (|v_FLIP|² − |v_p|²) with v_FLIP = v_p + sum N dv_I: the blend then
    exchanges energy as pure FLIP does (:func:`blend_heat`)."""
    p = wp.tid()
    if active[p] == 0:
        return
    bx, by, wx, dwx, wy, dwy = particle_stencil(x[p], geo.x0, geo.y0, geo.inv_h, geo.kind, geo.l)
    vp = wp.vec2d()
    dv = wp.vec2d()
    for i in range(3):
        ii = wrap_index(bx + i, geo.nx, geo.px)
        for j in range(3):
            n = wrap_index(by + j, geo.ny, geo.py) * geo.nx + ii
            N = wx[i] * wy[j]
            vp += N * g_vel[n]
            dv += N * g_dvel[n]
    v_flip = v[p] + dv
    f = flip_bodies
    target = vp
    if mat_kind[p] == MAT_GAS:
        f = flip
        if own != 0 and f < F64(1.0):
            target = gas_velocity(bx, by, wx, wy, geo, g_vel_gas, g_dvel)
    v_new = f * v_flip + (F64(1.0) - f) * target
    if heating != 0 and mat_kind[p] == MAT_GAS:      # an elastic body's energy is not heat: not booked
        ie[p] = ie[p] + blend_heat(mass[p], v_flip, v_new)
    v[p] = v_new
    v_pic[p] = vp


@wp.kernel
def g2p_velocity_apic(
    x: wp.array(dtype=wp.vec2d),
    active: wp.array(dtype=wp.int32),
    g_vel: wp.array(dtype=wp.vec2d),
    geo: GridGeometry,
    vol: wp.array(dtype=wp.float64),
    vol0: wp.array(dtype=wp.float64),
    v_max: wp.float64,
    v: wp.array(dtype=wp.vec2d),
    v_pic: wp.array(dtype=wp.vec2d),
    b_aff: wp.array(dtype=wp.mat22d),
):
    """APIC: v_p = v_pic = sum N v_I [m/s]; affine moment B_p = sum N v_I (x) (x_I - x_p) [m^2/s] (the next P2G
    uses C_p = B_p D_p^-1); see :mod:`blastfrac.mpm.apic`.

    Guard: B_p = 0 once V_p > v_max V_p0 (vol, vol0 [m^2]; the products' pressure is frozen there, METHOD §2.7).
    A point alone on its nodes gets its own affine field back from them, so its C_p, hence its volume rate
    tr C_p, never decays and its volume grows exponentially (to overflow in a slab expanding into vacuum).
    """
    p = wp.tid()
    if active[p] == 0:
        return
    bx, by, wx, dwx, wy, dwy = particle_stencil(x[p], geo.x0, geo.y0, geo.inv_h, geo.kind, geo.l)
    h = F64(1.0) / geo.inv_h
    fx = (x[p][0] - geo.x0) * geo.inv_h
    fy = (x[p][1] - geo.y0) * geo.inv_h
    vp = wp.vec2d()
    Bm = wp.mat22d()
    for i in range(3):
        ii = wrap_index(bx + i, geo.nx, geo.px)
        for j in range(3):
            n = wrap_index(by + j, geo.ny, geo.py) * geo.nx + ii
            N = wx[i] * wy[j]
            dx = wp.vec2d((F64(bx + i) - fx) * h, (F64(by + j) - fy) * h)
            vI = g_vel[n]
            vp += N * vI
            Bm += N * wp.outer(vI, dx)
    v[p] = vp
    v_pic[p] = vp
    if vol[p] > v_max * vol0[p]:
        Bm = wp.mat22d()
    b_aff[p] = Bm


@wp.func
def accumulate_extent(xp: wp.vec2d, x0: wp.float64, y0: wp.float64, inv_h: wp.float64, extent: wp.array(dtype=wp.int32)):
    """Widen ``extent`` (min i, min j, max i, max j) by the stencil base cell of a particle at xp [m]."""
    bx = int(wp.floor((xp[0] - x0) * inv_h - F64(0.5)))
    by = int(wp.floor((xp[1] - y0) * inv_h - F64(0.5)))
    wp.atomic_min(extent, 0, bx)
    wp.atomic_min(extent, 1, by)
    wp.atomic_max(extent, 2, bx)
    wp.atomic_max(extent, 3, by)


@wp.kernel
def update_particle_kinematics(
    active: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=wp.float64),
    g_vel: wp.array(dtype=wp.vec2d),
    v_pic: wp.array(dtype=wp.vec2d),
    geo: GridGeometry,
    dt: wp.float64,
    x: wp.array(dtype=wp.vec2d),
    vol: wp.array(dtype=wp.float64),
    vol_prev: wp.array(dtype=wp.float64),
    rho: wp.array(dtype=wp.float64),
    grad_v: wp.array(dtype=wp.mat22d),
    deactivated: wp.array(dtype=wp.int32),
    extent: wp.array(dtype=wp.int32),
):
    """L_p = sum v_I (x) grad N_I (remapped v_I); V_p *= det(I + dt L); rho = m/V; x_p += dt v_pic.

    A particle whose stencil leaves a non-periodic grid, or whose position or volume is no longer finite, is
    deactivated (active = 0) and counted.  The stencil base cell at the new position widens ``extent`` (min i,
    min j, max i, max j), from which the grid's active box is renewed (:mod:`blastfrac.mpm.grid`).
    """
    p = wp.tid()
    if active[p] == 0:
        return
    bx, by, wx, dwx, wy, dwy = particle_stencil(x[p], geo.x0, geo.y0, geo.inv_h, geo.kind, geo.l)
    L = wp.mat22d()
    for i in range(3):
        ii = wrap_index(bx + i, geo.nx, geo.px)
        for j in range(3):
            n = wrap_index(by + j, geo.ny, geo.py) * geo.nx + ii
            grad = wp.vec2d(dwx[i] * wy[j] * geo.inv_h, wx[i] * dwy[j] * geo.inv_h)
            L += wp.outer(g_vel[n], grad)
    grad_v[p] = L
    J = wp.determinant(wp.identity(n=2, dtype=wp.float64) + dt * L)
    vol_prev[p] = vol[p]
    vol[p] = vol[p] * J
    rho[p] = mass[p] / vol[p]
    xn = x[p] + dt * v_pic[p]
    fx = (xn[0] - geo.x0) * geo.inv_h
    fy = (xn[1] - geo.y0) * geo.inv_h
    # Whether the particle is still on the grid, tested in floating point: a blown-up particle (a NaN or huge
    # coordinate) converts to INT_MIN on a CPU but saturates on a GPU (NaN to 0, +huge to INT_MAX, whose base + 2
    # wraps negative), where it would stay active and scatter out of the grid. A NaN fails every comparison, so
    # each test is true only for a valid particle. First a bound on the coordinates before a periodic axis wraps
    # them (the wrap of a huge one is anything, 0 included); no grid has 1e9 cells along an axis.
    out = 0
    if not (wp.abs(fx) < F64(1.0e9) and wp.abs(fy) < F64(1.0e9)):
        out = 1
    if geo.px != 0:
        fx = fx - wp.floor(fx / wp.float64(geo.nx)) * wp.float64(geo.nx)
        xn[0] = geo.x0 + fx / geo.inv_h
    if geo.py != 0:
        fy = fy - wp.floor(fy / wp.float64(geo.ny)) * wp.float64(geo.ny)
        xn[1] = geo.y0 + fy / geo.inv_h
    x[p] = xn
    # then, on a non-periodic axis, the stencil's base cell floor(f - 1/2) within [0, n - 3]
    zx = fx - F64(0.5)
    zy = fy - F64(0.5)
    if geo.px == 0 and not (zx >= F64(0.0) and zx < wp.float64(geo.nx - 2)):
        out = 1
    if geo.py == 0 and not (zy >= F64(0.0) and zy < wp.float64(geo.ny - 2)):
        out = 1
    if out != 0 or not (J > F64(0.0)):
        active[p] = 0
        wp.atomic_add(deactivated, 0, 1)
        return
    accumulate_extent(xn, geo.x0, geo.y0, geo.inv_h, extent)


@wp.kernel
def particle_extent(
    active: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec2d),
    x0: wp.float64,
    y0: wp.float64,
    inv_h: wp.float64,
    extent: wp.array(dtype=wp.int32),
):
    """Widen ``extent`` by every active particle's stencil base cell (the active box at construction)."""
    p = wp.tid()
    if active[p] != 0:
        accumulate_extent(x[p], x0, y0, inv_h, extent)
