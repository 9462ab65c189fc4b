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
"""

from __future__ import annotations

import numpy as np


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
    kind, d = charge_geometry(charge)
    if kind == "circle":
        c, r = np.asarray(d["center"], float), float(d["radius"])
        return c - r, c + r
    v = np.asarray(d["vertices"], float)
    return v.min(axis=0), v.max(axis=0)


def charge_area_centroid(charge) -> tuple[float, np.ndarray]:
    kind, d = charge_geometry(charge)
    if kind == "circle":
        return float(np.pi * d["radius"] ** 2), np.asarray(d["center"], float)
    return polygon_area_centroid(np.asarray(d["vertices"], float))


SEEDING_MODES = ("conformal", "lattice")


def charge_contains(charge, pts: np.ndarray) -> np.ndarray:
    """True where pts [n,2] lie inside the charge (circle: strictly; polygon: even-odd rule)."""
    kind, d = charge_geometry(charge)
    if kind == "circle":
        return np.linalg.norm(pts - np.asarray(d["center"], float), axis=1) < d["radius"]
    return points_in_polygon(pts, np.asarray(d["vertices"], float))


def circle_rings(center, radius: float, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Conformal points of a disk [m]: (x [n,2] m, vol [n] m^2), see the module docstring.

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
    if nc <= 2:
        xs.append(c[None, :])
        vs.append(np.array([np.pi * rc * rc]))
    else:
        half = np.pi / nc                                    # sector half-angle
        rg = (2.0 / 3.0) * rc * np.sin(half) / half          # sector centroid radius
        th = np.arange(nc) * 2.0 * half
        xs.append(c + rg * np.stack([np.cos(th), np.sin(th)], axis=1))
        vs.append(np.full(nc, np.pi * rc * rc / nc))
    for i in range(K):                                       # from the core outwards
        ra, rb = rc + i * s, rc + (i + 1) * s
        rm = 0.5 * (ra + rb)
        n = max(3, int(round(2.0 * np.pi * rm / s)))
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
            pts, vol = circle_rings(d["center"], d["radius"], dx)
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
