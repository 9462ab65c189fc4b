"""Plane shapes of the joint generator (geometry/joints.py): a rectangle/polygon or disc with the segment
operations the joints need (clipping, distances, point tests), and small polygon helpers."""

from __future__ import annotations

import math

import numpy as np

#: relative tolerance (of the domain size) for points on lines, merged points and on-boundary tests
REL_TOL = 1e-9


class Shape:
    """A rectangle/polygon (vertices, counter-clockwise) or a disc, with the segment operations the joints need."""

    def __init__(self, domain):
        t = getattr(domain, "type", None)
        if t == "disc":
            self.kind = "disc"
            self.center = np.asarray(domain.center, float)
            self.radius = float(domain.radius)
            lo, hi = self.center - self.radius, self.center + self.radius
        else:
            self.kind = "poly"
            v = np.asarray(domain.polygon, float)
            if _signed_area(v) < 0:
                v = v[::-1]
            self.v = v
            lo, hi = v.min(axis=0), v.max(axis=0)
        self.lo, self.hi = lo, hi
        self.scale = float(np.max(hi - lo))
        self.tol = REL_TOL * self.scale

    @property
    def area(self) -> float:
        return math.pi * self.radius**2 if self.kind == "disc" else _signed_area(self.v)

    def contains(self, pts: np.ndarray) -> np.ndarray:
        pts = np.atleast_2d(pts)
        if self.kind == "disc":
            return np.linalg.norm(pts - self.center, axis=1) < self.radius
        return _points_in_polygon(pts, self.v)

    def boundary_distance(self, pts: np.ndarray) -> np.ndarray:
        pts = np.atleast_2d(pts)
        if self.kind == "disc":
            return np.abs(np.linalg.norm(pts - self.center, axis=1) - self.radius)
        a, b = self.v, np.roll(self.v, -1, axis=0)
        return np.min(_point_seg_dist(pts[:, None, :], a[None], b[None]), axis=1)

    def crossings(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Parameters t ∈ [0, 1] at which the segment p→q meets the boundary."""
        d = q - p
        if self.kind == "disc":
            f = p - self.center
            a, b, c = d @ d, 2 * f @ d, f @ f - self.radius**2
            disc = b * b - 4 * a * c
            if disc <= 0 or a == 0:
                return np.zeros(0)
            s = math.sqrt(disc)
            t = np.array([(-b - s) / (2 * a), (-b + s) / (2 * a)])
            return t[(t >= 0) & (t <= 1)]
        a, b = self.v, np.roll(self.v, -1, axis=0)
        e = b - a
        den = d[0] * e[:, 1] - d[1] * e[:, 0]
        ok = np.abs(den) > 1e-300
        w = a - p
        t = np.where(ok, (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / np.where(ok, den, 1.0), -1.0)
        u = np.where(ok, (w[:, 0] * d[1] - w[:, 1] * d[0]) / np.where(ok, den, 1.0), -1.0)
        eps = 1e-12
        hit = ok & (t >= -eps) & (t <= 1 + eps) & (u >= -eps) & (u <= 1 + eps)
        return np.clip(t[hit], 0.0, 1.0)

    def clip(self, p: np.ndarray, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """The pieces of p→q inside the shape (pieces along the boundary are dropped)."""
        L = float(np.linalg.norm(q - p))
        if L == 0.0:
            return []
        ts = np.unique(np.concatenate([[0.0, 1.0], self.crossings(p, q)]))
        keep = []
        for t0, t1 in zip(ts[:-1], ts[1:]):
            if (t1 - t0) * L <= self.tol:
                continue
            m = p + 0.5 * (t0 + t1) * (q - p)
            if self.boundary_distance(m[None])[0] <= self.tol:
                continue                                   # along the boundary
            if self.contains(m[None])[0]:
                if keep and abs(keep[-1][1] - t0) * L <= self.tol:
                    keep[-1] = (keep[-1][0], t1)
                else:
                    keep.append((t0, t1))
        return [(p + t0 * (q - p), p + t1 * (q - p)) for t0, t1 in keep]

    def along_boundary(self, p: np.ndarray, q: np.ndarray) -> bool:
        """True when a stretch of p→q longer than the tolerance runs along the boundary."""
        ts = np.unique(np.concatenate([[0.0, 1.0], self.crossings(p, q)]))
        L = float(np.linalg.norm(q - p))
        for t0, t1 in zip(ts[:-1], ts[1:]):
            if (t1 - t0) * L > self.tol and self.boundary_distance((p + 0.5 * (t0 + t1) * (q - p))[None])[0] <= self.tol:
                return True
        return False

    def ray_hit(self, p: np.ndarray, u: np.ndarray, reach: float) -> float | None:
        """Distance along the unit direction u from p to the boundary, if within ``reach``."""
        t = self.crossings(p, p + reach * u)
        t = t[t * reach > self.tol]
        return float(t.min() * reach) if len(t) else None

    def tangent(self, pt: np.ndarray) -> np.ndarray:
        """Unit tangent of the boundary at (or nearest to) a boundary point."""
        if self.kind == "disc":
            r = pt - self.center
            return np.array([-r[1], r[0]]) / np.linalg.norm(r)
        a, b = self.v, np.roll(self.v, -1, axis=0)
        k = int(np.argmin(_point_seg_dist(pt[None, None, :], a[None], b[None])[0]))
        e = b[k] - a[k]
        return e / np.linalg.norm(e)

    def corner_distance(self, pt: np.ndarray) -> float:
        if self.kind == "disc":
            return math.inf
        return float(np.min(np.linalg.norm(self.v - pt, axis=1)))


def _signed_area(v: np.ndarray) -> float:
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _points_in_polygon(pts: np.ndarray, v: np.ndarray) -> np.ndarray:
    x, y = pts[:, 0], pts[:, 1]
    inside = np.zeros(len(pts), bool)
    for (x1, y1), (x2, y2) in zip(v, np.roll(v, -1, axis=0)):
        if y1 == y2:
            continue
        cross = (y1 > y) != (y2 > y)
        xi = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
        inside ^= cross & (x < xi)
    return inside


def _point_seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points p to segments a→b (broadcast over the leading axes)."""
    ab = b - a
    ll = np.sum(ab * ab, axis=-1)
    t = np.clip(np.sum((p - a) * ab, axis=-1) / np.where(ll > 0, ll, 1.0), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def subtract_disc(p: np.ndarray, q: np.ndarray, c: np.ndarray, r: float, tol: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The pieces of p→q outside the disc (c, r)."""
    d, f = q - p, p - c
    a, b, cc = d @ d, 2 * f @ d, f @ f - r * r
    disc = b * b - 4 * a * cc
    if a == 0 or disc <= 0:
        return [(p, q)]
    s = math.sqrt(disc)
    t0, t1 = (-b - s) / (2 * a), (-b + s) / (2 * a)
    L = math.sqrt(a)
    out = []
    if t0 > 0:
        out.append((0.0, min(t0, 1.0)))
    if t1 < 1:
        out.append((max(t1, 0.0), 1.0))
    return [(p + u0 * d, p + u1 * d) for u0, u1 in out if (u1 - u0) * L > tol]
