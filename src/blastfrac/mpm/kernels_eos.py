"""Detonation-products state update (METHOD §2.3–2.6): the burn fraction (the programmed-burn law of
:func:`blastfrac.mpm.burn.burn_fraction`), q, JWL energy/pressure, c, stress; one kernel, one pass over the
points (the burn was a kernel of its own, whose launch and pass over the points cost more than its law)."""

from __future__ import annotations

import warp as wp

from blastfrac.materials.artificial_viscosity import bulk_viscosity  # noqa: F401 (shared with the rock)
from blastfrac.materials.jwl import jwl_energy_update, jwl_sound_speed_sq, products_sound_speed
from blastfrac.mpm.bodies import MAT_GAS
from blastfrac.mpm.burn import burn_fraction

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated

F64 = wp.float64


@wp.kernel
def update_jwl_state(
    active: wp.array(dtype=wp.int32),
    kind: wp.array(dtype=wp.int32),
    vol0: wp.array(dtype=wp.float64),
    vol: wp.array(dtype=wp.float64),
    vol_prev: wp.array(dtype=wp.float64),
    rho: wp.array(dtype=wp.float64),
    grad_v: wp.array(dtype=wp.mat22d),
    light_time: wp.array(dtype=wp.float64),
    clock: wp.array(dtype=wp.float64),
    dt: wp.float64,
    p_cj: wp.float64,
    width: wp.float64,
    mode: int,
    rho0: wp.float64,
    D: wp.float64,
    A: wp.float64,
    B: wp.float64,
    R1: wp.float64,
    R2: wp.float64,
    w: wp.float64,
    q1: wp.float64,
    q2: wp.float64,
    v_max: wp.float64,
    burn: wp.array(dtype=wp.float64),
    ie: wp.array(dtype=wp.float64),
    pres: wp.array(dtype=wp.float64),
    q: wp.array(dtype=wp.float64),
    cs: wp.array(dtype=wp.float64),
    stress: wp.array(dtype=wp.mat22d),
):
    """Advance the burn fraction at the end-of-step time t = clock[0] + dt [s] (clock[0]: the time at the start of the
    step, on the device so that a captured step reads it when it runs) (never decreasing), then q, p [Pa], ie [J/m],
    c [m/s] and sigma = -(p + q) I of each products particle (kind MAT_GAS; elastic points keep burn = 0 and are
    left alone)."""
    p = wp.tid()
    if active[p] == 0 or kind[p] != MAT_GAS:
        return
    v0 = vol0[p]
    V = vol[p] / v0
    # q's sound speed is the products' own at the start of the step, of the burnt share F (the unburnt share
    # carries no pressure): not cs[p], the time step's signal speed, which holds q's own augmentation and the
    # burn front's floor D(1 - F) and so made the linear term ~(1 + sqrt 2)x stronger than its Q2 said.
    c_mix = products_sound_speed(burn[p], wp.max(vol_prev[p] / v0, F64(0.2)), ie[p] / v0, pres[p], rho0, A, B, R1, R2, w)
    t = clock[0] + dt
    burn[p] = burn_fraction(burn[p], t, light_time[p], V, wp.sqrt(v0), D, rho0, p_cj, width, mode)
    L = grad_v[p]
    trD = L[0, 0] + L[1, 1]
    l = wp.sqrt(vol[p])
    qn = bulk_viscosity(trD, rho[p], l, c_mix, q1, q2)
    F = burn[p]
    if V > v_max:
        F = F64(0.0)
    r = jwl_energy_update(V, vol[p], vol_prev[p], v0, ie[p], pres[p], qn, F, A, B, R1, R2, w)
    pn = r[0]
    ie[p] = r[1]
    pres[p] = pn
    q[p] = qn
    Vc = wp.max(V, F64(0.2))
    c2 = jwl_sound_speed_sq(Vc, r[1] / v0, pn, rho0, A, B, R1, R2, w)
    c2 = wp.max(c2, D * D * (F64(1.0) - burn[p]) * (F64(1.0) - burn[p]))
    c = wp.sqrt(c2)
    if trD < F64(0.0):
        s = q2 * c - q1 * l * trD
        c = s + wp.sqrt(s * s + c * c)
    cs[p] = c
    stress[p] = wp.mat22d(-(pn + qn), F64(0.0), F64(0.0), -(pn + qn))
