"""NumPy checks for block-contact tests: interpenetration of blocks and the leapfrog energy.

Independent of the contact kernel: geometry only, from node positions and the topology.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def element_heights(x: np.ndarray) -> np.ndarray:
    """Smallest height 2A/L_max of every element [m] (x: node positions [3E, 2], counter-clockwise)."""
    p0, p1, p2 = x[0::3], x[1::3], x[2::3]
    area = 0.5 * np.abs((p1 - p0)[:, 0] * (p2 - p0)[:, 1] - (p1 - p0)[:, 1] * (p2 - p0)[:, 0])
    lmax = np.max([np.linalg.norm(p1 - p0, axis=1), np.linalg.norm(p2 - p1, axis=1),
                   np.linalg.norm(p0 - p2, axis=1)], axis=0)
    return 2.0 * area / lmax


def penetration(x: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """For every node, the depth [m] of the deepest element other than its own that contains it (the distance
    to that element's nearest edge; 0 outside all) and that element (−1 if none).

    x: node positions [3E, 2] (node 3e+k is vertex k of element e, counter-clockwise); reach: largest distance
    from a node to the centroid of an element that can contain it (the longest edge will do).
    """
    p0, p1, p2 = x[0::3], x[1::3], x[2::3]
    tree = cKDTree((p0 + p1 + p2) / 3.0)
    near = tree.query_ball_point(x, r=reach)
    nid = np.repeat(np.arange(len(x)), [len(c) for c in near])
    eid = np.concatenate([np.asarray(c, dtype=np.int64) for c in near])
    keep = eid != nid // 3
    nid, eid = nid[keep], eid[keep]
    gmax = np.full(len(nid), -np.inf)
    for a, b in ((p0, p1), (p1, p2), (p2, p0)):
        d = b[eid] - a[eid]
        r = x[nid] - a[eid]
        g = (r[:, 0] * d[:, 1] - r[:, 1] * d[:, 0]) / np.linalg.norm(d, axis=1)   # outward signed distance
        gmax = np.maximum(gmax, g)
    dep = np.where(gmax < 0.0, -gmax, 0.0)
    depth = np.zeros(len(x))
    host = np.full(len(x), -1)
    order = np.argsort(dep)                                  # the deepest host of a node is written last
    depth[nid[order]] = dep[order]
    host[nid[order]] = np.where(dep[order] > 0.0, eid[order], -1)
    return depth, host


def relative_penetration(x: np.ndarray, reach: float) -> np.ndarray:
    """Per node: penetration depth divided by the height of the element it is in (0 outside)."""
    depth, host = penetration(x, reach)
    h = element_heights(x)
    return np.where(host >= 0, depth / h[np.maximum(host, 0)], 0.0)


def leapfrog_kinetic(mass: np.ndarray, v_before: np.ndarray, v_after: np.ndarray, theta: float = 0.0) -> float:
    """½ v^{n−½}ᵀ M v^{n+½} [J/m]: with the strain energy at step n this is the energy the central-difference
    scheme conserves exactly for a linear system (½vᵀMv of one half step alone oscillates with Δt).

    M is the block mass matrix m[(1 − 3θ/4)I + (θ/4)J] per element (m = ρA/3 the node mass, θ the
    consistent-mass fraction: 0 lumped, ½ averaged), written out here from its definition.
    """
    m = mass[0::3]
    a, b = m * (1.0 - 0.75 * theta), m * 0.25 * theta
    dot = np.einsum("ij,ij->i", v_before, v_after).reshape(-1, 3).sum(axis=1)
    s0, s1 = v_before.reshape(-1, 3, 2).sum(axis=1), v_after.reshape(-1, 3, 2).sum(axis=1)
    return float(0.5 * np.sum(a * dot + b * np.einsum("ij,ij->i", s0, s1)))
