"""Linear isotropic elasticity of the CST blocks, plane strain, hypoelastic Jaumann update.

Stress is stored as (σxx, σyy, σxy) [Pa], tension positive. The velocity gradient
L = ∂v/∂x [1/s] is passed as a 2×2 matrix (rows: velocity component).
"""

from __future__ import annotations

import numpy as np
import warp as wp


def lame(youngs: float, poisson: float) -> tuple[float, float]:
    """Lamé constants (λ, G) [Pa] from E [Pa] and ν."""
    return youngs * poisson / ((1 + poisson) * (1 - 2 * poisson)), youngs / (2 * (1 + poisson))


@wp.func
def jaumann_stress_update(sig: wp.vec3d, grad_v: wp.mat22d, dt: wp.float64, lam: wp.float64, mu: wp.float64):
    """σ ← σ + (Wσ − σW) + D:Δε, with Δε = sym(L)Δt and W = skew(L)Δt (plane strain)."""
    half = wp.float64(0.5)
    two = wp.float64(2.0)
    exx = grad_v[0, 0] * dt
    eyy = grad_v[1, 1] * dt
    exy = half * (grad_v[0, 1] + grad_v[1, 0]) * dt
    w = half * (grad_v[0, 1] - grad_v[1, 0]) * dt
    sxx = sig[0]
    syy = sig[1]
    sxy = sig[2]
    tr = lam * (exx + eyy)
    return wp.vec3d(
        sxx + two * w * sxy + tr + two * mu * exx,
        syy - two * w * sxy + tr + two * mu * eyy,
        sxy + w * (syy - sxx) + two * mu * exy,
    )


@wp.func
def strain_energy_density(sig: wp.vec3d, lam: wp.float64, mu: wp.float64):
    """½ σ:C⁻¹:σ [J/m³] for plane strain (σzz = ν(σxx+σyy) implied)."""
    half = wp.float64(0.5)
    # plane-strain compliance: exx = (sxx - nu'(syy))/E'... written with Lamé constants
    s = lam + mu
    exx = ((lam + wp.float64(2.0) * mu) * sig[0] - lam * sig[1]) / (wp.float64(4.0) * mu * s)
    eyy = ((lam + wp.float64(2.0) * mu) * sig[1] - lam * sig[0]) / (wp.float64(4.0) * mu * s)
    exy = sig[2] / (wp.float64(2.0) * mu)
    return half * (sig[0] * exx + sig[1] * eyy) + sig[2] * exy


def np_jaumann_stress_update(sig, grad_v, dt, lam, mu):
    """NumPy twin of :func:`jaumann_stress_update`; sig (3,), grad_v (2,2)."""
    exx, eyy = grad_v[0, 0] * dt, grad_v[1, 1] * dt
    exy = 0.5 * (grad_v[0, 1] + grad_v[1, 0]) * dt
    w = 0.5 * (grad_v[0, 1] - grad_v[1, 0]) * dt
    sxx, syy, sxy = sig
    tr = lam * (exx + eyy)
    return np.array([sxx + 2 * w * sxy + tr + 2 * mu * exx,
                     syy - 2 * w * sxy + tr + 2 * mu * eyy,
                     sxy + w * (syy - sxx) + 2 * mu * exy])


def np_strain_energy_density(sig, lam, mu):
    """NumPy twin of :func:`strain_energy_density`, from the plane-strain compliance matrix."""
    c = np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])
    s = np.array([sig[0], sig[1], sig[2]])
    eps = np.linalg.solve(c, s)            # (εxx, εyy, γxy)
    return 0.5 * float(s @ eps)
