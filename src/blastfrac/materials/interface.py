"""Interface spring law of the CDEM: elastic springs that fail in tension or shear.

One *spring* here is a node pair with a normal and a tangential component that fail
together (the paper's "spring"). Forces are per unit thickness [N/m]; the normal force
``Fn`` is positive in compression, the spring's area ``Ac`` is its tributary edge length
[m] (unit thickness), ``Kn = kn·Ac`` and ``Ks = ks·Ac`` [N/m per m].

Laws (METHOD.md §1.3, the paper's Eqs. 17–22):
- elastic increments: Fn ← Fn − Kn·Δd_n (opening Δd_n > 0), Fs ← Fs − Ks·Δd_s;
- tension (Y19): −Fn ≥ T·Ac; shear, Mohr–Coulomb (Y20): |Fs| ≥ Fn·tanφ + c·Ac;
- crushing (optional, not in the paper): Fn ≥ σ_cr·Ac, a compression cap on the normal stress. A Mohr–Coulomb
  spring with tension cut-off cannot fail in uniaxial strain at usual friction angles, so without it a blast's
  crushed zone comes only from the hoop tension and the shear near the wall; lattice models of concrete and
  rock close the envelope the same way (a compressive cap). A crushed spring keeps its normal force (it is a
  closed broken spring: unilateral contact) and keeps its shear force up to residual friction, Fn·tanφ_r;
  brittle (no softening: the crushed rock goes on carrying the pressure);
- brittle: the spring breaks at once (tension first, then the crushing cap, then shear);
- linear softening (Y21–Y22): past the strength the force follows the strength, which
  decreases with the opening (slip) increment at the rate ``slope`` [Pa/m] until it
  reaches zero; the spring then breaks;
- broken: unilateral frictional contact from the *total* gap (no tension; compression
  Kn·(g0 − gap); |Fs| ≤ Fn·tanφ_r).

The Warp functions and their NumPy twins below must stay line-for-line equivalent;
``tests/unit/test_interface_law.py`` compares them.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

INTACT = 0
TENSILE = 1
SHEAR = 2
CRUSHED = 3

vec5d = wp.types.vector(length=5, dtype=wp.float64)


def softening_slope(strength: float, fracture_energy: float | None, k: float) -> float:
    """Softening rate [Pa/m] so that the work dissipated per unit area equals G_f exactly.

    With the softening driven by the total opening increment, the energy dissipated per unit
    area is G_f' + strength²/(2k) for a nominal slope strength²/(2 G_f'); choosing
    G_f' = G_f − strength²/(2k) makes it G_f. Returns 0 (brittle) when G_f is None.
    Raises ValueError when k ≤ strength²/(2 G_f) (snap-back: the mesh cannot represent G_f).
    """
    if fracture_energy is None or strength == 0.0:
        return 0.0
    g_eff = fracture_energy - strength**2 / (2.0 * k)
    if g_eff <= 0.0:
        raise ValueError(
            f"fracture energy {fracture_energy} J/m² is below strength²/(2k) = {strength**2 / (2 * k):.3g} J/m²: "
            "the spring would snap back; raise the stiffness or the fracture energy"
        )
    return strength**2 / (2.0 * g_eff)


def band_slopes(strength: float, fracture_energy: np.ndarray, k: float) -> np.ndarray:
    """softening_slope for an array of fracture energies [J/m²] (one per interface) at one strength [Pa] and
    nominal stiffness k [Pa/m]; raises ValueError, naming the smallest, where one would snap back."""
    g = np.asarray(fracture_energy, float)
    g_eff = g - strength**2 / (2.0 * k)
    if np.any(g_eff <= 0.0):
        raise ValueError(
            f"fracture energy {g.min():.3g} J/m² (the fracture band's share on the thinnest blocks) is below "
            f"strength²/(2k) = {strength**2 / (2 * k):.3g} J/m²: the spring would snap back; raise the fracture "
            "energy or the stiffness, or narrow rock.fracture_band_width"
        )
    return strength**2 / (2.0 * g_eff)


@wp.func
def spring_update_intact(
    fn: wp.float64, fs: wp.float64, t_str: wp.float64, c_str: wp.float64,
    dn: wp.float64, ds: wp.float64,
    kn: wp.float64, ks: wp.float64, ac: wp.float64,
    tan_phi: wp.float64, tan_phi_r: wp.float64,
    slope_t: wp.float64, slope_c: wp.float64, breakable: wp.int32, crush: wp.float64,
):
    """Advance an intact spring by opening dn and slip ds [m]; crush: crushing strength σ_cr [Pa], 0 for none.

    Returns (Fn, Fs, T, c, mode) with forces [N/m], current strengths [Pa] and the mode code.
    """
    zero = wp.float64(0.0)
    fn = fn - kn * dn
    fs = fs - ks * ds
    if breakable == 0:
        return vec5d(fn, fs, t_str, c_str, wp.float64(0.0))
    if -fn >= t_str * ac:
        if slope_t > zero:
            t_new = t_str - slope_t * wp.max(dn, zero)
            if t_new > zero:
                return vec5d(-t_new * ac, fs, t_new, c_str, wp.float64(0.0))
        return vec5d(zero, zero, zero, zero, wp.float64(1.0))
    if crush > zero and fn >= crush * ac:
        cap = fn * tan_phi_r
        return vec5d(fn, wp.clamp(fs, -cap, cap), zero, zero, wp.float64(3.0))
    limit = fn * tan_phi + c_str * ac
    if wp.abs(fs) >= limit:
        sgn = wp.sign(fs)
        if slope_c > zero:
            c_new = c_str - slope_c * wp.abs(ds)
            if c_new > zero:
                return vec5d(fn, sgn * (fn * tan_phi + c_new * ac), t_str, c_new, wp.float64(0.0))
        return vec5d(fn, sgn * wp.max(fn, zero) * tan_phi_r, zero, zero, wp.float64(2.0))
    return vec5d(fn, fs, t_str, c_str, wp.float64(0.0))


@wp.func
def spring_update_broken(
    fs: wp.float64, gap: wp.float64, g0: wp.float64, ds: wp.float64,
    kn: wp.float64, ks: wp.float64, tan_phi_r: wp.float64,
):
    """Broken spring as unilateral frictional contact; returns (Fn, Fs) [N/m].

    gap: current normal separation (x_j − x_i)·n [m]; g0: gap at which the unloaded spring
    carried no force (non-zero after an in-situ stress initialisation).
    """
    fn = wp.max(wp.float64(0.0), -kn * (gap - g0))
    fs = fs - ks * ds
    cap = fn * tan_phi_r
    if wp.abs(fs) > cap:
        fs = wp.sign(fs) * cap
    return wp.vec2d(fn, fs)


@wp.func
def spring_dashpot(dv: wp.vec2d, n: wp.vec2d, t: wp.vec2d, kn: wp.float64, ks: wp.float64,
                   mi: wp.float64, mj: wp.float64, zeta: wp.float64):
    """Viscous force on the j node of a spring pair [N/m]: −2ζ√(m_eff K)(Δv·ê)ê along n̂ and t̂.

    dv = v_j − v_i [m/s]; m_eff = m_i m_j/(m_i + m_j) [kg/m]; ζ the fraction of critical damping of
    the two-node oscillator of each spring component. It damps the pair's own (mesh-scale)
    vibration, whose frequency √(K/m_eff) is the highest of the model, and leaves waves much
    longer than an element nearly untouched.
    """
    m_eff = mi * mj / (mi + mj)
    return spring_dashpot_of(dv, n, t, wp.vec2d(wp.sqrt(m_eff * kn), wp.sqrt(m_eff * ks)), zeta)


@wp.func
def spring_dashpot_of(dv: wp.vec2d, n: wp.vec2d, t: wp.vec2d, root: wp.vec2d, zeta: wp.float64):
    """:func:`spring_dashpot` from root = (√(m_eff·Kn), √(m_eff·Ks)) [kg/s per m], which the model keeps per pair
    (Model.pair_dashpot): the spring kernel then reads two numbers instead of two node masses and two roots."""
    two = wp.float64(2.0)
    cn = two * zeta * root[0]
    cs = two * zeta * root[1]
    return -(cn * wp.dot(dv, n)) * n - (cs * wp.dot(dv, t)) * t


# ----------------------------------------------------------------------------- NumPy twins
def np_spring_update_intact(fn, fs, t_str, c_str, dn, ds, kn, ks, ac, tan_phi, tan_phi_r, slope_t, slope_c, breakable=1,
                            crush=0.0):
    """NumPy twin of :func:`spring_update_intact` (scalars); returns (Fn, Fs, T, c, mode)."""
    fn = fn - kn * dn
    fs = fs - ks * ds
    if not breakable:
        return fn, fs, t_str, c_str, INTACT
    if -fn >= t_str * ac:
        if slope_t > 0.0:
            t_new = t_str - slope_t * max(dn, 0.0)
            if t_new > 0.0:
                return -t_new * ac, fs, t_new, c_str, INTACT
        return 0.0, 0.0, 0.0, 0.0, TENSILE
    if crush > 0.0 and fn >= crush * ac:
        cap = fn * tan_phi_r
        return fn, min(max(fs, -cap), cap), 0.0, 0.0, CRUSHED
    limit = fn * tan_phi + c_str * ac
    if abs(fs) >= limit:
        sgn = math.copysign(1.0, fs) if fs != 0.0 else 0.0
        if slope_c > 0.0:
            c_new = c_str - slope_c * abs(ds)
            if c_new > 0.0:
                return fn, sgn * (fn * tan_phi + c_new * ac), t_str, c_new, INTACT
        return fn, sgn * max(fn, 0.0) * tan_phi_r, 0.0, 0.0, SHEAR
    return fn, fs, t_str, c_str, INTACT


def np_spring_update_broken(fs, gap, g0, ds, kn, ks, tan_phi_r):
    """NumPy twin of :func:`spring_update_broken`; returns (Fn, Fs)."""
    fn = max(0.0, -kn * (gap - g0))
    fs = fs - ks * ds
    cap = fn * tan_phi_r
    if abs(fs) > cap:
        fs = np.sign(fs) * cap
    return fn, fs


def np_spring_dashpot(dv, n, t, kn, ks, mi, mj, zeta):
    """NumPy twin of :func:`spring_dashpot`."""
    dv, n, t = (np.asarray(a, float) for a in (dv, n, t))
    m_eff = mi * mj / (mi + mj)
    return -(2 * zeta * math.sqrt(m_eff * kn) * (dv @ n)) * n - (2 * zeta * math.sqrt(m_eff * ks) * (dv @ t)) * t


def tensile_failure(fn: float, t_str: float, ac: float) -> bool:
    """Eq. (Y19) as a predicate: tensile normal stress −Fn/Ac at or above T."""
    return -fn >= t_str * ac


def crushing_failure(fn: float, crush: float, ac: float) -> bool:
    """The compression cap as a predicate: compressive normal stress Fn/Ac at or above σ_cr (σ_cr > 0)."""
    return crush > 0.0 and fn >= crush * ac


def shear_failure(fn: float, fs: float, c_str: float, tan_phi: float, ac: float) -> bool:
    """Eq. (Y20) as a predicate: |τ| ≥ σ_n·tanφ + c with σ_n = Fn/Ac compression positive."""
    return abs(fs) >= fn * tan_phi + c_str * ac
