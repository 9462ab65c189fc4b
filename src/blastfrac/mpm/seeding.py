"""Material-point seeding of charge regions (circles, polygons; any number).

Two layouts, both with point spacing s = h/ppc (``ppc`` points per cell per direction):

* ``lattice``: points on a regular sub-lattice of the grid, at the sub-cell centres. Each point
  starts with volume s^2 [m^2 per unit thickness]; with ``exact_area`` the volumes of a charge are
  scaled so that they add up to the charge's exact area (mass and chemical energy per unit
  thickness are then exact).  Along a curved boundary the lattice leaves a ragged void up to one
  spacing wide between the outermost points and the circle.
* ``conformal`` (circles only; polygons fall back to the lattice): concentric rings of width s
  laid from the circle inwards around a small core; each ring holds round(2π r_m/s) points of
  equal volume (the ring's area shared out, so the charge area is exact) at its mid radius r_m,
  every other ring rotated by half a pitch.  A point's radius ½√V_p is then s/2, so the outer
  ring touches the circle: a charge that fills a borehole leaves no void at its wall (a void lets
  the products accelerate across it and strike the wall well above their pressure).

A point belongs to the first charge containing it (later charges drop the points that fall inside
earlier ones).

**Charges cut by symmetry lines** (half and quarter models, ``geometry.symmetry``): a charge that carries
``cuts`` (:class:`CutCharge`, or a dict with a ``"cuts"`` list of :class:`Cut`) is seeded only on the modelled
side of each line; its area is the clipped area (exact: a polygon clipped by the half-planes, a disc intersected
with them in closed form). A point on a line holds half its share (a quarter on two lines): the grid's slip wall
there is an image wall (mpm/grid.py), through which the point and its mirror image count once. A circle centred
on its cut lines is laid on rings of an even number of points (and an even core), which are symmetric about both
axes through the centre, so the half (quarter) seeding is exactly the part of a symmetric full seeding on the
modelled side and its area is exact by symmetry; an off-centre cut keeps the plain rings (or lattice) on its side,
scaled to the clipped area. The charge keeps its whole centroid as its default initiation point (the hole's
centre, on the line), :func:`charge_area_centroid`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np


class Cut(NamedTuple):
    """A symmetry line x_axis = coord [m]; the modelled part is where sign·(x_axis − coord) ≤ 0 (sign −1: the line
    is the part's left or bottom side, +1: its right or top side)."""

    axis: int
    coord: float
    sign: int

    @property
    def side(self) -> str:
        return (("left", "right"), ("bottom", "top"))[self.axis][self.sign > 0]

    def beyond(self, pts) -> np.ndarray:
        """Signed distance [m] of points [n,2] beyond the line (> 0: cut off, 0: on it)."""
        return self.sign * (np.atleast_2d(np.asarray(pts, float))[:, self.axis] - self.coord)


def charge_cuts(charge) -> list[Cut]:
    """The symmetry cuts a charge (CutCharge, pydantic model or dict) carries; [] for a whole charge."""
    d = charge.model_dump() if hasattr(charge, "model_dump") else dict(charge)
    return [Cut(int(a), float(c), int(sg)) for a, c, sg in d.get("cuts") or ()]


def symmetry_cuts(charges) -> list[Cut]:
    """The symmetry lines of a half or quarter model: the union of its charges' cuts, in order."""
    out: list[Cut] = []
    for ch in charges:
        for c in charge_cuts(ch):
            if c not in out:
                out.append(c)
    return out


class CutCharge:
    """The part of a scenario charge (CircleCharge or PolygonCharge) on the modelled side of symmetry lines.

    Every other attribute (kind, center, radius, vertices, gas_state) is the whole charge's. ``area`` and ``bbox``
    are the clipped ones; ``contains`` and ``meets_segment`` test the clipped region (tolerance as the charge's).
    """

    def __init__(self, charge, cuts):
        self.charge = charge
        self.cuts = tuple(Cut(*c) for c in cuts)

    def __getattr__(self, name):
        if name in ("charge", "cuts") or name.startswith("__"):
            raise AttributeError(name)
        return getattr(self.charge, name)

    def model_dump(self, **kw) -> dict:
        return {**self.charge.model_dump(**kw), "cuts": [tuple(c) for c in self.cuts]}

    @property
    def area(self) -> float:
        return charge_area_centroid(self)[0]

    @property
    def bbox(self):
        lo, hi = charge_bbox(self)
        return (float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1]))

    def _size(self) -> float:
        (a0, b0), (a1, b1) = self.charge.bbox
        return max(a1 - a0, b1 - b0)

    def contains(self, p, tol: float = 1e-9) -> bool:
        return self.charge.contains(p, tol) and all(c.beyond(p)[0] <= tol * self._size() for c in self.cuts)

    def meets_segment(self, a, b, tol: float = 1e-9) -> bool:
        a, b = np.asarray(a, float), np.asarray(b, float)
        t0, t1 = 0.0, 1.0                                 # the part of a→b on the modelled side
        for c in self.cuts:
            fa, fb = c.beyond(a)[0] - tol * self._size(), c.beyond(b)[0] - tol * self._size()
            if fa > 0 and fb > 0:
                return False
            if fa > 0 or fb > 0:
                t = fa / (fa - fb)
                t0, t1 = (max(t0, t), t1) if fa > 0 else (t0, min(t1, t))
        if t1 < t0:
            return False
        return self.charge.meets_segment(tuple(a + t0 * (b - a)), tuple(a + t1 * (b - a)), tol)


def cut_charges(charges, lines) -> list[CutCharge]:
    """Each charge cut by the symmetry ``lines`` ((side, axis, coord, sign), GeometryConfig.symmetry_lines); every
    charge of a half or quarter model carries all its lines (the grid takes its walls from them)."""
    cuts = [Cut(axis, coord, sign) for _, axis, coord, sign in lines]
    return [CutCharge(ch, cuts) for ch in charges]


def fold_to_modelled_side(x: np.ndarray, cuts) -> np.ndarray:
    """Points [n,2] beyond a symmetry line reflected to their mirror image on the modelled side (through the image
    wall on the line a point and its image are the same material); a copy."""
    x = np.array(x, dtype=float, copy=True)
    for c in cuts:
        b = c.beyond(x)
        out = b > 0
        x[out, c.axis] -= 2.0 * c.sign * b[out]
    return x


def clip_polygon(verts, cuts) -> np.ndarray:
    """The polygon [k,2] clipped to the modelled side of each cut (Sutherland–Hodgman); [0,2] when nothing is left."""
    v = np.asarray(verts, float).reshape(-1, 2)
    for c in cuts:
        if not len(v):
            break
        f = c.beyond(v)
        out = []
        for i in range(len(v)):
            j = (i + 1) % len(v)
            if f[i] <= 0:
                out.append(v[i])
            if (f[i] < 0 < f[j]) or (f[j] < 0 < f[i]):
                t = f[i] / (f[i] - f[j])
                p = v[i] + t * (v[j] - v[i])
                p[c.axis] = c.coord
                out.append(p)
        v = np.asarray(out, float).reshape(-1, 2)
    return v


def _sector(r: float, u: np.ndarray, w: np.ndarray) -> float:
    return 0.5 * r * r * math.atan2(u[0] * w[1] - u[1] * w[0], u @ w)


def _disc_triangle_area(r: float, a: np.ndarray, b: np.ndarray) -> float:
    """Signed area of the disc (0, r) ∩ the triangle (0, a, b) [m²]."""
    da, db = math.hypot(*a), math.hypot(*b)
    if da <= r and db <= r:
        return 0.5 * float(a[0] * b[1] - a[1] * b[0])
    d = b - a
    qa, qb = float(d @ d), float(a @ d)
    disc = qb * qb - qa * (da * da - r * r)
    if qa == 0.0 or disc <= 0.0:
        return _sector(r, a, b)
    sq = math.sqrt(disc)
    t1, t2 = (-qb - sq) / qa, (-qb + sq) / qa
    if t2 <= 0.0 or t1 >= 1.0:
        return _sector(r, a, b)
    p1, p2 = a + max(t1, 0.0) * d, a + min(t2, 1.0) * d
    out = 0.5 * float(p1[0] * p2[1] - p1[1] * p2[0])
    if t1 > 0.0:
        out += _sector(r, a, p1)
    if t2 < 1.0:
        out += _sector(r, p2, b)
    return out


def disc_cut_area(center, radius: float, cuts) -> float:
    """Area [m²] of the disc on the modelled side of the cuts (closed form: disc ∩ convex polygon)."""
    c, r = np.asarray(center, float), float(radius)
    box = clip_polygon(c + 2.0 * r * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]), cuts)
    if len(box) < 3:
        return 0.0
    q = box - c
    return abs(sum(_disc_triangle_area(r, q[i], q[(i + 1) % len(q)]) for i in range(len(q))))


def points_in_polygon(pts: np.ndarray, verts: np.ndarray) -> np.ndarray:
    """Even-odd ray-casting test; pts [n,2], verts [k,2]; returns bool [n]."""
    x, y = pts[:, 0], pts[:, 1]
    inside = np.zeros(len(pts), dtype=bool)
    k = len(verts)
    for i in range(k):
        (x1, y1), (x2, y2) = verts[i], verts[(i + 1) % k]
        cross = (y1 > y) != (y2 > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
        inside ^= cross & (x < xi)
    return inside


def polygon_area_centroid(verts: np.ndarray) -> tuple[float, np.ndarray]:
    """Area [m^2] and centroid [m] of a simple polygon (shoelace)."""
    v = np.asarray(verts, dtype=np.float64)
    x, y = v[:, 0], v[:, 1]
    xs, ys = np.roll(x, -1), np.roll(y, -1)
    cr = x * ys - xs * y
    a = 0.5 * cr.sum()
    c = np.array([((x + xs) * cr).sum(), ((y + ys) * cr).sum()]) / (6.0 * a)
    return abs(a), c


def charge_geometry(charge) -> tuple[str, dict]:
    """Normalise a charge (pydantic model or dict) to (kind, params)."""
    d = charge.model_dump() if hasattr(charge, "model_dump") else dict(charge)
    return d["kind"], d


def charge_bbox(charge) -> tuple[np.ndarray, np.ndarray]:
    """Box (lo [2], hi [2]) [m] of the charge; of its part on the modelled side when it carries cuts."""
    kind, d = charge_geometry(charge)
    cuts = charge_cuts(d)
    if kind == "circle":
        c, r = np.asarray(d["center"], float), float(d["radius"])
        lo, hi = c - r, c + r
    else:
        v = clip_polygon(d["vertices"], cuts) if cuts else np.asarray(d["vertices"], float)
        if not len(v):
            v = np.asarray(d["vertices"], float)
        lo, hi = v.min(axis=0), v.max(axis=0)
    for ct in cuts:                                  # a circle's box is clamped at the lines (a cover, not tight)
        if ct.sign < 0:
            lo[ct.axis] = max(lo[ct.axis], ct.coord)
        else:
            hi[ct.axis] = min(hi[ct.axis], ct.coord)
    return lo, hi


def charge_area_centroid(charge) -> tuple[float, np.ndarray]:
    """(area [m²], centroid [m]) of the charge. A charge cut by symmetry lines has its clipped area and the centroid
    of the *whole* charge, its default initiation point: a hole's half charge lights at the hole's centre, on the
    line, as the full model does."""
    kind, d = charge_geometry(charge)
    cuts = charge_cuts(d)
    if kind == "circle":
        area = disc_cut_area(d["center"], d["radius"], cuts) if cuts else float(np.pi * d["radius"] ** 2)
        return area, np.asarray(d["center"], float)
    area, c = polygon_area_centroid(np.asarray(d["vertices"], float))
    if cuts:
        v = clip_polygon(d["vertices"], cuts)
        area = polygon_area_centroid(v)[0] if len(v) >= 3 else 0.0
    return area, c


SEEDING_MODES = ("conformal", "lattice")


def charge_contains(charge, pts: np.ndarray) -> np.ndarray:
    """True where pts [n,2] lie inside the charge (circle: strictly; polygon: even-odd rule), and not beyond its
    cuts (points on a cut line are inside)."""
    kind, d = charge_geometry(charge)
    if kind == "circle":
        inside = np.linalg.norm(pts - np.asarray(d["center"], float), axis=1) < d["radius"]
    else:
        inside = points_in_polygon(pts, np.asarray(d["vertices"], float))
    for c in charge_cuts(d):
        inside &= c.beyond(pts) <= ON_LINE_TOL * _charge_size(kind, d)
    return inside


#: a seeded point within this fraction of the charge's size of a cut line lies on it
ON_LINE_TOL = 1e-9


def _charge_size(kind: str, d: dict) -> float:
    if kind == "circle":
        return 2.0 * float(d["radius"])
    return float(np.ptp(np.asarray(d["vertices"], float), axis=0).max())


def _apply_cuts(kind: str, d: dict, pts: np.ndarray, vol: np.ndarray, exact: bool):
    """The points of a charge on the modelled side of its cuts: those beyond are dropped, those on a line get half
    their volume (per line) and sit exactly on it; with ``exact`` the volumes are scaled to the clipped area."""
    cuts = charge_cuts(d)
    if not cuts:
        return pts, vol
    tol = ON_LINE_TOL * _charge_size(kind, d)
    keep = np.ones(len(pts), bool)
    vol = vol.copy()
    pts = pts.copy()
    for c in cuts:
        b = c.beyond(pts)
        keep &= b <= tol
        on = np.abs(b) <= tol
        vol[on] *= 0.5
        pts[on, c.axis] = c.coord
    pts, vol = pts[keep], vol[keep]
    if exact and len(vol):
        area = disc_cut_area(d["center"], d["radius"], cuts) if kind == "circle" else \
            polygon_area_centroid(clip_polygon(d["vertices"], cuts))[0]
        vol *= area / vol.sum()
    return pts, vol


def circle_rings(center, radius: float, spacing: float, even: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Conformal points of a disk [m]: (x [n,2] m, vol [n] m^2), see the module docstring.

    ``even``: every ring and the core (when it has more than one point) hold an even number of points,
    2·max(2, round(π r_m/s)), which makes the layout symmetric about both axes through the centre (the seeding of
    a charge cut by symmetry lines through its centre); a core of 4 or 8 points is turned by half a sector, off the
    axes (a point on a cut line keeps half its volume, and the lightest point sets the contact's stable step).

    Rings of width s = ``spacing`` from the circle inwards, K = floor((R − s/√π)/s) of them, ring i
    between R − (i+1)s and R − is with n_i = max(3, round(2π r_m/s)) equal points at its mid radius r_m;
    the core disk left over (radius between s/√π and s(1 + 1/√π)) holds round(area/s²) points: one at
    the centre if that is at most 2, else equal sectors with the points at their centroids. The outer
    ring's points are s/2 from the circle and their radius ½√V_p is s/2 within the rounding of n_i.
    """
    c = np.asarray(center, float)
    R, s = float(radius), float(spacing)
    K = max(0, int(np.floor((R - s / np.sqrt(np.pi)) / s)))
    rc = R - K * s
    xs, vs = [], []
    nc = int(round(np.pi * rc * rc / (s * s)))
    if even and nc > 2:
        nc = 2 * int(round(0.5 * nc))
    if nc <= 2:
        xs.append(c[None, :])
        vs.append(np.array([np.pi * rc * rc]))
    else:
        half = np.pi / nc                                    # sector half-angle
        rg = (2.0 / 3.0) * rc * np.sin(half) / half          # sector centroid radius
        th = np.arange(nc) * 2.0 * half
        if even and nc % 4 == 0:                             # off both axes, still symmetric about them
            th = th + half
        xs.append(c + rg * np.stack([np.cos(th), np.sin(th)], axis=1))
        vs.append(np.full(nc, np.pi * rc * rc / nc))
    for i in range(K):                                       # from the core outwards
        ra, rb = rc + i * s, rc + (i + 1) * s
        rm = 0.5 * (ra + rb)
        n = 2 * max(2, int(round(np.pi * rm / s))) if even else max(3, int(round(2.0 * np.pi * rm / s)))
        th = (np.arange(n) + 0.5 * ((K - i) % 2)) * (2.0 * np.pi / n)
        xs.append(c + rm * np.stack([np.cos(th), np.sin(th)], axis=1))
        vs.append(np.full(n, np.pi * (rb * rb - ra * ra) / n))
    return np.concatenate(xs), np.concatenate(vs)


def seed_charges(charges, spec, ppc: int, exact_area: bool = True, mode: str = "lattice"):
    """Seed points in the charges on grid ``spec``; returns (x [n,2] m, vol [n] m^2, charge_id [n]).

    mode: ``lattice`` (all charges on the grid sub-lattice) or ``conformal`` (circles on rings, polygons on
    the lattice); see the module docstring.
    """
    if mode not in SEEDING_MODES:
        raise ValueError(f"unknown seeding mode '{mode}'; expected one of {SEEDING_MODES}")
    h = spec.h
    dx = h / ppc
    xs_all, vol_all, cid_all = [], [], []
    taken = None
    for k, ch in enumerate(charges):
        kind, d = charge_geometry(ch)
        if mode == "conformal" and kind == "circle":
            cuts = charge_cuts(d)
            centred = bool(cuts) and all(abs(c.beyond(d["center"])[0]) <= ON_LINE_TOL * 2 * d["radius"] for c in cuts)
            pts, vol = circle_rings(d["center"], d["radius"], dx, even=centred)
            # symmetric rings cut through their centre keep the exact area; an off-centre cut is scaled to it
            pts, vol = _apply_cuts(kind, d, pts, vol, exact=not centred)
            new = np.ones(len(pts), bool)
            for j in range(k):
                new &= ~charge_contains(charges[j], pts)
            pts, vol = pts[new], vol[new]
            xs_all.append(pts)
            vol_all.append(vol)
            cid_all.append(np.full(len(pts), k, dtype=np.int32))
            continue
        lo, hi = charge_bbox(ch)
        i0 = int(np.floor((lo[0] - spec.x0) / dx)) - 1
        i1 = int(np.ceil((hi[0] - spec.x0) / dx)) + 1
        j0 = int(np.floor((lo[1] - spec.y0) / dx)) - 1
        j1 = int(np.ceil((hi[1] - spec.y0) / dx)) + 1
        I, J = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1), indexing="xy")
        pts = np.stack([spec.x0 + (I.ravel() + 0.5) * dx, spec.y0 + (J.ravel() + 0.5) * dx], axis=1)
        pts = pts[charge_contains(ch, pts)]
        for j in range(k):                                   # earlier conformal charges are not on the lattice
            if mode == "conformal" and charge_geometry(charges[j])[0] == "circle":
                pts = pts[~charge_contains(charges[j], pts)]
        if taken is not None and len(pts):
            key = np.round((pts - [spec.x0, spec.y0]) / dx - 0.5).astype(np.int64)
            keys = key[:, 0] * 1_000_003 + key[:, 1]
            new = ~np.isin(keys, taken)
            pts, keys = pts[new], keys[new]
        else:
            key = np.round((pts - [spec.x0, spec.y0]) / dx - 0.5).astype(np.int64)
            keys = key[:, 0] * 1_000_003 + key[:, 1]
        taken = keys if taken is None else np.concatenate([taken, keys])
        vol = np.full(len(pts), dx * dx)
        if charge_cuts(d):
            pts, vol = _apply_cuts(kind, d, pts, vol, exact=False)
        if exact_area and len(pts):
            area, _ = charge_area_centroid(ch)
            ratio = area / vol.sum()
            if 0.75 < ratio < 1.33:
                vol *= ratio
        xs_all.append(pts)
        vol_all.append(vol)
        cid_all.append(np.full(len(pts), k, dtype=np.int32))
    return np.concatenate(xs_all), np.concatenate(vol_all), np.concatenate(cid_all)


def slab_1d(length: float, ncell: int, ppc: int = 2, pad: int = 3):
    """A genuinely 1D setup: material on 0 <= x <= length in a strip one cell wide, periodic in y.

    Returns (GridSpec, x [n,2] m, vol [n] m^2); the grid has ``pad`` cells beyond each end
    (add a wall at x = 0 with ``Grid.set_walls(xmin=0.0)``).
    """
    from blastfrac.mpm.grid import GridSpec

    h = length / ncell
    spec = GridSpec(x0=-pad * h, y0=0.0, h=h, nx=ncell + 2 * pad + 1, ny=1, periodic_y=True)
    xs = (np.arange(ppc * ncell) + 0.5) * h / ppc
    ys = (np.arange(ppc) + 0.5) * h / ppc
    x = np.stack([np.repeat(xs, ppc), np.tile(ys, len(xs))], axis=1)
    return spec, x, np.full(len(x), (h / ppc) ** 2)
