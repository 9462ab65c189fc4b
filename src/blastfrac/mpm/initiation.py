"""Lighting times per explosive body: a detonation travels through explosive only (METHOD §2.4; issue 15).

A detonation point or line lights the charges it lies in or touches, and the detonation runs from there
through the explosive at D, never through rock or air. Charges whose material points touch (within 1.5
point spacings) form one *body*: a detonation crosses from one to the other, as it does between primed and
column charges in contact. A body whose initiators all lie in no part of it does not light by time; its
points can still burn by compression (the volumetric burn).

Within a body the lighting time of a point X from an initiator is

* from a point: the straight-line time |X − x_d|/D + t_d when the body is one convex charge (a circle or a
  convex polygon), which is exact; otherwise (several charges, a non-convex polygon) the shortest path through
  the body's points (Dijkstra on the graph joining points closer than 4 spacings, weighted by distance, from
  the initiator to the points around it), which never cuts a corner of rock and runs a little longer than the
  geodesic (tests/unit/test_initiation.py);
* from a line: the cord formula of :func:`burn.line_lighting_times`, over the bodies the line touches
  (straight lines from the cord: a cord through a non-convex body may light a point across a notch early).

With no initiator in the scenario each charge lights at its own area centroid (the former default), each only
its own body.
"""

from __future__ import annotations

import numpy as np

from .burn import line_lighting_times

TOUCH_SPACINGS = 1.5     # points of two charges closer than this many spacings join their bodies
GRAPH_SPACINGS = 4.0     # neighbour radius of the shortest-path graph, in spacings (metric error ≈ 1 %)


def _spacing(vol: np.ndarray) -> float:
    return float(np.sqrt(np.median(vol))) if len(vol) else 0.0


def charge_bodies(x: np.ndarray, vol: np.ndarray, cid: np.ndarray, n_charges: int) -> np.ndarray:
    """Body label of each charge [n_charges]: connected components of 'the points of i and j touch'."""
    from scipy.cluster.hierarchy import DisjointSet
    from scipy.spatial import cKDTree

    ds = DisjointSet(range(n_charges))
    if len(x) and n_charges > 1:
        h = _spacing(vol)
        for i, j in cKDTree(x).query_pairs(TOUCH_SPACINGS * h, output_type="ndarray"):
            if cid[i] != cid[j]:
                ds.merge(int(cid[i]), int(cid[j]))
    roots = {r: k for k, r in enumerate(sorted({ds[c] for c in range(n_charges)}))}
    return np.array([roots[ds[c]] for c in range(n_charges)], dtype=np.int64)


def _convex_charge(ch) -> bool:
    if ch.kind == "circle":
        return True
    v = np.asarray(ch.vertices, float)
    e = np.roll(v, -1, axis=0) - v
    cr = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
    return bool(np.all(cr >= -1e-12 * np.abs(cr).max()) or np.all(cr <= 1e-12 * np.abs(cr).max()))


def _path_lengths(xb: np.ndarray, h: float, seeds: np.ndarray, seed_len: np.ndarray) -> np.ndarray:
    """Shortest path [m] through the points xb from a virtual source joined to ``seeds`` with ``seed_len``."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra
    from scipy.spatial import cKDTree

    n = len(xb)
    pairs = cKDTree(xb).query_pairs(GRAPH_SPACINGS * h, output_type="ndarray")
    w = np.linalg.norm(xb[pairs[:, 0]] - xb[pairs[:, 1]], axis=1) if len(pairs) else np.zeros(0)
    rows = np.r_[pairs[:, 0], np.full(len(seeds), n)] if len(pairs) else np.full(len(seeds), n)
    cols = np.r_[pairs[:, 1], seeds] if len(pairs) else seeds
    vals = np.r_[w, np.maximum(seed_len, 1e-300)]
    g = coo_matrix((vals, (rows, cols)), shape=(n + 1, n + 1)).tocsr()
    return dijkstra(g, directed=False, indices=n)[:n]


def body_lighting_times(x: np.ndarray, vol: np.ndarray, cid: np.ndarray, charges, points, point_delays,
                        lines, D: float) -> np.ndarray:
    """t_l [s] of each point (initial positions x [n,2] m, areas vol [n] m², charge index cid [n]).

    charges: the scenario's charges (``contains``, ``meets_segment``, ``kind``); points [k,2] m with delays [k] s;
    lines: DetonationLine items (start, end, delay, velocity or None = D, simultaneous: the whole line at delay);
    D [m/s]. Points of a body that no
    initiator reaches get +inf.
    """
    x = np.asarray(x, float).reshape(-1, 2)
    vol = np.asarray(vol, float).reshape(-1)
    cid = np.asarray(cid, np.int64).reshape(-1)
    n_ch = len(charges)
    t = np.full(len(x), np.inf)
    if len(x) == 0:
        return t
    body = charge_bodies(x, vol, cid, n_ch)
    pbody = body[cid]
    h = _spacing(vol)
    single_convex = {b: (np.sum(body == b) == 1 and _convex_charge(charges[int(np.flatnonzero(body == b)[0])]))
                     for b in np.unique(body)}
    points = np.asarray(points, float).reshape(-1, 2)
    point_delays = np.asarray(point_delays, float).reshape(-1)
    for p, delay in zip(points, point_delays):
        hit = {int(body[k]) for k, ch in enumerate(charges) if ch.contains(tuple(p))}
        for b in hit:
            sel = np.flatnonzero(pbody == b)
            if single_convex[b]:
                tb = delay + np.linalg.norm(x[sel] - p, axis=1) / D
            else:
                d = np.linalg.norm(x[sel] - p, axis=1)
                seeds = np.flatnonzero(d <= max(GRAPH_SPACINGS * h, d.min() * (1 + 1e-9)))
                tb = delay + _path_lengths(x[sel], h, seeds, d[seeds]) / D
            t[sel] = np.minimum(t[sel], tb)
    for dl in lines:
        vel = np.inf if getattr(dl, "simultaneous", False) else (dl.velocity if dl.velocity is not None else D)
        hit = {int(body[k]) for k, ch in enumerate(charges) if ch.meets_segment(dl.start, dl.end)}
        for b in hit:
            sel = np.flatnonzero(pbody == b)
            t[sel] = np.minimum(t[sel], line_lighting_times(x[sel], dl.start, dl.end, dl.delay, vel, D))
    return t
