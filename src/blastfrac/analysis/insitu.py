"""Checks of the in-situ stress stage against the Kirsch solution (METHOD §1.8, VALIDATION §0.2).

Kirsch (plane, tension positive): a circular hole of radius a, free of traction, in a plate under the far
field (σxx, σyy, τxy) = (Sx, Sy, T) has, at polar position (r, θ) about its centre, the hoop stress

  σθθ = (Sx + Sy)/2·(1 + a²/r²) − (Sx − Sy)/2·(1 + 3a⁴/r⁴)·cos 2θ − T·(1 + 3a⁴/r⁴)·sin 2θ   [Pa].

At the wall (r = a) its largest value is Sx + Sy + 4·√(((Sx − Sy)/2)² + T²): under a vertical compression
P alone (Sy = −P), +P of tension at the crown and floor.
"""

from __future__ import annotations

import numpy as np


def kirsch_hoop_stress(r, theta, a: float, sxx: float, syy: float, sxy: float):
    """Kirsch hoop stress σθθ [Pa] at radius r [m] and polar angle θ [rad] about a hole of radius a [m]."""
    r, theta = np.asarray(r, float), np.asarray(theta, float)
    q2, q4 = (a / r) ** 2, (a / r) ** 4
    return (0.5 * (sxx + syy) * (1 + q2) - 0.5 * (sxx - syy) * (1 + 3 * q4) * np.cos(2 * theta)
            - sxy * (1 + 3 * q4) * np.sin(2 * theta))


def kirsch_wall_max_tension(sxx: float, syy: float, sxy: float) -> float:
    """Largest hoop stress on the wall of a free hole [Pa] (tension positive)."""
    return sxx + syy + 4.0 * float(np.hypot(0.5 * (sxx - syy), sxy))


def wall_stress_check(x: np.ndarray, sigma: np.ndarray, center, a: float, sxx: float, syy: float, sxy: float,
                      tensile_strength: float) -> dict:
    """Hoop stress of the blocks touching the wall of the hole (center, a) against Kirsch.

    x: node positions [3E, 2] m (three per element, element order); sigma: element stress (σxx, σyy, τxy)
    [E, 3] Pa. The wall blocks are those with a node on the wall (within 0.02·a of it). Returns the largest hoop
    tension of those blocks, Kirsch at their centroids (what the mesh can resolve) and at the wall itself, the
    RMS difference, and how many wall blocks exceed the tensile strength [Pa].
    """
    c = np.asarray(center, float)
    xe = x.reshape(-1, 3, 2)
    rn = np.linalg.norm(xe - c, axis=2)
    wall = (np.abs(rn - a) < 0.02 * a).any(axis=1)
    cen = xe[wall].mean(axis=1) - c
    r = np.linalg.norm(cen, axis=1)
    th = np.arctan2(cen[:, 1], cen[:, 0])
    s = sigma[wall]
    cs, sn = np.cos(th), np.sin(th)
    s_tt = s[:, 0] * sn**2 + s[:, 1] * cs**2 - 2 * s[:, 2] * sn * cs
    k_tt = kirsch_hoop_stress(r, th, a, sxx, syy, sxy)
    return {
        "wall_blocks": int(wall.sum()),
        "hoop_max_tension": float(s_tt.max()) if len(s_tt) else 0.0,
        "kirsch_max_tension_at_block_centroids": float(k_tt.max()) if len(k_tt) else 0.0,
        "kirsch_max_tension_at_wall": kirsch_wall_max_tension(sxx, syy, sxy),
        "hoop_rms_difference": float(np.sqrt(np.mean((s_tt - k_tt) ** 2))) if len(s_tt) else 0.0,
        "blocks_above_tensile_strength": int(np.sum(s_tt > tensile_strength)),
    }
