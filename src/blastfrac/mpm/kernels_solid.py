"""Elastic material-point state update (the law: :mod:`blastfrac.materials.linear_elastic_mp`)."""

from __future__ import annotations

import warp as wp

from blastfrac.materials.linear_elastic_mp import elastic_stress_update
from blastfrac.mpm.bodies import MAT_ELASTIC

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated

F64 = wp.float64


@wp.kernel
def update_elastic_state(
    active: wp.array(dtype=wp.int32),
    kind: wp.array(dtype=wp.int32),
    grad_v: wp.array(dtype=wp.mat22d),
    rho: wp.array(dtype=wp.float64),
    vol_prev: wp.array(dtype=wp.float64),
    vol: wp.array(dtype=wp.float64),
    lam: wp.array(dtype=wp.float64),
    mu: wp.array(dtype=wp.float64),
    dt: wp.float64,
    stress: wp.array(dtype=wp.mat22d),
    pres: wp.array(dtype=wp.float64),
    cs: wp.array(dtype=wp.float64),
    work: wp.array(dtype=wp.float64),
):
    """Advance the stress sigma [Pa] of each elastic point (kind MAT_ELASTIC; gas points are left alone) with its
    own Lamé constants lam, mu [Pa] (shape [n]) over dt [s]; p = -tr(sigma)/2 [Pa]; c = sqrt((lambda + 2 mu)/rho)
    [m/s]; stored work W += dt/2 (V^n sigma^n + V^{n+1} sigma^{n+1}) : D [J/m] (vol_prev, vol [m^2], rho [kg/m^3])."""
    p = wp.tid()
    if active[p] == 0 or kind[p] != MAT_ELASTIC:
        return
    L = grad_v[p]
    s0 = stress[p]
    lp = lam[p]
    mp = mu[p]
    s = elastic_stress_update(s0, L, dt, lp, mp)
    Dm = F64(0.5) * (L + wp.transpose(L))
    vs = F64(0.5) * (vol_prev[p] * s0 + vol[p] * s)
    work[p] = work[p] + dt * wp.ddot(vs, Dm)
    stress[p] = s
    pres[p] = -F64(0.5) * (s[0, 0] + s[1, 1])
    cs[p] = wp.sqrt((lp + F64(2.0) * mp) / rho[p])
