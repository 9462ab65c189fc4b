"""Monitor points: rock quantities sampled at fixed reference points over time."""

from __future__ import annotations

import numpy as np


def locate_points(X: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Element containing each point and its barycentric weights, on the reference mesh.

    X: node reference positions [3E, 2]; points [M, 2]. Points outside every element are
    assigned the nearest element centroid (weights then extrapolate mildly).
    """
    p0, p1, p2 = X[0::3], X[1::3], X[2::3]
    elems, weights = [], []
    for p in np.atleast_2d(points):
        d1, d2, dp = p1 - p0, p2 - p0, p - p0
        det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        l1 = (dp[:, 0] * d2[:, 1] - dp[:, 1] * d2[:, 0]) / det
        l2 = (d1[:, 0] * dp[:, 1] - d1[:, 1] * dp[:, 0]) / det
        l0 = 1 - l1 - l2
        inside = np.flatnonzero((l0 >= -1e-12) & (l1 >= -1e-12) & (l2 >= -1e-12))
        e = int(inside[0]) if len(inside) else int(np.argmin(np.linalg.norm((p0 + p1 + p2) / 3 - p, axis=1)))
        elems.append(e)
        weights.append([l0[e], l1[e], l2[e]])
    return np.array(elems, np.int64), np.array(weights)


class MonitorSet:
    """Samples each monitor's quantities from the rock state (host arrays)."""

    def __init__(self, monitors: list, X: np.ndarray):
        self.monitors = monitors
        pts = np.array([m.position for m in monitors]).reshape(-1, 2)
        self.elems, self.weights = locate_points(X, pts) if len(monitors) else (np.zeros(0, int), np.zeros((0, 3)))
        self.columns = [f"{m.name}:{q}" for m in monitors for q in m.quantities]

    def sample(self, x: np.ndarray, X: np.ndarray, v: np.ndarray, sigma: np.ndarray, gas_pressure=None) -> list[float]:
        row = []
        for k, m in enumerate(self.monitors):
            e, w = self.elems[k], self.weights[k]
            nodes = slice(3 * e, 3 * e + 3)
            u = w @ (x[nodes] - X[nodes])
            vel = w @ v[nodes]
            s = sigma[e]
            vals = {
                "ux": u[0], "uy": u[1], "vx": vel[0], "vy": vel[1], "speed": float(np.hypot(*vel)),
                "sxx": s[0], "syy": s[1], "sxy": s[2], "pressure": -0.5 * (s[0] + s[1]),
                "gas_pressure": float(gas_pressure(np.array([m.position]))[0]) if gas_pressure else 0.0,
            }
            row.extend(float(vals[q]) for q in m.quantities)
        return row
