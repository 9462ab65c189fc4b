"""Flow of detonation gas along a crack narrower than a material point (docs/explosive.md, "Gas in cracks").

A crack segment of aperture w [m] (per unit thickness) between two gas volumes at pressures p_d > p_r (the
donor d upstream) passes the mass flux

    ṁ = ρ_d · w · u,    u = min(u_visc, u_choke)                          [kg/(m·s)]
    u_visc  = w² (p_d − p_r) / (12 μ Δx)                                  (cubic law, plane Poiseuille flow)
    u_choke = Φ(γ_d) · c_d,  Φ(γ) = (2/(γ+1))^((γ+1)/(2(γ−1)))             (sonic throat from a reservoir)

(ρ_d·Φ·c_d is the choked mass flux ρ*u* of an isentropic nozzle fed from rest: Φ(1.4) = 0.5787.)

with μ the gas viscosity [Pa·s], Δx [m] the length over which the pressure drops, c_d [m/s] the donor's sound
speed and γ_d = ρ_d c_d²/p_d its isentropic exponent. The viscous law holds while the gas creeps through a
narrow or slightly pressurised crack (it is the lubrication limit the cubic-law test checks); a wide crack
under a blast pressure drop would pass the gas faster than sound, and the flux is then the choked one of an
isentropic nozzle fed by the donor's state (Munjiza's duct entrance, Munjiza 2004 ch. 8). Friction along a
choked crack (Fanno flow) is not modelled: u_choke is an upper bound that a long, rough crack does not reach.

Every law exists twice: a ``@wp.func`` for the kernels and a NumPy twin (``*_np``) for the tests.
"""

from __future__ import annotations

import numpy as np
import warp as wp

F64 = wp.float64

#: the isentropic exponent is clamped to [GAMMA_MIN, GAMMA_MAX] in the choke factor (a cold, nearly empty
#: crack cell can report γ → 1 or a huge ratio ρc²/p)
GAMMA_MIN = 1.05
GAMMA_MAX = 10.0


@wp.func
def choke_factor(gamma: wp.float64):
    """Φ(γ) = ρ*u*/(ρ₀c₀): choked mass flux of an isentropic nozzle fed from rest over ρ₀c₀ of the reservoir [-]."""
    g = wp.clamp(gamma, F64(GAMMA_MIN), F64(GAMMA_MAX))
    return wp.pow(F64(2.0) / (g + F64(1.0)), (g + F64(1.0)) / (F64(2.0) * (g - F64(1.0))))


@wp.func
def crack_flow_speed(w: wp.float64, dp: wp.float64, mu: wp.float64, dx: wp.float64, c_choke: wp.float64):
    """min(w²·dp/(12 μ Δx), c_choke) [m/s] for an aperture w [m], pressure drop dp ≥ 0 [Pa] over Δx [m]."""
    u = w * w * dp / (F64(12.0) * mu * dx)
    return wp.min(u, c_choke)


@wp.func
def crack_mass_flux(rho_d: wp.float64, c_d: wp.float64, gamma_d: wp.float64, w: wp.float64, dp: wp.float64,
                    mu: wp.float64, dx: wp.float64):
    """ṁ = ρ_d·w·min(u_visc, Φ(γ_d)·c_d) [kg/(m·s)] per unit thickness from the donor d (dp = p_d − p_r ≥ 0)."""
    if w <= F64(0.0) or dp <= F64(0.0) or rho_d <= F64(0.0):
        return F64(0.0)
    return rho_d * w * crack_flow_speed(w, dp, mu, dx, choke_factor(gamma_d) * c_d)


# ----------------------------------------------------------------------------- numpy twins
def choke_factor_np(gamma):
    g = np.clip(np.asarray(gamma, dtype=np.float64), GAMMA_MIN, GAMMA_MAX)
    return (2.0 / (g + 1.0)) ** ((g + 1.0) / (2.0 * (g - 1.0)))


def crack_flow_speed_np(w, dp, mu, dx, c_choke):
    return np.minimum(np.asarray(w) ** 2 * np.asarray(dp) / (12.0 * mu * np.asarray(dx)), c_choke)


def crack_mass_flux_np(rho_d, c_d, gamma_d, w, dp, mu, dx):
    w, dp, rho_d = np.asarray(w, float), np.asarray(dp, float), np.asarray(rho_d, float)
    ok = (w > 0) & (dp > 0) & (rho_d > 0)
    u = crack_flow_speed_np(np.where(ok, w, 0.0), np.where(ok, dp, 0.0), mu, dx, choke_factor_np(gamma_d) * c_d)
    return np.where(ok, rho_d * w * u, 0.0)
