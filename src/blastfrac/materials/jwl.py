"""JWL equation of state for detonation products (METHOD.md §2.3, §2.6, §2.7).

Notation (SI units throughout):

* ``V``  relative volume v/v0 of the products [-];
* ``E``  internal energy per unit *initial* volume [J/m^3 = Pa];
* ``A, B`` [Pa], ``R1, R2, omega`` [-], ``rho0`` initial density [kg/m^3].

    p(V, E) = a(V) + b(V) E,
    a(V) = A (1 - w/(R1 V)) exp(-R1 V) + B (1 - w/(R2 V)) exp(-R2 V),
    b(V) = w / V.

The isentrope through a point (V_ref, E_ref) is

    p_s(V) = A exp(-R1 V) + B exp(-R2 V) + C V^-(1+w),
    E_s(V) = A/R1 exp(-R1 V) + B/R2 exp(-R2 V) + C / (w V^w),

with C fixed by E_s(V_ref) = E_ref; one checks dE_s/dV = -p_s and p(V, E_s) = p_s.

Every law exists twice: a ``@wp.func`` used by the MPM kernels and a NumPy twin
(``*_np``) used by the tests and by host-side reports.  The kernels work on a
material point of initial volume ``V0`` [m^2 per unit thickness in 2D] whose
internal energy ``ie`` [J per unit thickness] is ``E * V0``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

F64 = wp.float64

#: relative volume below which the exponentials and the w/(R V) terms are evaluated at the floor (§2.7)
V_FLOOR = 0.2


@dataclass(frozen=True)
class JWLParams:
    """One JWL set plus the detonation velocity used by programmed burn.

    rho0: initial density [kg/m^3]; D: detonation velocity [m/s]; A, B: [Pa];
    R1, R2, omega: [-]; E0: detonation energy per unit initial volume [J/m^3].
    """

    rho0: float
    D: float
    A: float
    B: float
    R1: float
    R2: float
    omega: float
    E0: float

    def as_tuple(self) -> tuple[float, ...]:
        return (self.rho0, self.D, self.A, self.B, self.R1, self.R2, self.omega, self.E0)


# ----------------------------------------------------------------------------- warp functions
@wp.func
def jwl_a(V: wp.float64, A: wp.float64, B: wp.float64, R1: wp.float64, R2: wp.float64, w: wp.float64):
    """Energy-independent part a(V) of the JWL pressure [Pa]."""
    return A * (F64(1.0) - w / (R1 * V)) * wp.exp(-R1 * V) + B * (F64(1.0) - w / (R2 * V)) * wp.exp(-R2 * V)


@wp.func
def jwl_pressure(
    V: wp.float64, E: wp.float64, A: wp.float64, B: wp.float64, R1: wp.float64, R2: wp.float64, w: wp.float64
):
    """JWL pressure p(V, E) [Pa]; E per unit initial volume [J/m^3]."""
    return jwl_a(V, A, B, R1, R2, w) + w / V * E


@wp.func
def jwl_sound_speed_sq(
    V: wp.float64,
    E: wp.float64,
    p: wp.float64,
    rho0: wp.float64,
    A: wp.float64,
    B: wp.float64,
    R1: wp.float64,
    R2: wp.float64,
    w: wp.float64,
):
    """Squared sound speed c^2 [m^2/s^2] = (dp/drho)_s at (V, E, p) (METHOD §2.6)."""
    e1 = wp.exp(-R1 * V)
    e2 = wp.exp(-R2 * V)
    t1 = (R1 * A * (F64(1.0) - w / (R1 * V)) - A * w / (R1 * V * V)) * e1
    t2 = (R2 * B * (F64(1.0) - w / (R2 * V)) - B * w / (R2 * V * V)) * e2
    rho = rho0 / V
    c2 = V * V / rho0 * (t1 + t2 + w * E / (V * V)) + w * p / rho
    return wp.max(c2, F64(0.0))


@wp.func
def products_sound_speed(
    F: wp.float64,
    V: wp.float64,
    E: wp.float64,
    p: wp.float64,
    rho0: wp.float64,
    A: wp.float64,
    B: wp.float64,
    R1: wp.float64,
    R2: wp.float64,
    w: wp.float64,
):
    """Sound speed c [m/s] of partly burnt explosive, burn fraction F [-]: the pressure is F·p_JWL(V, E), so
    c² = F·c²_JWL at (V [-], E [J/m³], p [Pa]); 0 for unburnt explosive, which carries no pressure."""
    return wp.sqrt(F * jwl_sound_speed_sq(V, E, p, rho0, A, B, R1, R2, w))


@wp.func
def jwl_energy_update(
    V_new: wp.float64,
    vol_new: wp.float64,
    vol_old: wp.float64,
    vol0: wp.float64,
    ie: wp.float64,
    p_old: wp.float64,
    q: wp.float64,
    F: wp.float64,
    A: wp.float64,
    B: wp.float64,
    R1: wp.float64,
    R2: wp.float64,
    w: wp.float64,
):
    """Implicit-in-p energy update consistent with the volume change (METHOD §2.3).

    vol_new, vol_old, vol0: particle volumes [m^2/m]; ie: internal energy [J/m];
    p_old: pressure at the old level [Pa]; q: artificial viscosity [Pa]; F: burn
    fraction [-] (scales a and b). V_new is clamped to >= V_FLOOR inside.
    Returns vec2d(p_new [Pa], ie_new [J/m]); p_new >= 0.
    """
    dvh = F64(0.5) * (vol_new - vol_old)
    ie_star = ie - dvh * (p_old + F64(2.0) * q)
    Vc = wp.max(V_new, F64(V_FLOOR))
    a = F * jwl_a(Vc, A, B, R1, R2, w)
    b = F * w / Vc
    p_new = (a + b * ie_star / vol0) / (F64(1.0) + b * dvh / vol0)
    if p_new < F64(0.0):
        p_new = F64(0.0)
    ie_new = ie_star - dvh * p_new
    return wp.vec2d(p_new, ie_new)


# ----------------------------------------------------------------------------- numpy twins
def jwl_a_np(V, A, B, R1, R2, w):
    V = np.asarray(V, dtype=np.float64)
    return A * (1.0 - w / (R1 * V)) * np.exp(-R1 * V) + B * (1.0 - w / (R2 * V)) * np.exp(-R2 * V)


def jwl_pressure_np(V, E, A, B, R1, R2, w):
    """NumPy twin of :func:`jwl_pressure` [Pa]."""
    V = np.asarray(V, dtype=np.float64)
    return jwl_a_np(V, A, B, R1, R2, w) + w / V * np.asarray(E, dtype=np.float64)


def jwl_sound_speed_sq_np(V, E, p, rho0, A, B, R1, R2, w):
    """NumPy twin of :func:`jwl_sound_speed_sq` [m^2/s^2]."""
    V = np.asarray(V, dtype=np.float64)
    e1, e2 = np.exp(-R1 * V), np.exp(-R2 * V)
    t1 = (R1 * A * (1.0 - w / (R1 * V)) - A * w / (R1 * V * V)) * e1
    t2 = (R2 * B * (1.0 - w / (R2 * V)) - B * w / (R2 * V * V)) * e2
    c2 = V * V / rho0 * (t1 + t2 + w * np.asarray(E) / (V * V)) + w * np.asarray(p) * V / rho0
    return np.maximum(c2, 0.0)


def products_sound_speed_np(F, V, E, p, rho0, A, B, R1, R2, w):
    """NumPy twin of :func:`products_sound_speed` [m/s]."""
    return np.sqrt(np.asarray(F, dtype=np.float64) * jwl_sound_speed_sq_np(V, E, p, rho0, A, B, R1, R2, w))


def jwl_energy_update_np(V_new, vol_new, vol_old, vol0, ie, p_old, q, F, A, B, R1, R2, w):
    """NumPy twin of :func:`jwl_energy_update`; returns (p_new [Pa], ie_new [J/m])."""
    dvh = 0.5 * (np.asarray(vol_new, dtype=np.float64) - vol_old)
    ie_star = ie - dvh * (p_old + 2.0 * q)
    Vc = np.maximum(V_new, V_FLOOR)
    a = F * jwl_a_np(Vc, A, B, R1, R2, w)
    b = F * w / Vc
    p_new = np.maximum((a + b * ie_star / vol0) / (1.0 + b * dvh / vol0), 0.0)
    return p_new, ie_star - dvh * p_new


def isentrope_constant(P: JWLParams, V_ref: float = 1.0, E_ref: float | None = None) -> float:
    """Constant C [Pa] of the isentrope through (V_ref, E_ref); E_ref defaults to E0."""
    E_ref = P.E0 if E_ref is None else E_ref
    return (E_ref - P.A / P.R1 * np.exp(-P.R1 * V_ref) - P.B / P.R2 * np.exp(-P.R2 * V_ref)) * P.omega * V_ref**P.omega


def isentrope_pressure_np(V, P: JWLParams, C: float):
    """p_s(V) [Pa] on the isentrope of constant C."""
    V = np.asarray(V, dtype=np.float64)
    return P.A * np.exp(-P.R1 * V) + P.B * np.exp(-P.R2 * V) + C * V ** (-(1.0 + P.omega))


def isentrope_energy_np(V, P: JWLParams, C: float):
    """E_s(V) [J/m^3 of initial volume] on the isentrope of constant C."""
    V = np.asarray(V, dtype=np.float64)
    return P.A / P.R1 * np.exp(-P.R1 * V) + P.B / P.R2 * np.exp(-P.R2 * V) + C / (P.omega * V**P.omega)
