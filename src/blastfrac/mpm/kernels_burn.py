"""Programmed-burn kernel (METHOD §2.4); the law is :func:`blastfrac.mpm.burn.burn_fraction`."""

from __future__ import annotations

import warp as wp

from blastfrac.mpm.bodies import MAT_GAS
from blastfrac.mpm.burn import burn_fraction


@wp.kernel
def update_burn(
    active: wp.array(dtype=wp.int32),
    kind: wp.array(dtype=wp.int32),
    light_time: wp.array(dtype=wp.float64),
    vol: wp.array(dtype=wp.float64),
    vol0: wp.array(dtype=wp.float64),
    t: wp.float64,
    D: wp.float64,
    rho0: wp.float64,
    p_cj: wp.float64,
    width: wp.float64,
    mode: int,
    burn: wp.array(dtype=wp.float64),
):
    """burn_p = F(t, t_l, V) at the end-of-step time t [s]; never decreases. Only explosive points (kind
    MAT_GAS) burn; elastic bodies keep burn = 0."""
    p = wp.tid()
    if active[p] == 0 or kind[p] != MAT_GAS:
        return
    v0 = vol0[p]
    burn[p] = burn_fraction(burn[p], t, light_time[p], vol[p] / v0, wp.sqrt(v0), D, rho0, p_cj, width, mode)
