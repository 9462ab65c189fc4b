"""Plane geometry for the scenario's consistency checks (pure Python and numpy, no mesher, no Warp).

Points are (x, y) tuples [m]; polygons are vertex lists in either orientation.
"""

from __future__ import annotations

import math

import numpy as np

Point = tuple[float, float]


def polygon_area(v) -> float:
    """Signed area [m²] (positive when counter-clockwise)."""
    n = len(v)
    return 0.5 * sum(v[i][0] * v[(i + 1) % n][1] - v[(i + 1) % n][0] * v[i][1] for i in range(n))


def polygon_centroid(v) -> Point:
    a = polygon_area(v)
    n = len(v)
    cx = cy = 0.0
    for i in range(n):
        (x1, y1), (x2, y2) = v[i], v[(i + 1) % n]
        cr = x1 * y2 - x2 * y1
        cx += (x1 + x2) * cr
        cy += (y1 + y2) * cr
    return (cx / (6 * a), cy / (6 * a))


def seg_dist(p: Point, a: Point, b: Point) -> float:
    ax, ay = b[0] - a[0], b[1] - a[1]
    ll = ax * ax + ay * ay
    t = 0.0 if ll == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / ll))
    return math.dist(p, (a[0] + t * ax, a[1] + t * ay))


def _orient(a: Point, b: Point, c: Point) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def segments_cross(a: Point, b: Point, c: Point, d: Point) -> bool:
    """True when segments ab and cd cross at a point interior to both (touching ends do not count)."""
    d1, d2, d3, d4 = _orient(c, d, a), _orient(c, d, b), _orient(a, b, c), _orient(a, b, d)
    return d1 * d2 < 0 and d3 * d4 < 0


def segments_touch(a: Point, b: Point, c: Point, d: Point) -> bool:
    """True when segments ab and cd share any point (crossing, touching or overlapping)."""
    if segments_cross(a, b, c, d):
        return True
    scale = max(math.dist(a, b), math.dist(c, d), 1e-300)
    tol = 1e-12 * scale
    return min(seg_dist(a, c, d), seg_dist(b, c, d), seg_dist(c, a, b), seg_dist(d, a, b)) <= tol


def polygon_self_intersection(v) -> tuple[int, int] | None:
    """Indices (i, j) of two non-adjacent edges that meet, or None for a simple polygon."""
    n = len(v)
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):
                continue                                 # adjacent edges share a vertex
            if segments_touch(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]):
                return i, j
    return None


def repeated_vertex(v) -> tuple[int, int] | None:
    """Indices (i, j), i < j, of two equal vertices, or None."""
    seen: dict[tuple[float, float], int] = {}
    for j, p in enumerate(v):
        key = (float(p[0]), float(p[1]))
        if key in seen:
            return seen[key], j
        seen[key] = j
    return None


def point_in_polygon(p: Point, v) -> bool:
    inside, n = False, len(v)
    for i in range(n):
        (x1, y1), (x2, y2) = v[i], v[(i + 1) % n]
        if (y1 > p[1]) != (y2 > p[1]) and p[0] < (x2 - x1) * (p[1] - y1) / (y2 - y1) + x1:
            inside = not inside
    return inside


def polygon_dist(p: Point, v) -> float:
    """Distance from p to the polygon's boundary [m]."""
    n = len(v)
    return min(seg_dist(p, v[i], v[(i + 1) % n]) for i in range(n))


def points_in_polygon(pts: np.ndarray, v) -> np.ndarray:
    """Even-odd test of many points [n, 2] (vectorised)."""
    x, y = pts[:, 0], pts[:, 1]
    inside = np.zeros(len(pts), bool)
    n = len(v)
    for i in range(n):
        (x1, y1), (x2, y2) = v[i], v[(i + 1) % n]
        if y1 == y2:
            continue
        cross = (y1 > y) != (y2 > y)
        xi = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
        inside ^= cross & (x < xi)
    return inside


def polygons_overlap(p, q, tol: float) -> bool:
    """True when two simple polygons share interior area (touching along edges or at vertices is allowed).

    Crossing edges, a vertex of one deeper than ``tol`` inside the other, or one centroid inside the other.
    """
    n, m = len(p), len(q)
    for i in range(n):
        for j in range(m):
            if segments_cross(p[i], p[(i + 1) % n], q[j], q[(j + 1) % m]):
                return True
    for a, b in ((p, q), (q, p)):
        for x in a:
            if point_in_polygon(x, b) and polygon_dist(x, b) > tol:
                return True
        c = polygon_centroid(a)
        if point_in_polygon(c, b) and polygon_dist(c, b) > tol:
            return True
    return False
