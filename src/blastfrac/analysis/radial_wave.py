"""Reference solution of the outgoing stress wave of a pressurised borehole: 1D axisymmetric elastodynamics.

A borehole of radius r_b [m] in an unbounded, linear elastic rock in plane strain, loaded on its wall by a
pressure history p(t) [Pa] (measured on a blast run, ``borehole_pressure.csv``), has a purely radial motion
u(r, t) with

    ρ ü = ∂σ_rr/∂r + (σ_rr − σ_θθ)/r,
    σ_rr = (λ + 2μ) ∂u/∂r + λ u/r,   σ_θθ = λ ∂u/∂r + (λ + 2μ) u/r,   σ_rr(r_b, t) = −p(t).

:func:`radial_wave` solves it with linear elements in r (the axisymmetric weak form, weight r; one-point
quadrature), lumped mass and central differences, on a 1D mesh fine enough that the answer is converged where
the 2D block mesh is not: it is the yardstick for how well a block mesh carries the pulse from the hole to a
monitor (examples/confined_blast/mesh_study.md). The outer radius is far enough that no reflection returns to
the sampled radii before t_end (it is chosen so by default). Elastic only: no fracture, no gas in cracks.

With ``discs`` it also returns what a monitor with an averaging radius reads at (r0, 0): the mean over the disc
of σ_xx = σ_rr cos²θ + σ_θθ sin²θ and σ_yy = σ_rr sin²θ + σ_θθ cos²θ (:func:`disc_quadrature`: Gauss in the
distance from the disc's centre, uniform in its angle).

Checks (tests/unit/test_radial_wave.py): a slow ramp gives the thick-cylinder Lamé field; a front ramped over
0.1 µs arrives at (r − r_b)/c_p with the peak −p·√(r_b/r) of a cylindrical front, converging with dr.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..materials.elastic import lame


@dataclass
class RadialWave:
    """Sampled histories: ``t`` [s] [T]; ``srr``, ``stt`` [Pa] [T, R] at the sample ``radii`` [m]; ``u_wall``
    [m] [T]; and, when asked, ``disc_sxx``, ``disc_syy`` [Pa] [T, M], the disc-averaged σ_xx and σ_yy of each
    monitor (a monitor at (r0, 0): σ_xx is its radial, σ_yy its hoop stress)."""

    t: np.ndarray
    radii: np.ndarray
    srr: np.ndarray
    stt: np.ndarray
    u_wall: np.ndarray
    disc_sxx: np.ndarray | None = None
    disc_syy: np.ndarray | None = None


def disc_quadrature(r0: float, radius: float, n_r: int = 8, n_t: int = 32) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (radius from the hole centre [m], polar angle about the hole centre [rad]) and weights (summing to 1)
    of a Gauss (in ρ) × uniform (in angle) rule over the disc of ``radius`` [m] centred at (r0, 0)."""
    g, wg = np.polynomial.legendre.leggauss(n_r)
    rho = 0.5 * radius * (g + 1.0)
    w_rho = 0.5 * radius * wg * rho                 # ρ dρ
    ang = (np.arange(n_t) + 0.5) * 2 * math.pi / n_t
    R, A = np.meshgrid(rho, ang, indexing="ij")
    W = np.repeat(w_rho[:, None], n_t, 1) * (2 * math.pi / n_t)
    x, y = r0 + R * np.cos(A), R * np.sin(A)
    W = W / W.sum()
    return np.hypot(x, y).ravel(), np.arctan2(y, x).ravel(), W.ravel()


def radial_wave(t_p: np.ndarray, p: np.ndarray, r_b: float, E: float, nu: float, rho: float, radii, t_end: float,
                dr: float = 2e-5, r_out: float | None = None, sample_dt: float = 1e-7,
                discs: list[tuple[float, float]] | None = None, cfl: float = 0.5) -> RadialWave:
    """The wave of the wall pressure p(t) (samples ``t_p`` [s], ``p`` [Pa], linear in between, 0 before the
    first sample and held after the last) sampled every ``sample_dt`` [s] at ``radii`` [m] up to ``t_end`` [s].

    ``dr`` [m]: element length (uniform); ``r_out`` [m]: outer radius (free), by default beyond the reach of any
    reflection before t_end; ``discs``: monitors (r0 [m], averaging radius [m]) whose disc-averaged σ_xx and σ_yy are
    also returned; ``cfl``: Δt = cfl·dr/c_p.
    """
    lam, mu = lame(E, nu)
    M = lam + 2 * mu
    c_p = math.sqrt(M / rho)
    radii = np.atleast_1d(np.asarray(radii, float))
    r_far = max([float(q) for q in radii] + [r0 + a for r0, a in (discs or [])] + [r_b])
    if r_out is None:
        r_out = r_far + 0.5 * c_p * t_end + 4 * dr          # the reflection from r_out returns after t_end
    n = int(math.ceil((r_out - r_b) / dr))
    r = r_b + dr * np.arange(n + 1)                          # nodes
    rm = 0.5 * (r[1:] + r[:-1])                              # element midpoints
    h = np.diff(r)
    mass = np.zeros(n + 1)                                   # lumped, per radian
    mass[:-1] += 0.5 * rho * rm * h
    mass[1:] += 0.5 * rho * rm * h
    dt = cfl * dr / c_p
    steps = int(math.ceil(t_end / dt))
    dt = t_end / steps
    every = max(1, int(round(sample_dt / dt)))

    # sample points: element stresses interpolated linearly between element midpoints
    def interp_weights(q):
        q = np.clip(np.asarray(q, float), rm[0], rm[-1])
        j = np.clip(np.searchsorted(rm, q) - 1, 0, len(rm) - 2)
        a = (q - rm[j]) / (rm[j + 1] - rm[j])
        return j, a

    js, as_ = interp_weights(radii)
    quad = []
    for r0, a in (discs or []):
        rq, th, wq = disc_quadrature(r0, a)
        jq, aq = interp_weights(rq)
        quad.append((jq, aq, np.cos(th) ** 2 * wq, np.sin(th) ** 2 * wq))
    u = np.zeros(n + 1)
    v = np.zeros(n + 1)
    ts, srr_s, stt_s, uw, dsx, dsy = [], [], [], [], [], []

    def stresses(u):
        er = np.diff(u) / h
        et = 0.5 * (u[1:] + u[:-1]) / rm
        return M * er + lam * et, lam * er + M * et

    def sample(t, s_rr, s_tt):
        ts.append(t)
        srr_s.append(s_rr[js] * (1 - as_) + s_rr[js + 1] * as_)
        stt_s.append(s_tt[js] * (1 - as_) + s_tt[js + 1] * as_)
        uw.append(u[0])
        if quad:
            rx, ry = [], []
            for jq, aq, cw, sw in quad:
                a_rr = s_rr[jq] * (1 - aq) + s_rr[jq + 1] * aq
                a_tt = s_tt[jq] * (1 - aq) + s_tt[jq + 1] * aq
                rx.append(float(cw @ a_rr + sw @ a_tt))
                ry.append(float(sw @ a_rr + cw @ a_tt))
            dsx.append(rx)
            dsy.append(ry)

    def load(t):
        return float(np.interp(t, t_p, p, left=0.0, right=p[-1]))

    f = np.zeros(n + 1)
    s_rr, s_tt = stresses(u)
    sample(0.0, s_rr, s_tt)
    for k in range(steps):
        t = k * dt
        f[:] = 0.0
        # internal force per radian: ∫ (σ_rr ∂δu/∂r + σ_θθ δu/r) r dr, one-point rule
        f[:-1] += s_rr * rm - 0.5 * s_tt * h
        f[1:] -= s_rr * rm + 0.5 * s_tt * h
        f[0] += load(t) * r_b                                # the wall pressure pushes outward
        v += dt * f / mass if k else 0.5 * dt * f / mass     # leapfrog, the first half step from rest
        u += dt * v
        s_rr, s_tt = stresses(u)
        if (k + 1) % every == 0:
            sample((k + 1) * dt, s_rr, s_tt)
    return RadialWave(np.array(ts), radii, np.array(srr_s), np.array(stt_s), np.array(uw),
                      np.array(dsx) if quad else None, np.array(dsy) if quad else None)
