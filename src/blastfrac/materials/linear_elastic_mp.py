"""Linear-elastic material-point model (plane strain): the MPM core benchmarks (VALIDATION §5) and the elastic
bodies of a scenario (``[[explosive.bodies]]``, an impactor; :mod:`blastfrac.mpm.bodies`).

The kernel that applies the law to the points is :func:`blastfrac.mpm.kernels_solid.update_elastic_state`: each
point carries its own Lamé constants, so bodies of different materials and the detonation products share one grid
and one launch per stage.

Hypoelastic rate form with the Jaumann rate, integrated explicitly:

    sigma += dt (lambda tr(D) I + 2 mu D) + dt (W sigma - sigma W),

with D = sym(L), W = skew(L), L the particle velocity gradient [1/s]; stresses in Pa
(tension positive).  Plane strain: the in-plane response uses lambda, mu of the 3D
material; sigma_zz does not enter the in-plane forces.

Stored energy.  A hypoelastic law has no strain-energy function; the energy the material
holds is the work done on it, accumulated per particle with the trapezoidal rule

    W_p += dt/2 (V_p^n sigma^n + V_p^{n+1} sigma^{n+1}) : D      [J per unit thickness],

which is exactly the energy the grid's internal forces exchange with the motion (for small
strains it equals 1/2 sigma : C^-1 : sigma V, to which it reduces exactly at constant V).
The closed form w = 1/2 sigma : C^-1 : sigma (plane-strain compliance) times the current
volume is kept as a diagnostic: at finite strain it differs from the work by O(strain)
(the Cauchy stress acts on the current volume, and the Jaumann rate rotates sigma), e.g.
by 8 % of the kinetic energy at peak compression in the two-disk benchmark, where the
contact strains reach ~10 %.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

F64 = wp.float64


@dataclass(frozen=True)
class LinearElasticMP:
    """Young's modulus E [Pa], Poisson's ratio nu [-], density rho0 [kg/m^3]."""

    E: float
    nu: float
    rho0: float

    @property
    def lam(self) -> float:
        return self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu))

    @property
    def mu(self) -> float:
        return self.E / (2 * (1 + self.nu))

    @property
    def p_wave_speed(self) -> float:
        """Plane-strain P-wave speed sqrt((lambda + 2 mu)/rho0) [m/s]."""
        return float(np.sqrt((self.lam + 2 * self.mu) / self.rho0))


@wp.func
def elastic_stress_update(sig: wp.mat22d, L: wp.mat22d, dt: wp.float64, lam: wp.float64, mu: wp.float64):
    """Jaumann-rate hypoelastic update of the in-plane Cauchy stress [Pa]."""
    Dm = F64(0.5) * (L + wp.transpose(L))
    W = F64(0.5) * (L - wp.transpose(L))
    trD = Dm[0, 0] + Dm[1, 1]
    I = wp.identity(n=2, dtype=wp.float64)
    return sig + dt * (lam * trD * I + F64(2.0) * mu * Dm) + dt * (W * sig - sig * W)


def elastic_stress_update_np(sig, L, dt, lam, mu):
    """NumPy twin of :func:`elastic_stress_update`; sig, L shape [..., 2, 2]."""
    Lt = np.swapaxes(L, -1, -2)
    Dm, W = 0.5 * (L + Lt), 0.5 * (L - Lt)
    trD = Dm[..., 0, 0] + Dm[..., 1, 1]
    return sig + dt * (lam * trD[..., None, None] * np.eye(2) + 2 * mu * Dm) + dt * (W @ sig - sig @ W)


def strain_energy_density_np(sig, E: float, nu: float):
    """Plane-strain strain energy per unit volume [J/m^3] from in-plane stresses sig [..., 2, 2]."""
    sxx, syy, sxy = sig[..., 0, 0], sig[..., 1, 1], sig[..., 0, 1]
    exx = ((1 - nu**2) * sxx - nu * (1 + nu) * syy) / E
    eyy = ((1 - nu**2) * syy - nu * (1 + nu) * sxx) / E
    gxy = 2 * (1 + nu) * sxy / E
    return 0.5 * (sxx * exx + syy * eyy + sxy * gxy)


def stress_work_increment_np(sig_old, sig_new, vol_old, vol_new, L, dt):
    """NumPy twin of the work increment dt/2 (V^n sigma^n + V^{n+1} sigma^{n+1}) : sym(L) [J/m]."""
    Dm = 0.5 * (L + np.swapaxes(L, -1, -2))
    vs = 0.5 * (np.asarray(vol_old)[..., None, None] * sig_old + np.asarray(vol_new)[..., None, None] * sig_new)
    return dt * (vs * Dm).sum(axis=(-1, -2))
