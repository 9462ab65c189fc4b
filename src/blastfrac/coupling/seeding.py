"""Keep the explosive's material points clear of the rock before the first step (METHOD §3.7).

A charge that fills a borehole is seeded inside the circle, but the meshed wall is the inscribed polygon,
so points near the circle can lie inside the rock or overlap the wall. A point at a distance d from the
nearest rock boundary edge with (1 − snap)·clearance ≤ d < clearance is moved straight away from that edge
to d = clearance: the outer ring of a conformal seeding (mpm/seeding.py), which touches the circle, then
touches the polygon too instead of being deleted (the polygon's sagitta L²/8R is a few % of a point
radius). Points still closer than ``clearance`` [m], or inside a rock element, are removed, and the
volumes of the rest are scaled so that the charge keeps its nominal area (mass and chemical energy
unchanged).
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


def nearest_on_segments(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Closest points [n,2] of segments a→b [n,2] to points p [n,2] (row-wise)."""
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    return a + t[:, None] * d


def clear_from_rock(x: np.ndarray, vol: np.ndarray, model, clearance: float,
                    snap: float = 0.5, return_mask: bool = False):
    """(x, vol, removed): points at least ``clearance`` [m] from the rock's boundary edges and outside it
    (with ``return_mask``, also the mask of the input points kept).

    Points less than ``snap``·clearance short of it are moved away from the nearest edge instead of removed
    (up to three passes, for points near two edges); ``snap`` = 0 removes them all (the former rule).
    """
    if len(x) == 0:
        return (x, vol, 0, np.zeros(0, bool)) if return_mask else (x, vol, 0)
    x = np.array(x, dtype=float, copy=True)
    X = model.host["node_X"]
    slots = model.topology.boundary_slots
    a = X[slots]
    b = X[3 * (slots // 3) + (slots % 3 + 1) % 3]
    mid = 0.5 * (a + b)
    half = 0.5 * float(np.max(np.linalg.norm(b - a, axis=1)))
    tree = cKDTree(mid)
    keep = ~inside_elements(x, X)
    for _ in range(3 if snap > 0 else 1):
        moved = False
        near = tree.query_ball_point(x, r=clearance + half)
        for i, cand in enumerate(near):
            if not (cand and keep[i]):
                continue
            c = np.asarray(cand)
            q = nearest_on_segments(np.repeat(x[i:i + 1], len(c), 0), a[c], b[c])
            dist = np.linalg.norm(x[i] - q, axis=1)
            k = int(np.argmin(dist))
            if dist[k] >= clearance:
                continue
            if snap > 0 and dist[k] >= (1.0 - snap) * clearance and dist[k] > 0:
                x[i] = q[k] + (x[i] - q[k]) * (clearance / dist[k])
                moved = True
            else:
                keep[i] = False
        if not moved:
            break
    near = tree.query_ball_point(x, r=clearance + half)
    for i, cand in enumerate(near):
        if cand and keep[i]:
            c = np.asarray(cand)
            dist = segment_distance(np.repeat(x[i:i + 1], len(c), 0), a[c], b[c])
            keep[i] = bool(dist.min() >= clearance * (1.0 - 1e-9))
    keep &= ~inside_elements(x, X)
    removed = int((~keep).sum())
    total = float(vol.sum())
    x, vol = x[keep], vol[keep]
    if len(vol):
        vol = vol * (total / float(vol.sum()))
    if return_mask:
        return x, vol, removed, keep
    return x, vol, removed
