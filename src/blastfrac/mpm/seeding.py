"""Material-point seeding of charge regions (circles, polygons; any number).

Points sit on a regular sub-lattice of the grid, ``ppc`` per cell per direction, at the
sub-cell centres; a point belongs to the first charge containing it.  Each point starts
with volume (h/ppc)^2 [m^2 per unit thickness]; with ``exact_area`` the volumes of a
charge are scaled so that they add up to the charge's exact area (mass and chemical
energy per unit thickness are then exact).
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


def seed_charges(charges, spec, ppc: int, exact_area: bool = True):
    """Seed points in the charges on grid ``spec``; returns (x [n,2] m, vol [n] m^2, charge_id [n])."""
    h = spec.h
    dx = h / ppc
    xs_all, vol_all, cid_all = [], [], []
    taken = None
    for k, ch in enumerate(charges):
        lo, hi = charge_bbox(ch)
        i0 = int(np.floor((lo[0] - spec.x0) / dx)) - 1
        i1 = int(np.ceil((hi[0] - spec.x0) / dx)) + 1
        j0 = int(np.floor((lo[1] - spec.y0) / dx)) - 1
        j1 = int(np.ceil((hi[1] - spec.y0) / dx)) + 1
        I, J = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1), indexing="xy")
        pts = np.stack([spec.x0 + (I.ravel() + 0.5) * dx, spec.y0 + (J.ravel() + 0.5) * dx], axis=1)
        kind, d = charge_geometry(ch)
        if kind == "circle":
            inside = np.linalg.norm(pts - np.asarray(d["center"], float), axis=1) < d["radius"]
        else:
            inside = points_in_polygon(pts, np.asarray(d["vertices"], float))
        pts = pts[inside]
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
