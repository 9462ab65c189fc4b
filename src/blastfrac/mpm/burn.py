"""Programmed burn (METHOD §2.4): lighting times and the burn fraction F.

* Lighting time of a particle from its initial position X:
  t_l = min_k (|X - x_k| / D + t_k) over the detonation points k (delay t_k).
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
