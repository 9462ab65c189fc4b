"""The 1D reference of a borehole's outgoing wave (analysis/radial_wave.py), against closed forms.

- A pressure ramped slowly (over 40 transits of the cylinder) and then held gives the thick-cylinder Lamé
  field of a free outer face: σ_rr, σ_θθ and the wall displacement within 1 % of the formulas.
- A pressure ramped over 0.1 µs: the front reaches r at (r − r_b)/c_p (half its peak t_r/2 later, within 3
  elements), and its peak is the jump −p·√(r_b/r) of a cylindrical front (which decays as r^(−1/2)) at r = 2, 4,
  8 r_b within 0.5 % at dr = 0.01 mm, the largest error falling by more than 0.6× per halving of dr.
- A disc average of a uniform field is the field, and of the Lamé field its closed-form mean over the disc.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from blastfrac.analysis.radial_wave import disc_quadrature, radial_wave
from blastfrac.materials.elastic import lame

E, NU, RHO, RB = 50e9, 0.2, 2600.0, 0.005
LAM, MU = lame(E, NU)
CP = math.sqrt((LAM + 2 * MU) / RHO)


def test_slow_ramp_gives_the_thick_cylinder_lame_field():
    p0, r_out = 100e6, 0.05
    transit = (r_out - RB) / CP
    t_ramp = 40 * transit
    t = np.array([0.0, t_ramp, 3 * t_ramp])
    p = np.array([0.0, p0, p0])
    radii = np.array([0.006, 0.01, 0.02, 0.04])
    w = radial_wave(t, p, RB, E, NU, RHO, radii, t_end=1.5 * t_ramp, dr=1e-4, r_out=r_out, sample_dt=t_ramp / 50)
    late = w.t > 1.2 * t_ramp                      # held: the residual ringing averages out over the window
    srr, stt, uw = w.srr[late].mean(0), w.stt[late].mean(0), w.u_wall[late].mean()
    a2, b2 = RB**2, r_out**2
    k = p0 * a2 / (b2 - a2)
    srr_ex = k * (1 - b2 / radii**2)
    stt_ex = k * (1 + b2 / radii**2)
    # plane strain: u = (r/2(λ+μ))·A·... with σ_rr = A − B/r², σ_θθ = A + B/r²; u = A r/(2(λ+μ)) + B/(2μ r)
    A, B = k, k * b2
    u_ex = A * RB / (2 * (LAM + MU)) + B / (2 * MU * RB)
    print(f"\nσ_rr {srr / 1e6} vs {srr_ex / 1e6}; σ_θθ {stt / 1e6} vs {stt_ex / 1e6}; u_wall {uw:.4e} vs {u_ex:.4e}")
    np.testing.assert_allclose(srr, srr_ex, rtol=0.01, atol=0.005 * p0)
    np.testing.assert_allclose(stt, stt_ex, rtol=0.01)
    assert uw == pytest.approx(u_ex, rel=0.01)


def _front(dr, t_r=1e-7):
    """Peak σ_rr / p and the time of half the peak − ((r − r_b)/c_p + t_r/2), in element transits, at 2, 4,
    8 r_b for a pressure ramped to p over t_r and held."""
    p0 = 100e6
    radii = np.array([2, 4, 8]) * RB
    t_end = (radii.max() - RB) / CP + 1e-6
    w = radial_wave(np.array([0.0, t_r]), np.array([0.0, p0]), RB, E, NU, RHO, radii, t_end=t_end, dr=dr,
                    sample_dt=2e-9)
    peak = w.srr.min(0) / p0
    half = np.array([w.t[np.argmax(w.srr[:, i] <= 0.5 * w.srr[:, i].min())] for i in range(len(radii))])
    return peak, (half - (radii - RB) / CP - 0.5 * t_r) * CP / dr


def test_steep_front_carries_the_cylindrical_jump_and_converges():
    jump = -np.sqrt(RB / (np.array([2, 4, 8]) * RB))         # a cylindrical front's jump decays as r^(−1/2)
    errs = []
    for dr in (4e-5, 2e-5, 1e-5):                            # the 0.1 µs rise spans 12, 23, 46 elements
        peak, lag = _front(dr)
        errs.append(np.abs(peak - jump))
        print(f"\ndr = {dr * 1e3:.2f} mm: peak σ_rr/p {peak} (−√(r_b/r) = {jump}), half-peak lag {lag} elements")
        assert np.all(np.abs(lag) < 3)
    errs = np.array(errs)
    assert np.all(errs[-1] < 0.005)
    worst = errs.max(axis=1)                                 # the largest over the three radii
    print(f"largest peak error per dr: {worst}")
    assert worst[1] < 0.6 * worst[0] and worst[2] < 0.6 * worst[1]


def test_disc_average():
    rq, th, wq = disc_quadrature(0.05, 0.005)
    assert wq.sum() == pytest.approx(1.0, rel=1e-12)
    # a uniform field reads itself; the mean of x over the disc is its centre
    x = rq * np.cos(th)
    assert wq @ x == pytest.approx(0.05, rel=1e-12)
    # the Lamé σ_xx of a cavity, σ_rr = −p a²/r², σ_θθ = +p a²/r²: σ_xx = −p a² cos2θ / r², a harmonic function
    # of (x, y) (the real part of −p a²/z²), so its disc mean is its value at the centre (mean-value theorem)
    sxx = -1.0 * 0.005**2 * np.cos(2 * th) / rq**2
    assert wq @ sxx == pytest.approx(-0.005**2 / 0.05**2, rel=1e-6)
