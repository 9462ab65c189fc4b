"""Keep the explosive's material points clear of the rock before the first step (METHOD §3.7).

A charge that fills a borehole is seeded on the grid lattice inside the circle, but the meshed wall is
the inscribed polygon, so points near the circle can lie inside the rock or overlap the wall. Points
closer than ``clearance`` [m] to a rock boundary edge, or inside a rock element, are removed; the volumes
of the rest are scaled so that the charge keeps its nominal area (mass and chemical energy unchanged).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance [m] from points p [n,2] to segments a→b [n,2] (row-wise)."""
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)


def inside_elements(points: np.ndarray, X: np.ndarray, k: int = 8) -> np.ndarray:
    """True where a point lies inside one of the rock triangles (nodes X [3E,2]); k nearest centroids tested."""
    p0, p1, p2 = X[0::3], X[1::3], X[2::3]
    cent = (p0 + p1 + p2) / 3.0
    k = min(k, len(cent))
    _, nb = cKDTree(cent).query(points, k=k)
    nb = nb.reshape(len(points), -1)
    inside = np.zeros(len(points), bool)
    for j in range(nb.shape[1]):
        e = nb[:, j]
        d1, d2, dp = p1[e] - p0[e], p2[e] - p0[e], points - p0[e]
        det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        l1 = (dp[:, 0] * d2[:, 1] - dp[:, 1] * d2[:, 0]) / det
        l2 = (d1[:, 0] * dp[:, 1] - d1[:, 1] * dp[:, 0]) / det
        inside |= (l1 >= 0) & (l2 >= 0) & (l1 + l2 <= 1)
    return inside


def clear_from_rock(x: np.ndarray, vol: np.ndarray, model, clearance: float) -> tuple[np.ndarray, np.ndarray, int]:
    """(x, vol, removed): points at least ``clearance`` from the rock's boundary edges and outside it."""
    if len(x) == 0:
        return x, vol, 0
    X = model.host["node_X"]
    slots = model.topology.boundary_slots
    a = X[slots]
    b = X[3 * (slots // 3) + (slots % 3 + 1) % 3]
    mid = 0.5 * (a + b)
    half = 0.5 * float(np.max(np.linalg.norm(b - a, axis=1)))
    tree = cKDTree(mid)
    near = tree.query_ball_point(x, r=clearance + half)
    keep = ~inside_elements(x, X)
    for i, cand in enumerate(near):
        if cand and keep[i]:
            c = np.asarray(cand)
            dist = segment_distance(np.repeat(x[i:i + 1], len(c), 0), a[c], b[c])
            keep[i] = bool(dist.min() >= clearance)
    removed = int((~keep).sum())
    total = float(vol.sum())
    x, vol = x[keep], vol[keep]
    if len(vol):
        vol = vol * (total / float(vol.sum()))
    return x, vol, removed
