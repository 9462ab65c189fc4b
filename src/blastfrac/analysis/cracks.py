"""Crack statistics around a borehole: crushed-zone radius, radial crack count and lengths.

Definitions (documented in docs/results.md). Positions are those of the reference configuration; an
interface is *cracked* when at least one of its two springs has broken, and r is the distance of a point
from the hole centre.

* **Ring width w**: the median length of the interfaces within 2 r_b of the centre (the mesh size at the wall).
* **Crushed-zone radius r_c**: the outer radius of the run of consecutive rings [r_b + k·w, r_b + (k+1)·w),
  starting at the wall, in which at least half of the interfaces are cracked (r_c = r_b when the first ring
  is below one half). It is the radius within which most springs have broken.
* **Crack crossings of a circle** of radius R about the centre: the points where cracked interfaces cross
  the circle, grouped by angle; two neighbouring crossings less than ``MERGE_GAP``·h apart along the circle
  belong to the same crack (a crack zig-zags along element edges and can cross a circle several times), h
  being the mesh size along that circle (median length of the interfaces it crosses). A group whose arc is
  at most ``NARROW_ARC``·h long is one *crack crossing*; wider groups are shattered or tangential
  (spalling) zones, not single cracks, and are reported apart (``shattered_arc``).
* **N(R)**: the number of crack crossings of the circle R, sampled every w from r_c + 2w outward, for all
  cracks and for tensile ones (an interface counts as tensile when a spring broke in tension). Crossings
  of neighbouring circles are linked into radial chains, and only crossings on chains at least
  ``MIN_EXTENT``·h long count (a crack is at least three elements long; this drops the ragged fringe of
  crushed and spalled zones).
* **Radial crack count** N_rad = max over R of N(R): every radial crack crosses each circle between its
  start and its tip, so the circle crossed by most cracks counts all the cracks that coexist at one radius.
  Unlike a count of connected crack sets, this does not collapse a network whose cracks meet in the
  crushed zone into one crack.
* **Radial crack lengths**: the k-th longest crack reaches R_k = max{R : N(R) ≥ k}; its length is
  R_k − r_c (measured from the edge of the crushed zone), for k = 1 … N_rad.
"""

from __future__ import annotations

import numpy as np

#: crossings closer than this many ring widths along the circle belong to one crack [-]
MERGE_GAP = 1.0
#: a group of crossings longer than this many ring widths along the circle is not a single crack [-]
NARROW_ARC = 3.0
#: a chain of crossings shorter than this many local mesh sizes is the ragged edge of a zone, not a crack [-]
MIN_EXTENT = 3.0


def circle_crossings(a: np.ndarray, b: np.ndarray, center: np.ndarray, R: float) -> np.ndarray:
    """Polar angles [rad] at which the segments a→b [n,2] (m) cross the circle of radius R [m] about ``center``."""
    ra = np.linalg.norm(a - center, axis=1)
    rb = np.linalg.norm(b - center, axis=1)
    hit = ((ra - R) * (rb - R) <= 0.0) & (ra != rb)
    if not hit.any():
        return np.zeros(0)
    a, b, ra, rb = a[hit], b[hit], ra[hit], rb[hit]
    # the crossing point: solve |a + t(b − a) − c| = R for t in [0, 1]
    d, p = b - a, a - center
    qa = np.einsum("ij,ij->i", d, d)
    qb = 2.0 * np.einsum("ij,ij->i", p, d)
    qc = ra**2 - R**2
    disc = np.sqrt(np.maximum(qb**2 - 4 * qa * qc, 0.0))
    t1, t2 = (-qb - disc) / (2 * qa), (-qb + disc) / (2 * qa)
    t = np.where((t1 >= -1e-12) & (t1 <= 1 + 1e-12), t1, t2)
    q = p + np.clip(t, 0.0, 1.0)[:, None] * d
    return np.arctan2(q[:, 1], q[:, 0])


def group_crossings(theta: np.ndarray, R: float, w: float) -> list[tuple[float, float, int]]:
    """Groups of crossing angles on the circle R: (mid angle [rad], arc length [m], crossings) per group."""
    if len(theta) == 0:
        return []
    th = np.sort(np.mod(theta, 2 * np.pi))
    gaps = np.diff(np.concatenate([th, th[:1] + 2 * np.pi])) * R      # gap after each crossing, circular
    cut = np.flatnonzero(gaps > MERGE_GAP * w)
    if len(cut) == 0:                                                  # one group all round
        return [(0.0, 2 * np.pi * R, len(th))]
    groups = []
    start = (cut[-1] + 1) % len(th)                                    # a group starts after each large gap
    for c in cut:
        idx = np.arange(start, c + 1) if c >= start else np.concatenate([np.arange(start, len(th)), np.arange(c + 1)])
        t0, t1 = th[idx[0]], th[idx[-1]]
        span = (t1 - t0) % (2 * np.pi)
        groups.append((float(np.mod(t0 + 0.5 * span, 2 * np.pi)), float(span * R), len(idx)))
        start = (c + 1) % len(th)
    return groups


def local_mesh_size(a: np.ndarray, b: np.ndarray, center: np.ndarray, R: float) -> float:
    """Median length [m] of the interfaces a→b that cross the circle R (the mesh size along that circle)."""
    ra = np.linalg.norm(a - center, axis=1)
    rb = np.linalg.norm(b - center, axis=1)
    hit = (ra - R) * (rb - R) <= 0.0
    return float(np.median(np.linalg.norm(b[hit] - a[hit], axis=1))) if hit.any() else 0.0


def crossing_profile(a, b, cracked, tensile, center, radii) -> dict:
    """N(R) of the cracked interfaces a→b and of the tensile ones, and the shattered arc length [m], at each radius.

    ``cracked``, ``tensile``: masks over all interfaces; the merge gap and the narrow-arc limit scale with the
    mesh size along each circle, so that a crack through coarse elements is not split into several. Narrow
    crossings are linked into radial chains (:func:`persistent_counts`); only chains at least
    ``MIN_EXTENT`` local mesh sizes long count, which drops the ragged fringe of shattered zones.
    """
    narrow_all, narrow_ten, shattered, sizes = [], [], [], []
    for R in radii:
        w = local_mesh_size(a, b, center, R)
        g_all = group_crossings(circle_crossings(a[cracked], b[cracked], center, R), R, w)
        g_ten = group_crossings(circle_crossings(a[tensile], b[tensile], center, R), R, w)
        narrow_all.append([g[0] for g in g_all if g[1] <= NARROW_ARC * w])
        narrow_ten.append([g[0] for g in g_ten if g[1] <= NARROW_ARC * w])
        shattered.append(sum(g[1] for g in g_all if g[1] > NARROW_ARC * w))
        sizes.append(w)
    return {"radius": [float(r) for r in radii],
            "count": persistent_counts(radii, narrow_all, sizes),
            "count_tensile": persistent_counts(radii, narrow_ten, sizes),
            "shattered_arc": [float(s) for s in shattered], "mesh_size": sizes}


def persistent_counts(radii, angles: list[list[float]], sizes: list[float]) -> list[int]:
    """Crack crossings per circle that belong to a radial chain at least ``MIN_EXTENT``·h long.

    A crossing on circle i+1 continues the nearest crossing of circle i within ``MERGE_GAP``·h along the
    circle (h: the local mesh size); a crossing with no predecessor starts a chain, and a branch (a second
    crossing continuing the same predecessor) starts a chain at its parent's start radius.
    """
    chain_of: list[np.ndarray] = []           # chain id of each crossing, per circle
    start, end = [], []                       # per chain: first and last radius
    for i, (R, th) in enumerate(zip(radii, angles)):
        th = np.asarray(th, float)
        ids = np.full(len(th), -1, int)
        if i > 0 and len(th) and len(angles[i - 1]):
            prev = np.asarray(angles[i - 1], float)
            tol = MERGE_GAP * max(sizes[i], sizes[i - 1]) / R
            d = np.abs((th[:, None] - prev[None, :] + np.pi) % (2 * np.pi) - np.pi)
            used = set()
            for j in np.argsort(d.min(axis=1)):
                k = int(np.argmin(d[j]))
                if d[j, k] > tol:
                    continue
                parent = int(chain_of[i - 1][k])
                if k in used:                             # a branch: a new chain from the parent's start
                    start.append(start[parent])
                    end.append(R)
                    ids[j] = len(start) - 1
                else:
                    used.add(k)
                    ids[j] = parent
                    end[parent] = R
        for j in np.flatnonzero(ids < 0):
            start.append(R)
            end.append(R)
            ids[j] = len(start) - 1
        chain_of.append(ids)
    extent = np.asarray(end) - np.asarray(start) if start else np.zeros(0)
    counts = []
    for i, ids in enumerate(chain_of):
        counts.append(int(np.sum(extent[ids] >= MIN_EXTENT * sizes[i])) if len(ids) else 0)
    return counts


def lengths_from_profile(radii: np.ndarray, counts: np.ndarray, r_c: float) -> list[float]:
    """Crack lengths R_k − r_c [m], longest first, with R_k = max{R : N(R) ≥ k}, k = 1 … max N."""
    radii, counts = np.asarray(radii, float), np.asarray(counts, int)
    out = []
    for k in range(1, int(counts.max(initial=0)) + 1):
        out.append(float(radii[counts >= k].max() - r_c))
    return out


def crack_statistics(model, mode: np.ndarray, center: np.ndarray, r_b: float) -> dict:
    """Statistics of the cracks around the hole at ``center`` [m] of radius ``r_b`` [m] (SI units)."""
    topo = model.topology
    X = model.host["node_X"]
    pn = topo.pair_nodes
    a = X[pn[0::2, 0]]                      # the two ends of each interface (side e1)
    b = X[pn[1::2, 0]]
    mid = 0.5 * (a + b)
    r = np.linalg.norm(mid - center, axis=1)
    L = np.linalg.norm(b - a, axis=1)
    pair_mode = mode.reshape(-1, 2)
    cracked = (pair_mode > 0).any(axis=1)
    tensile = (pair_mode == 1).any(axis=1)
    near = r < 2.0 * r_b
    w = float(np.median(L[near])) if near.any() else float(np.median(L))
    # crushed zone: consecutive rings from the wall with at least half of the interfaces cracked
    r_c, k = r_b, 0
    while True:
        ring = (r >= r_b + k * w) & (r < r_b + (k + 1) * w)
        if ring.sum() == 0 or cracked[ring].mean() < 0.5:
            break
        k += 1
        r_c = r_b + k * w
    # crack crossings of circles outside the crushed zone
    r_max = float(np.linalg.norm(np.concatenate([a, b]) - center, axis=1).max())
    radii = np.arange(r_c + 2 * w, r_max, w)
    if len(radii) > 400:                     # keep the profile short on big meshes
        radii = np.linspace(radii[0], radii[-1], 400)
    prof = crossing_profile(a, b, cracked, tensile, center, radii)
    counts = np.asarray(prof["count"], int)
    lengths = lengths_from_profile(radii, counts, r_c)
    n_rad = int(counts.max(initial=0))
    r_at = float(radii[int(np.argmax(counts))]) if len(radii) else r_c
    return {
        "center": [float(center[0]), float(center[1])],
        "borehole_radius": r_b,
        "ring_width": w,
        "crushed_zone_radius": r_c,
        "crushed_zone_radius_over_rb": r_c / r_b,
        "radial_crack_count": n_rad,
        "radial_crack_count_radius": r_at,
        "radial_crack_count_tensile": int(max(prof["count_tensile"], default=0)),
        "radial_crack_lengths": lengths,
        "longest_radial_crack": max(lengths) if lengths else 0.0,
        "mean_radial_crack_length": float(np.mean(lengths)) if lengths else 0.0,
        "crossings": prof,
    }
