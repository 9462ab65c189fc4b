"""Fragmentation after a run: fragments, their sizes and the passing curve with a Swebrec fit (issue 15).

A *fragment* is a set of blocks connected through interfaces that still hold: an interface holds while at least
one of its two springs is intact (both broken: the faces are free to separate). For each fragment:
area A [m²] (reference block areas: mass / density), equivalent size x = 2√(A/π) [m] (the diameter of the
circle of the same area, the 2D analogue of the sieve size), centroid (current, area-weighted) [m], velocity
(mass-weighted mean of its nodes) [m/s], block count, and whether it touches the model's outer boundary
(the unbroken remainder of the rock mass does).

The passing curve is P(x) = mass fraction of fragments smaller than x. It is computed over the *blasted*
fragments (those not touching the outer boundary): a blast engineer sieves the muck pile, not the rock left
in place. x50 and x80 are read off it (the smallest fragment at which P reaches 50 / 80 %: the curve is a
staircase, and a fragment holding most of the mass is x50 itself), and the Swebrec function
(Ouchterlony 2005)

    P(x) = 1 / (1 + (ln(x_max/x) / ln(x_max/x50))^b),  0 < x < x_max

is fitted by least squares on the points of the curve (x50 within the sizes, the largest fragment < x_max ≤ 3×
it, 0.1 ≤ b ≤ 20; parameters that end on a bound are listed: the curve is then not Swebrec-like).
"""

from __future__ import annotations

import math

import numpy as np


def fragment_labels(n_elem: int, iface_elems: np.ndarray, pair_mode: np.ndarray) -> np.ndarray:
    """Fragment index of each block [E]: components of the graph of holding interfaces (≥ 1 intact spring)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    pm = np.asarray(pair_mode).reshape(-1, 2)
    holds = (pm == 0).any(axis=1)
    e = np.asarray(iface_elems)[holds]
    g = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n_elem, n_elem))
    _, lab = connected_components(g, directed=False)
    return lab


def fragments(model, state, outer_tags: set[str] | None = None) -> dict[str, np.ndarray]:
    """Per-fragment arrays (see the module docstring), sorted by decreasing area.

    outer_tags: boundary-side names that count as the model's outer boundary (default: every side that is not a
    borehole wall 'holeK').
    """
    topo, h = model.topology, model.host
    E = model.element_count
    lab = fragment_labels(E, topo.iface_elems, state.pair_mode.numpy())
    n = int(lab.max()) + 1 if E else 0
    X = h["node_X"]
    area_e = 0.5 * np.abs((X[1::3, 0] - X[0::3, 0]) * (X[2::3, 1] - X[0::3, 1])
                          - (X[2::3, 0] - X[0::3, 0]) * (X[1::3, 1] - X[0::3, 1]))
    x = state.x.numpy()
    v = state.v.numpy()
    m = h["node_mass"]
    cent_e = (x[0::3] + x[1::3] + x[2::3]) / 3.0
    area = np.bincount(lab, area_e, n)
    cx = np.bincount(lab, area_e * cent_e[:, 0], n) / area
    cy = np.bincount(lab, area_e * cent_e[:, 1], n) / area
    node_lab = np.repeat(lab, 3)
    mass = np.bincount(node_lab, m, n)
    vx = np.bincount(node_lab, m * v[:, 0], n) / mass
    vy = np.bincount(node_lab, m * v[:, 1], n) / mass
    blocks = np.bincount(lab, minlength=n)
    tags = np.asarray(topo.boundary_slot_tags, dtype=object)
    outer = np.array([(t in outer_tags) if outer_tags is not None else not str(t).startswith("hole") for t in tags],
                     bool) if len(tags) else np.zeros(0, bool)
    touches = np.zeros(n, bool)
    if len(tags):
        touches[np.unique(lab[topo.boundary_slots[outer] // 3])] = True
    order = np.argsort(-area, kind="stable")
    out = {"area": area, "size": 2.0 * np.sqrt(area / math.pi), "centroid_x": cx, "centroid_y": cy,
           "velocity_x": vx, "velocity_y": vy, "blocks": blocks, "touches_outer_boundary": touches}
    return {k: a[order] for k, a in out.items()}


def passing_curve(size: np.ndarray, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x sorted ascending, P(x) = weight fraction of fragments of size ≤ x) [m], [-]."""
    o = np.argsort(size, kind="stable")
    x, w = np.asarray(size, float)[o], np.asarray(weight, float)[o]
    return x, np.cumsum(w) / w.sum()


def passing_size(x: np.ndarray, P: np.ndarray, q: float) -> float:
    """The smallest fragment size at which the passing fraction reaches q [m] (the curve is a staircase of
    discrete fragments: no interpolation, so a fragment that holds most of the mass is x50 itself)."""
    if len(x) == 0:
        return math.nan
    k = int(np.searchsorted(P, q - 1e-12))
    return float(x[min(k, len(x) - 1)])


def swebrec(x, x50: float, x_max: float, b: float):
    """Swebrec passing fraction P(x) [-] (0 < x < x_max; 1 beyond)."""
    x = np.asarray(x, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.log(x_max / np.minimum(x, x_max * (1 - 1e-15))) / math.log(x_max / x50)
        return np.where(x >= x_max, 1.0, 1.0 / (1.0 + np.power(np.maximum(r, 0.0), b)))


def fit_swebrec(x: np.ndarray, P: np.ndarray) -> dict:
    """Least-squares Swebrec fit to passing-curve points: {x50, x_max, b, rms, at_bound} (NaN under 4 points).

    x_max is sought in (x_largest, 3·x_largest] (Ouchterlony: about the largest block), x50 within the sizes,
    b in [0.1, 20]; ``at_bound`` names the parameters that ended on a bound (the curve is then not Swebrec-like,
    e.g. one fragment holds most of the mass).
    """
    from scipy.optimize import least_squares

    x, P = np.asarray(x, float), np.asarray(P, float)
    nan = {"x50": math.nan, "x_max": math.nan, "b": math.nan, "rms": math.nan, "at_bound": []}
    if len(x) < 4 or not np.all(x > 0) or x.min() == x.max():
        return nan
    x_top = float(x.max())

    def unpack(p):
        return math.exp(p[0]), x_top * (1.0 + math.exp(p[1])), math.exp(p[2])

    def res(p):
        x50, x_max, b = unpack(p)
        return swebrec(x, x50, x_max, b) - P

    lo_b = [math.log(x.min()), -12.0, math.log(0.1)]
    hi_b = [math.log(x_top), math.log(2.0), math.log(20.0)]
    x50_0 = passing_size(x, P, 0.5)
    p0 = [min(max(math.log(x50_0), lo_b[0] + 1e-9), hi_b[0] - 1e-9), math.log(0.3), math.log(2.0)]
    sol = least_squares(res, p0, bounds=(lo_b, hi_b), method="trf")
    x50, x_max, b = unpack(sol.x)
    names = ("x50", "x_max", "b")
    at = [n for n, v, a, c in zip(names, sol.x, lo_b, hi_b) if min(v - a, c - v) < 1e-6 * max(1.0, abs(c - a))]
    return {"x50": x50, "x_max": x_max, "b": b, "rms": float(np.sqrt(np.mean(sol.fun**2))), "at_bound": at}


def fragmentation_report(fr: dict[str, np.ndarray]) -> dict:
    """summary.json → fragmentation: counts, the largest fragment, x50/x80 of the blasted fragments, Swebrec fit."""
    blasted = ~fr["touches_outer_boundary"]
    x, P = passing_curve(fr["size"][blasted], fr["area"][blasted]) if blasted.any() else (np.zeros(0), np.zeros(0))
    fit = fit_swebrec(x, P)
    return {
        "fragments": int(len(fr["area"])), "blasted_fragments": int(blasted.sum()),
        "single_block_fragments": int(np.sum(fr["blocks"][blasted] == 1)),
        "largest_fragment_area": float(fr["area"][0]) if len(fr["area"]) else 0.0,
        "blasted_area": float(fr["area"][blasted].sum()),
        "x50": passing_size(x, P, 0.5), "x80": passing_size(x, P, 0.8),
        "swebrec": fit,
        "note": "sizes are equivalent-circle diameters 2√(A/π) of fragments not touching the outer boundary; "
                "fragments of one block are at the mesh scale",
    }
