"""Line initiation (``explosive.detonation_lines``): lighting times against formulas written out here.

A cord from A to B (length L, unit direction u) is fired at A at t0; its front runs along it at v, and a
particle at X lights at t0 + min_{0<=s<=L} (s/v + |X - A - s u| / D).  Limits: v <= D, the particle lights
from A (triangle inequality); v -> inf, the whole cord lights at once, t0 + dist(X, segment)/D; v > D abeam,
the ray leaves the cord at the angle with cos = D/v: s* = a - d (D/v)/sqrt(1 - (D/v)^2),
|X - y(s*)| = d / sqrt(1 - (D/v)^2).
"""

import numpy as np
import pytest
from pydantic import ValidationError

from blastfrac.explosives.library import get_explosive
from blastfrac.mpm import MPMSolver
from blastfrac.mpm.burn import line_lighting_times
from blastfrac.scenario.explosive import ExplosiveConfig

PETN = get_explosive("petn")
D = PETN.D
A, B = np.array([0.01, -0.02]), np.array([0.01, 0.02])  # a vertical cord, L = 0.04
L = 0.04
T0 = 2e-6


def _brute(X, A, B, t0, v, D, n=400001):
    """Dense sampling of the cord (independent of the closed form)."""
    s = np.linspace(0.0, np.linalg.norm(B - A), n)
    y = A[None] + s[:, None] * ((B - A) / np.linalg.norm(B - A))[None]
    lt = t0 + (0.0 if np.isinf(v) else s / v)
    return np.array([np.min(lt + np.linalg.norm(y - x[None], axis=1) / D) for x in np.atleast_2d(X)])


def _seg_dist(X, A, B):
    u = (B - A) / np.linalg.norm(B - A)
    s = np.clip((X - A) @ u, 0.0, np.linalg.norm(B - A))
    return np.linalg.norm(X - (A[None] + s[:, None] * u[None]), axis=1)


RNG = np.random.default_rng(3)
X = np.column_stack([RNG.uniform(-0.03, 0.05, 200), RNG.uniform(-0.05, 0.05, 200)])


@pytest.mark.parametrize("v", [D, 0.5 * D])
def test_cord_at_or_below_D_lights_from_its_fired_end(v):
    t = line_lighting_times(X, A, B, T0, v, D)
    np.testing.assert_allclose(t, T0 + np.linalg.norm(X - A, axis=1) / D, rtol=1e-13)


def test_infinitely_fast_cord_lights_at_once():
    t = line_lighting_times(X, A, B, T0, np.inf, D)
    np.testing.assert_allclose(t, T0 + _seg_dist(X, A, B) / D, rtol=1e-13)
    # and a very fast (finite) cord tends to it
    t_fast = line_lighting_times(X, A, B, T0, 1e6 * D, D)
    np.testing.assert_allclose(t_fast, t, rtol=0, atol=1e-6 * L / D * 2)


def test_oblique_front_abeam_the_cord():
    v = 2.0 * D  # cos = D/v = 1/2: the front leaves the cord at 60 degrees
    c = D / v
    d, a = 0.005, 0.03  # particle 5 mm off the cord, 30 mm along it
    Xp = A + np.array([d, a])
    s_star = a - d * c / np.sqrt(1 - c * c)
    assert 0 < s_star < L
    expect = T0 + s_star / v + d / np.sqrt(1 - c * c) / D
    t = line_lighting_times(Xp[None], A, B, T0, v, D)
    np.testing.assert_allclose(t, [expect], rtol=1e-13)
    # = t0 + a/v + d sqrt(1 - c^2)/D, and the dense sampling agrees
    np.testing.assert_allclose(expect, T0 + a / v + d * np.sqrt(1 - c * c) / D, rtol=1e-13)
    np.testing.assert_allclose(t, _brute(Xp, A, B, T0, v, D), rtol=1e-9)


@pytest.mark.parametrize("v", [0.7 * D, D, 1.3 * D, 3.0 * D, np.inf])
def test_closed_form_is_the_minimum_over_the_cord(v):
    """Everywhere (before, abeam, past the far end, on the cord): the closed form equals the dense minimum."""
    t = line_lighting_times(X[:40], A, B, T0, v, D)
    np.testing.assert_allclose(t, _brute(X[:40], A, B, T0, v, D), rtol=1e-9)
    # past the far end (clamped at s = L) with v > D: t0 + L/v + |X - B|/D
    if v > D:
        Xp = B + np.array([0.001, 0.02])
        np.testing.assert_allclose(line_lighting_times(Xp[None], A, B, T0, v, D),
                                   [T0 + (0 if np.isinf(v) else L / v) + np.linalg.norm(Xp - B) / D], rtol=1e-13)


def _cfg(**kw):
    base = dict(name="petn", charges=[{"kind": "polygon", "vertices": [(0.0, -0.02), (0.02, -0.02), (0.02, 0.02),
                                                                         (0.0, 0.02)]}],
                grid={"cell_size": 2e-3, "margin": 0.004, "points_per_cell": 2})
    base.update(kw)
    return ExplosiveConfig(**base)


def test_solver_lights_particles_from_lines_and_points():
    v = 1.5 * D
    cfg = _cfg(detonation_lines=[{"start": tuple(A), "end": tuple(B), "delay": T0, "velocity": v}])
    s = MPMSolver(cfg)
    x = s.x.numpy()
    np.testing.assert_allclose(s.light_time.numpy(), _brute(x, A, B, T0, v, D, n=200001), rtol=1e-10)
    # default velocity: the explosive's D (the cord lights the charge as a point at its start would)
    s = MPMSolver(_cfg(detonation_lines=[{"start": tuple(A), "end": tuple(B), "delay": T0}]))
    np.testing.assert_allclose(s.light_time.numpy(), T0 + np.linalg.norm(x - A, axis=1) / D, rtol=1e-13)
    # with a point too: the earliest of both; the centroid default is not added
    p = np.array([0.015, 0.015])
    s = MPMSolver(_cfg(detonation_lines=[{"start": tuple(A), "end": tuple(B), "delay": T0, "velocity": v}],
                       detonation_points=[{"position": tuple(p), "delay": 0.0}]))
    expect = np.minimum(_brute(x, A, B, T0, v, D, n=200001), np.linalg.norm(x - p, axis=1) / D)
    np.testing.assert_allclose(s.light_time.numpy(), expect, rtol=1e-10)


def test_simultaneous_line_is_a_plane_wave():
    """simultaneous = true: every cord point fires at t0, so X lights at t0 + dist(X, segment)/D (the v -> inf
    limit), and particles abeam the cord light by their distance to its line alone (a plane front)."""
    s = MPMSolver(_cfg(detonation_lines=[{"start": tuple(A), "end": tuple(B), "delay": T0, "simultaneous": True}]))
    x = s.x.numpy()
    np.testing.assert_allclose(s.light_time.numpy(), T0 + _seg_dist(x, A, B) / D, rtol=1e-13)
    abeam = (x[:, 1] > A[1]) & (x[:, 1] < B[1])
    assert abeam.sum() > 10
    np.testing.assert_allclose(s.light_time.numpy()[abeam], T0 + np.abs(x[abeam, 0] - A[0]) / D, rtol=1e-12)
    with pytest.raises(ValidationError, match="not allowed with simultaneous"):
        _cfg(detonation_lines=[{"start": tuple(A), "end": tuple(B), "simultaneous": True, "velocity": 9000.0}])


def test_line_validation():
    # a cord crossing the charge with both ends outside it is accepted
    _cfg(detonation_lines=[{"start": (-0.01, 0.0), "end": (0.03, 0.0)}])
    # one touching a corner too
    _cfg(detonation_lines=[{"start": (0.02, 0.02), "end": (0.03, 0.03)}])
    # circle charge, a cord grazing it
    ExplosiveConfig(name="petn", charges=[{"kind": "circle", "center": (0.0, 0.0), "radius": 0.01}],
                    grid={"cell_size": 2e-3}, detonation_lines=[{"start": (-0.02, 0.01), "end": (0.02, 0.01)}])
    bad = [
        ({"start": (0.03, 0.0), "end": (0.05, 0.0)}, "neither lies in nor touches"),
        ({"start": (0.01, 0.0), "end": (0.01, 0.0)}, "distinct"),
        ({"start": (0.01, 0.0), "end": (0.01, 0.01), "delay": -1e-6}, "greater than or equal"),
        ({"start": (0.01, 0.0), "end": (0.01, 0.01), "delay": float("inf")}, "finite"),
        ({"start": (float("nan"), 0.0), "end": (0.01, 0.01)}, "finite"),
        ({"start": (0.01, 0.0), "end": (0.01, 0.01), "velocity": 0.0}, "greater than"),
        ({"start": (0.01, 0.0), "end": (0.01, 0.01), "velocity": float("inf")}, "finite"),
    ]
    for line, msg in bad:
        with pytest.raises(ValidationError, match=msg):
            _cfg(detonation_lines=[line])
    with pytest.raises(ValidationError, match="repeats"):
        _cfg(detonation_lines=[{"start": (0.01, 0.0), "end": (0.01, 0.01)}] * 2)
