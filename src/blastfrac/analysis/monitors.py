"""Monitor points: rock quantities sampled at fixed reference points over time.

A single CST block's stress scatters by ±5–25 % about the local field in this block–spring model, so a
monitor samples a neighbourhood of radius R around its point (all on the reference mesh):

- stress (sxx, syy, sxy, pressure): the area-weighted mean of the element stresses over the elements whose
  reference centroids lie within R, Σ A_e σ_e / Σ A_e;
- ux, uy, vx, vy, speed: the node_mass-weighted mean over the nodes whose reference positions lie within R
  (speed is |mean velocity|).

Default R = 2·h, with the local element size h = √(2A) [m] of the element containing the point (the nearest
one by centroid if none contains it): the side of a right isosceles triangle of area A, ≈ 0.93 × the side of
an equilateral one. R = 0 restores the single-element stress and the barycentric interpolation of that
element's 3 nodes. If no centroid (no node) lies within R, the containing element (its barycentric node
weights) is used instead.
"""

from __future__ import annotations

import numpy as np

DEFAULT_RADIUS_ELEMENTS = 2.0   # default R in local element sizes h = √(2A)


def locate_points(X: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Element containing each point and its barycentric weights, on the reference mesh.

    X: node reference positions [3E, 2] [m]; points [M, 2] [m]. Points outside every element are
    assigned the nearest element centroid (weights then extrapolate mildly).
    """
    p0, p1, p2 = X[0::3], X[1::3], X[2::3]
    elems, weights = [], []
    for p in np.atleast_2d(points):
        d1, d2, dp = p1 - p0, p2 - p0, p - p0
        det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        l1 = (dp[:, 0] * d2[:, 1] - dp[:, 1] * d2[:, 0]) / det
        l2 = (d1[:, 0] * dp[:, 1] - d1[:, 1] * dp[:, 0]) / det
        l0 = 1 - l1 - l2
        inside = np.flatnonzero((l0 >= -1e-12) & (l1 >= -1e-12) & (l2 >= -1e-12))
        e = int(inside[0]) if len(inside) else int(np.argmin(np.linalg.norm((p0 + p1 + p2) / 3 - p, axis=1)))
        elems.append(e)
        weights.append([l0[e], l1[e], l2[e]])
    return np.array(elems, np.int64), np.array(weights)


def element_areas(X: np.ndarray) -> np.ndarray:
    """Reference element areas [m²], [E], from node positions X [3E, 2] [m]."""
    d1, d2 = X[1::3] - X[0::3], X[2::3] - X[0::3]
    return 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def local_element_size(area: float) -> float:
    """h = √(2A) [m] of an element of area A [m²]."""
    return float(np.sqrt(2.0 * area))


def element_stencil(centroids: np.ndarray, area: np.ndarray, point, radius: float, elem: int):
    """Elements with centroid within ``radius`` [m] of ``point`` and their area weights (sum 1).

    Falls back to the single element ``elem`` if none (or radius = 0).
    """
    idx = np.flatnonzero(np.linalg.norm(centroids - point, axis=1) <= radius) if radius > 0 else np.zeros(0, np.int64)
    if len(idx) == 0:
        return np.array([elem], np.int64), np.ones(1)
    return idx, area[idx] / area[idx].sum()


def node_stencil(X: np.ndarray, mass: np.ndarray, point, radius: float, elem: int, bary: np.ndarray):
    """Nodes within ``radius`` [m] of ``point`` and their mass weights (sum 1).

    Falls back to the 3 nodes of ``elem`` with barycentric weights ``bary`` if none (or radius = 0).
    """
    idx = np.flatnonzero(np.linalg.norm(X - point, axis=1) <= radius) if radius > 0 else np.zeros(0, np.int64)
    if len(idx) == 0:
        return np.arange(3 * elem, 3 * elem + 3), np.asarray(bary, float)
    return idx, mass[idx] / mass[idx].sum()


def _flatten(stencils: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Concatenate per-monitor (indices, weights) into (idx, w, monitor id) arrays."""
    if not stencils:
        return np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.int64)
    idx = np.concatenate([s[0] for s in stencils]).astype(np.int64)
    w = np.concatenate([s[1] for s in stencils])
    seg = np.concatenate([np.full(len(s[0]), k, np.int64) for k, s in enumerate(stencils)])
    return idx, w, seg


def _weighted_means(gathered: np.ndarray, w: np.ndarray, seg: np.ndarray, m: int) -> np.ndarray:
    """Per-monitor Σ w·gathered over its stencil entries (weights already normalised), shape [m, d].

    gathered: the stencil entries' values [K, d] (K = len(w)); seg: monitor of each entry [K].
    """
    vals = gathered * w[:, None]
    return np.stack([np.bincount(seg, weights=vals[:, c], minlength=m) for c in range(vals.shape[1])], 1)


class MonitorSet:
    """Samples each monitor's quantities from the rock state (host arrays).

    monitors: scenario Monitor list; X: node reference positions [3E, 2] [m]; node_mass: lumped node masses
    [kg/m], [3E] (uniform weights if None). Stencils (indices and normalised weights) are built once here.
    Attributes: ``elems`` (element containing each point), ``weights`` (its barycentric weights),
    ``radii`` (resolved averaging radius per monitor [m]).
    """

    def __init__(self, monitors: list, X: np.ndarray, node_mass: np.ndarray | None = None):
        self.monitors = monitors
        self.columns = [f"{m.name}:{q}" for m in monitors for q in m.quantities]
        self.points = np.array([m.position for m in monitors], float).reshape(-1, 2)
        if not monitors:
            self.elems, self.weights = np.zeros(0, np.int64), np.zeros((0, 3))
        else:
            self.elems, self.weights = locate_points(X, self.points)
        mass = np.ones(len(X)) if node_mass is None else np.asarray(node_mass, float)
        area = element_areas(X)
        centroids = (X[0::3] + X[1::3] + X[2::3]) / 3.0
        self.radii = np.array([self._radius(m, area[e]) for m, e in zip(monitors, self.elems)], float)
        es, ns = [], []
        for k, (p, R, e) in enumerate(zip(self.points, self.radii, self.elems)):
            es.append(element_stencil(centroids, area, p, R, int(e)))
            ns.append(node_stencil(X, mass, p, R, int(e), self.weights[k]))
        self._e = _flatten(es)
        self._n = _flatten(ns)
        self._counts = [(len(a[0]), len(b[0])) for a, b in zip(es, ns)]

    @staticmethod
    def _radius(monitor, area: float) -> float:
        """Resolved averaging radius [m]: the scenario's, or 2·√(2A) of the containing element."""
        r = getattr(monitor, "radius", None)
        return DEFAULT_RADIUS_ELEMENTS * local_element_size(area) if r is None else float(r)

    def report(self) -> list[dict]:
        """Per monitor: name, position [m], resolved radius [m], number of elements and nodes averaged."""
        return [{"name": m.name, "position": [float(c) for c in p], "radius": float(R), "elements": int(ne),
                 "nodes": int(nn)}
                for m, p, R, (ne, nn) in zip(self.monitors, self.points, self.radii, self._counts)]

    def fields(self, x: np.ndarray, X: np.ndarray, v: np.ndarray, sigma: np.ndarray) -> dict[str, np.ndarray]:
        """Averaged u [m] and v [m/s] ([M, 2]) and σ (xx, yy, xy) [Pa] ([M, 3]) at every monitor."""
        m = len(self.monitors)
        ni, nw, ns = self._n
        ei, ew, es = self._e
        return {"u": _weighted_means(x[ni] - X[ni], nw, ns, m),
                "v": _weighted_means(v[ni], nw, ns, m),
                "sigma": _weighted_means(sigma[ei], ew, es, m)}

    def sample(self, x: np.ndarray, X: np.ndarray, v: np.ndarray, sigma: np.ndarray, gas_pressure=None) -> list[float]:
        """One history row: every monitor's quantities, in ``columns`` order.

        x, X: current and reference node positions [3E, 2] [m]; v: node velocities [3E, 2] [m/s];
        sigma: element stresses (xx, yy, xy) [E, 3] [Pa]; gas_pressure: callable points [M, 2] → [M] [Pa].
        """
        f = self.fields(x, X, v, sigma)
        wants_gas = gas_pressure is not None and any("gas_pressure" in m.quantities for m in self.monitors)
        gp = np.asarray(gas_pressure(self.points), float) if wants_gas else np.zeros(len(self.monitors))
        row = []
        for k, m in enumerate(self.monitors):
            u, vel, s = f["u"][k], f["v"][k], f["sigma"][k]
            vals = {
                "ux": u[0], "uy": u[1], "vx": vel[0], "vy": vel[1], "speed": float(np.hypot(*vel)),
                "sxx": s[0], "syy": s[1], "sxy": s[2], "pressure": -0.5 * (s[0] + s[1]),
                "gas_pressure": gp[k],
            }
            row.extend(float(vals[q]) for q in m.quantities)
        return row
