"""The crack gas's particle hash finds what a search over every particle finds.

A mouth (a crack end on the hole wall) is fed by the nearest active, fully burnt particle above the mass floor
within its radius, and a wide cell hands its gas to the nearest such particle within its own radius. These searches
went over every particle for each mouth (0.5 ms a rebuild at the 10 mm confined P0's 5,000 points); they now look
in the cells of a hash (kernels_crack_gas.GasHash, nearest_burnt). The reference here is the definition, evaluated
in NumPy: the least distance below the radius, ties to the lowest index (what the search in index order kept).
"""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from blastfrac.coupling.crack_gas import hash_burnt
from blastfrac.coupling.kernels_crack_gas import GasHash, GasParticles, nearest_burnt

F64 = wp.float64


@wp.kernel
def _query(hsh: GasHash, parts: GasParticles, pts: wp.array(dtype=wp.vec2d), radius: wp.array(dtype=wp.float64),
           floor: wp.float64, out: wp.array(dtype=wp.int32)):
    k = wp.tid()
    out[k] = nearest_burnt(hsh, parts, pts[k], radius[k], floor)


def _particles(x, active, burn, mass, mass0):
    d = "cpu"
    p = GasParticles()
    n = len(x)
    p.x = wp.array(x, dtype=wp.vec2d, device=d)
    p.v = wp.zeros(n, dtype=wp.vec2d, device=d)
    p.mass, p.mass0 = wp.array(mass, dtype=F64, device=d), wp.array(mass0, dtype=F64, device=d)
    p.vol, p.vol0, p.rho, p.ie, p.pres, p.q, p.out, p.scale = (wp.zeros(n, dtype=F64, device=d) for _ in range(8))
    p.burn = wp.array(burn, dtype=F64, device=d)
    p.stress = wp.zeros(n, dtype=wp.mat22d, device=d)
    p.active = wp.array(active, dtype=wp.int32, device=d)
    p.touched = wp.zeros(n, dtype=wp.int32, device=d)
    return p


def _hash(parts, n, cell, dim):
    h = GasHash()
    h.values = wp.zeros(2 * n, dtype=wp.int32)
    h.starts, h.ends = wp.zeros(dim * dim, dtype=wp.int32), wp.zeros(dim * dim, dtype=wp.int32)
    h.cell_inv = 1.0 / cell
    h.dim = dim
    keys = wp.zeros(2 * n, dtype=wp.int32)
    hash_burnt(parts, h, keys, n, "cpu")
    return h


def _reference(x, ok, pts, radius):
    """Index of the nearest eligible point closer than radius (ties: lowest index), −1 if none."""
    out = np.full(len(pts), -1)
    for k, (pt, r) in enumerate(zip(pts, radius)):
        d2 = ((x - pt) ** 2).sum(axis=1)
        cand = np.flatnonzero(ok & (d2 < r * r))
        if len(cand):
            out[k] = cand[np.argmin(d2[cand])]          # argmin: the first (lowest index) of equal minima
    return out


@pytest.mark.parametrize("dim", [4, 16])
@pytest.mark.parametrize("floor", [-1.0, 0.505])
def test_nearest_burnt_is_the_search_over_every_particle(dim, floor):
    rng = np.random.default_rng(7 + dim)
    n, cell = 5000, 1.0e-3
    # a cloud much wider than dim cells (the cells wrap: far points share a cell and must be told apart), with
    # points repeated (equal distances: the tie rule) and some on the cell lines
    x = rng.uniform(-0.02, 0.03, size=(n, 2))
    x[100:200] = x[0:100]
    x[200:260] = np.round(x[200:260] / cell) * cell
    active = (rng.random(n) > 0.1).astype(np.int32)
    burn = np.where(rng.random(n) > 0.2, 1.0, rng.uniform(0.0, 0.999, n))
    mass0 = rng.uniform(1e-6, 2e-6, n)
    mass = mass0 * rng.uniform(0.3, 1.0, n)
    parts = _particles(x, active, burn, mass, mass0)
    h = _hash(parts, n, cell, dim)
    # queries: random, at particles (distance 0), and at a cell corner
    m = 2000
    pts = np.concatenate([rng.uniform(-0.022, 0.032, size=(m - 150, 2)), x[:100], [[0.0, 0.0]] * 50])
    radius = rng.uniform(0.05, 3.0, len(pts)) * cell        # up to 3 cells: more than dim = 4 wraps
    out = wp.zeros(len(pts), dtype=wp.int32)
    wp.launch(_query, dim=len(pts), inputs=[h, parts, wp.array(pts, dtype=wp.vec2d), wp.array(radius, dtype=F64),
                                            F64(floor), out])
    ok = (active != 0) & (burn >= 1.0) & ~(mass <= floor * mass0)
    ref = _reference(x, ok, pts, radius)
    got = out.numpy()
    assert (ref >= 0).sum() > 300 and (ref < 0).sum() > 300        # both outcomes are exercised
    np.testing.assert_array_equal(got, ref)


def test_an_empty_hash_finds_nothing():
    n = 10
    x = np.zeros((n, 2))
    parts = _particles(x, np.zeros(n, np.int32), np.ones(n), np.ones(n), np.ones(n))    # all inactive
    h = _hash(parts, n, 1e-3, 16)
    out = wp.zeros(1, dtype=wp.int32)
    wp.launch(_query, dim=1, inputs=[h, parts, wp.array([[0.0, 0.0]], dtype=wp.vec2d), wp.array([1e-3], dtype=F64),
                                     F64(-1.0), out])
    assert out.numpy()[0] == -1


def test_equal_distances_go_to_the_lowest_index():
    """Two points equally far (exactly, in binary fractions) on either side of a cell line: the search visits the
    higher index first (its cell comes first), and must still answer the lower, as the search in index order."""
    cell = 2.0 ** -10
    pt = np.array([3 * cell, 5.5 * cell])
    off = np.array([2.0 ** -12, 0.0])
    x = np.array([pt + off, pt - off, pt + 3 * off])           # 0 in cell 3, 1 in cell 2, 2 farther
    n = len(x)
    parts = _particles(x, np.ones(n, np.int32), np.ones(n), np.ones(n), np.ones(n))
    h = _hash(parts, n, cell, 16)
    out = wp.zeros(1, dtype=wp.int32)
    wp.launch(_query, dim=1, inputs=[h, parts, wp.array([pt], dtype=wp.vec2d), wp.array([cell], dtype=F64),
                                     F64(-1.0), out])
    assert out.numpy()[0] == _reference(x, np.ones(n, bool), [pt], [cell])[0] == 0
