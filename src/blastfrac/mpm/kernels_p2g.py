"""Particle-to-grid transfers (METHOD §2.2 steps 1 and 5): one kernel per transfer.

Scatter with ``wp.atomic_add`` inside a single launch (safe on CPU and CUDA).
Arguments: particle arrays, grid geometry scalars, then grid outputs (zeroed by the launcher).
The momentum carries each particle's affine velocity C_p = B_p D_p^-1 (APIC, :mod:`blastfrac.mpm.apic`) when
``affine`` is 1; with the FLIP/PIC transfer (``affine`` 0) B_p stays 0 and the term is skipped.
"""

from __future__ import annotations

import warp as wp

from blastfrac.mpm.apic import affine_from_moments, affine_inertia
from blastfrac.mpm.bodies import MAT_GAS
from blastfrac.mpm.shape import GridGeometry, stencil_1d, wrap_index

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated

F64 = wp.float64


@wp.func
def particle_stencil(x: wp.vec2d, x0: wp.float64, y0: wp.float64, inv_h: wp.float64, kind: int, l: wp.float64):
    """Bases (bx, by) and 1D weights/derivatives (per unit of grid coordinate) of a particle at x [m]."""
    bx, wx, dwx = stencil_1d((x[0] - x0) * inv_h, kind, l)
    by, wy, dwy = stencil_1d((x[1] - y0) * inv_h, kind, l)
    return bx, by, wx, dwx, wy, dwy


@wp.func
def particle_affine(affine: int, B: wp.mat22d, xp: wp.vec2d, geo: GridGeometry, bx: int, by: int, wx: wp.vec3d,
                    wy: wp.vec3d):
    """(C_p = B_p D_p⁻¹ [1/s], 0 unless ``affine``; the particle's fractional grid coordinates fx, fy; h [m]) for
    the momentum's affine term N m_p C_p (x_I − x_p), x_I − x_p = ((b + k) − f)·h."""
    h = F64(1.0) / geo.inv_h
    fx = (xp[0] - geo.x0) * geo.inv_h
    fy = (xp[1] - geo.y0) * geo.inv_h
    Cp = wp.mat22d()
    if affine != 0:
        Cp = affine_from_moments(B, affine_inertia(wx, wy, F64(bx) - fx, F64(by) - fy, h))
    return Cp, fx, fy, h


@wp.kernel
def p2g(
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    b_aff: wp.array(dtype=wp.mat22d),
    mass: wp.array(dtype=wp.float64),
    vol: wp.array(dtype=wp.float64),
    stress: wp.array(dtype=wp.mat22d),
    f_ext: wp.array(dtype=wp.vec2d),
    f_ext_moment: wp.array(dtype=wp.mat22d),
    active: wp.array(dtype=wp.int32),
    geo: GridGeometry,
    affine: int,
    g_mass: wp.array(dtype=wp.float64),
    g_mom: wp.array(dtype=wp.vec2d),
    g_force: wp.array(dtype=wp.vec2d),
):
    """m_I += N m_p; p_I += N m_p (v_p + C_p (x_I − x_p)); f_I += -V_p sigma_p grad N + N f_ext_p + M_p grad N
    (per unit thickness; C_p = B_p D_p^-1 [1/s] the APIC affine velocity, 0 with FLIP/PIC).

    M_p = Σ_k f_k ⊗ (x_k − x_p) [N] is the first moment of the external forces f_k that act at points x_k other
    than the particle centre (contact tractions on the particle's surface): N_I(x_k) ≈ N_I(x_p) + ∇N_I·(x_k − x_p).
    """
    p = wp.tid()
    if active[p] == 0:
        return
    bx, by, wx, dwx, wy, dwy = particle_stencil(x[p], geo.x0, geo.y0, geo.inv_h, geo.kind, geo.l)
    m = mass[p]
    mv = m * v[p]
    vs = vol[p] * stress[p]
    fe = f_ext[p]
    ms = f_ext_moment[p] - vs
    Cp, fx, fy, h = particle_affine(affine, b_aff[p], x[p], geo, bx, by, wx, wy)
    for i in range(3):
        ii = wrap_index(bx + i, geo.nx, geo.px)
        for j in range(3):
            n = wrap_index(by + j, geo.ny, geo.py) * geo.nx + ii
            N = wx[i] * wy[j]
            grad = wp.vec2d(dwx[i] * wy[j] * geo.inv_h, wx[i] * dwy[j] * geo.inv_h)
            wp.atomic_add(g_mass, n, N * m)
            if affine != 0:
                dx = wp.vec2d((F64(bx + i) - fx) * h, (F64(by + j) - fy) * h)
                wp.atomic_add(g_mom, n, N * mv + (N * m) * (Cp * dx))
            else:
                wp.atomic_add(g_mom, n, N * mv)
            wp.atomic_add(g_force, n, N * fe + ms * grad)


@wp.kernel
def p2g_momentum(
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    b_aff: wp.array(dtype=wp.mat22d),
    mass: wp.array(dtype=wp.float64),
    active: wp.array(dtype=wp.int32),
    geo: GridGeometry,
    affine: int,
    g_mom: wp.array(dtype=wp.vec2d),
):
    """MUSL remap: p_I = sum N m_p (v_p + C_p (x_I − x_p)), C_p = B_p D_p^-1, with the updated particle velocities
    and affine moments [N s/m]."""
    p = wp.tid()
    if active[p] == 0:
        return
    bx, by, wx, dwx, wy, dwy = particle_stencil(x[p], geo.x0, geo.y0, geo.inv_h, geo.kind, geo.l)
    m = mass[p]
    mv = m * v[p]
    Cp, fx, fy, h = particle_affine(affine, b_aff[p], x[p], geo, bx, by, wx, wy)
    for i in range(3):
        ii = wrap_index(bx + i, geo.nx, geo.px)
        for j in range(3):
            n = wrap_index(by + j, geo.ny, geo.py) * geo.nx + ii
            N = wx[i] * wy[j]
            if affine != 0:
                dx = wp.vec2d((F64(bx + i) - fx) * h, (F64(by + j) - fy) * h)
                wp.atomic_add(g_mom, n, N * mv + (N * m) * (Cp * dx))
            else:
                wp.atomic_add(g_mom, n, N * mv)


@wp.kernel
def p2g_gas(
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    mass: wp.array(dtype=wp.float64),
    active: wp.array(dtype=wp.int32),
    mat_kind: wp.array(dtype=wp.int32),
    geo: GridGeometry,
    g_mass: wp.array(dtype=wp.float64),
    g_mom: wp.array(dtype=wp.vec2d),
):
    """The gas's own nodal mass and momentum, m_I = sum N m_p and p_I = sum N m_p v_p over the gas points alone
    [kg/m, N s/m]: the PIC share of the gas's blend aims at this velocity where elastic bodies share its nodes,
    so that the blend exchanges no momentum between gas and bodies (:func:`~blastfrac.mpm.kernels_g2p.g2p_velocity`)."""
    p = wp.tid()
    if active[p] == 0 or mat_kind[p] != MAT_GAS:
        return
    bx, by, wx, dwx, wy, dwy = particle_stencil(x[p], geo.x0, geo.y0, geo.inv_h, geo.kind, geo.l)
    m = mass[p]
    mv = m * v[p]
    for i in range(3):
        ii = wrap_index(bx + i, geo.nx, geo.px)
        for j in range(3):
            n = wrap_index(by + j, geo.ny, geo.py) * geo.nx + ii
            N = wx[i] * wy[j]
            wp.atomic_add(g_mass, n, N * m)
            wp.atomic_add(g_mom, n, N * mv)
