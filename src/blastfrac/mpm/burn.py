"""Programmed burn (METHOD §2.4): lighting times and the burn fraction F.

* Lighting time of a particle from its initial position X:
  t_l = min_k (|X - x_k| / D + t_k) over the detonation points k (delay t_k), and over the
  detonation lines (a cord from A to B fired at A at t_k, its front running at v along it):
  t_l = t_k + min_{0<=s<=L} (s / v + |X - A - s u| / D), in closed form (:func:`line_lighting_times`).
* Time burn:       F1 = clamp((t - t_l) D / (k_w h_e), 0, 1), h_e the particle length
  (sqrt of its initial area), k_w = 1.5 by default.
* Volumetric burn: F2 = (1 - V) rho0 D^2 / p_CJ, set to 1 above 0.95, clamped to [0, 1].
* F = max(F1, F2) (mode "combined"), F = 0 below 1e-4, and F never decreases.
"""

from __future__ import annotations

import numpy as np
import warp as wp

F64 = wp.float64

BURN_COMBINED = 0
BURN_TIME = 1
BURN_VOLUMETRIC = 2
BURN_INSTANT = 3
BURN_MODES = {"combined": BURN_COMBINED, "time": BURN_TIME, "volumetric": BURN_VOLUMETRIC, "instant": BURN_INSTANT}
F_MIN = 1.0e-4


def lighting_times(X: np.ndarray, points: np.ndarray, delays: np.ndarray, D: float) -> np.ndarray:
    """t_l [s] for initial positions X [n,2] [m], detonation points [k,2] [m], delays [k] [s], D [m/s]."""
    X = np.asarray(X, dtype=np.float64).reshape(-1, 2)
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    dl = np.asarray(delays, dtype=np.float64).reshape(-1)
    if len(pts) == 0:
        raise ValueError("at least one detonation point is needed")
    d = np.linalg.norm(X[:, None, :] - pts[None, :, :], axis=2)
    return np.min(d / D + dl[None, :], axis=1)


def line_lighting_times(X: np.ndarray, start, end, delay: float, velocity: float, D: float) -> np.ndarray:
    """t_l [s] of initial positions X [n,2] [m] lit by one detonation line (cord) from ``start`` to ``end`` [m].

    A cord point at arc length s from ``start`` lights at delay + s / velocity; the particle lights at
    min over s in [0, L] of f(s) = delay + s / v + sqrt((a - s)^2 + d^2) / D, a = (X - A)·u the abscissa
    along the cord, d the distance to its line.  f is convex; f'(s) = 1/v - (a - s) / (D r).
    * v <= D: f' >= 1/v - 1/D >= 0, so s* = 0 (the particle lights from ``start``);
    * v > D: f' = 0 where (a - s)/r = c = D/v, i.e. s = a - d c / sqrt(1 - c^2); clamped to [0, L]
      (convexity makes the clamped stationary point the minimiser).  v = inf gives s* = clamp(a, 0, L):
      t_l = delay + dist(X, segment) / D.
    """
    X = np.asarray(X, dtype=np.float64).reshape(-1, 2)
    A, B = np.asarray(start, np.float64), np.asarray(end, np.float64)
    L = float(np.linalg.norm(B - A))
    if not L > 0:
        raise ValueError("a detonation line needs start != end")
    u = (B - A) / L
    r = X - A
    a = r @ u
    d = np.abs(r[:, 0] * u[1] - r[:, 1] * u[0])
    v = float(velocity)
    if v <= D:
        s = np.zeros(len(X))
    else:
        c = D / v  # 0 for v = inf
        s = np.clip(a - d * c / np.sqrt(1.0 - c * c), 0.0, L)
    dist = np.hypot(a - s, d)
    return delay + (0.0 if np.isinf(v) else s / v) + dist / D


@wp.func
def burn_fraction(
    F_old: wp.float64,
    t: wp.float64,
    t_light: wp.float64,
    V: wp.float64,
    h_e: wp.float64,
    D: wp.float64,
    rho0: wp.float64,
    p_cj: wp.float64,
    width: wp.float64,
    mode: int,
):
    """Burn fraction at time t [s] for relative volume V; monotone in time (>= F_old)."""
    if mode == 3:
        return F64(1.0)
    F1 = F64(0.0)
    F2 = F64(0.0)
    if mode != 2:
        F1 = wp.clamp((t - t_light) * D / (width * h_e), F64(0.0), F64(1.0))
    if mode != 1:
        F2 = (F64(1.0) - V) * rho0 * D * D / p_cj
        if F2 > F64(0.95):
            F2 = F64(1.0)
        F2 = wp.clamp(F2, F64(0.0), F64(1.0))
    F = wp.max(F1, F2)
    if F < F64(F_MIN):
        F = F64(0.0)
    return wp.max(F, F_old)


def burn_fraction_np(F_old, t, t_light, V, h_e, D, rho0, p_cj, width=1.5, mode: str = "combined"):
    """NumPy twin of :func:`burn_fraction`."""
    F_old = np.asarray(F_old, dtype=np.float64)
    if mode == "instant":
        return np.ones_like(F_old)
    F1 = np.zeros_like(F_old) if mode == "volumetric" else np.clip((t - np.asarray(t_light)) * D / (width * np.asarray(h_e)), 0, 1)
    if mode == "time":
        F2 = np.zeros_like(F_old)
    else:
        F2 = (1.0 - np.asarray(V)) * rho0 * D * D / p_cj
        F2 = np.clip(np.where(F2 > 0.95, 1.0, F2), 0, 1)
    F = np.maximum(F1, F2)
    F = np.where(F < F_MIN, 0.0, F)
    return np.maximum(F, F_old)
