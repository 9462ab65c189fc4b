"""Fragmentation (analysis/fragments.py): a mesh cut by drawn cracks into known pieces gives those pieces, and the
Swebrec fit recovers the parameters of a passing curve drawn from it."""

import math

import numpy as np
import pytest

from blastfrac.analysis.fragments import (fit_swebrec, fragmentation_report, fragments, passing_curve, passing_size,
                                          swebrec)
from blastfrac.geometry.mesh import TriMesh
from blastfrac.model.builder import ModelBuilder
from conftest import scenario

H = 0.005          # grid spacing [m]
N = 20             # 20 × 20 squares: a 0.1 m square


def _grid_model():
    i, j = np.meshgrid(np.arange(N + 1), np.arange(N + 1), indexing="ij")
    V = np.stack([i.ravel() * H, j.ravel() * H], 1)
    idx = lambda a, b: a * (N + 1) + b  # noqa: E731
    tri = []
    for a in range(N):
        for b in range(N):
            tri += [[idx(a, b), idx(a + 1, b), idx(a + 1, b + 1)], [idx(a, b), idx(a + 1, b + 1), idx(a, b + 1)]]
    sc = scenario(geometry={"domain": {"type": "rectangle", "width": N * H, "height": N * H,
                                       "center": [N * H / 2, N * H / 2]}, "mesh_size": H})
    m = ModelBuilder(sc, TriMesh(V, np.array(tri))).finalize("cpu")
    return m, m.state()


def _cut(model, state, on_line) -> None:
    """Break both springs of every interface whose two vertices satisfy on_line(x, y)."""
    X = model.host["node_X"]
    pn = model.topology.pair_nodes
    A, B = X[pn[0::2, 0]], X[pn[1::2, 0]]
    q = np.flatnonzero(on_line(A) & on_line(B))
    mode = state.pair_mode.numpy().copy()
    mode[2 * q] = mode[2 * q + 1] = 1
    state.pair_mode.assign(mode)


def test_drawn_cracks_give_the_known_pieces():
    m, st = _grid_model()
    x0, x1, y0, y1, xs = 0.02, 0.05, 0.02, 0.06, 0.035
    eps = 1e-12

    def vline(xc):
        return lambda p: (np.abs(p[:, 0] - xc) < eps) & (p[:, 1] > y0 - eps) & (p[:, 1] < y1 + eps)

    def hline(yc):
        return lambda p: (np.abs(p[:, 1] - yc) < eps) & (p[:, 0] > x0 - eps) & (p[:, 0] < x1 + eps)

    for line in (vline(x0), vline(x1), vline(xs), hline(y0), hline(y1)):     # both vertices on the same line
        _cut(m, st, line)
    # one lone triangle far from the box: the lower triangle of the square at (0.08, 0.08)
    a, b = 16, 16
    corner = np.array([[a * H, b * H], [(a + 1) * H, b * H], [(a + 1) * H, (b + 1) * H]])

    def lone(p):
        d = np.min(np.linalg.norm(p[:, None, :] - corner[None], axis=2), axis=1)
        return d < eps

    _cut(m, st, lone)
    fr = fragments(m, st)
    total = (N * H) ** 2
    expect = sorted([total - (x1 - x0) * (y1 - y0) - H * H / 2, (xs - x0) * (y1 - y0), (x1 - xs) * (y1 - y0),
                     H * H / 2], reverse=True)
    np.testing.assert_allclose(fr["area"], expect, rtol=1e-12)
    assert list(fr["touches_outer_boundary"]) == [True, False, False, False]
    assert fr["blocks"][-1] == 1
    np.testing.assert_allclose(fr["size"], 2 * np.sqrt(np.array(expect) / math.pi), rtol=1e-12)
    cx = sorted(fr["centroid_x"][1:3])
    np.testing.assert_allclose(cx, [(x0 + xs) / 2, (xs + x1) / 2], rtol=1e-12)
    rep = fragmentation_report(fr)
    assert rep["fragments"] == 4 and rep["blasted_fragments"] == 3 and rep["single_block_fragments"] == 1


def test_x50_of_a_dominant_fragment_is_that_fragment():
    """Staircase passing curve: 20 % of the mass in small pieces, 80 % in one 0.2 m fragment: x50 = x80 = 0.2 m."""
    size = np.r_[np.full(10, 0.01), 0.2]
    area = np.r_[np.full(10, 0.02), 0.8]
    x, P = passing_curve(size, area)
    assert passing_size(x, P, 0.5) == 0.2 and passing_size(x, P, 0.8) == 0.2 and passing_size(x, P, 0.1) == 0.01


def test_intact_rock_is_one_fragment():
    m, st = _grid_model()
    fr = fragments(m, st)
    assert len(fr["area"]) == 1 and fr["area"][0] == pytest.approx((N * H) ** 2, rel=1e-12)


def test_swebrec_fit_recovers_its_parameters():
    """Fragments sampled so that their mass-passing curve is a Swebrec curve (x50 = 20 mm, x_max = 150 mm, b = 2.2):
    the fit returns them within 3 %, and x50 read off the curve matches."""
    x50, x_max, b = 0.02, 0.15, 2.2
    sizes = np.geomspace(1e-3, 0.149, 400)
    P = swebrec(sizes, x50, x_max, b)
    w = np.diff(np.r_[0.0, P])                  # the mass of each size class
    x, Pc = passing_curve(sizes, w)
    fit = fit_swebrec(x, Pc / Pc[-1] * P[-1])
    assert fit["x50"] == pytest.approx(x50, rel=0.03)
    assert fit["x_max"] == pytest.approx(x_max, rel=0.03)
    assert fit["b"] == pytest.approx(b, rel=0.03)
    assert passing_size(x, Pc / Pc[-1] * P[-1], 0.5) == pytest.approx(x50, rel=0.02)   # one size class of 400
    assert fit["at_bound"] == []
