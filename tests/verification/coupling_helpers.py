"""Builders shared by the coupling tests: structured rock meshes and gas boxes."""

from __future__ import annotations

import numpy as np

from blastfrac.geometry.mesh import TriMesh


def structured_rectangle(x0: float, y0: float, lx: float, ly: float, nx: int, ny: int) -> TriMesh:
    """Rectangle [x0, x0+lx] × [y0, y0+ly] split into nx·ny squares of two counter-clockwise triangles."""
    xs, ys = np.linspace(x0, x0 + lx, nx + 1), np.linspace(y0, y0 + ly, ny + 1)
    V = np.array([[x, y] for y in ys for x in xs])
    tris = []
    for j in range(ny):
        for i in range(nx):
            a, b = j * (nx + 1) + i, j * (nx + 1) + i + 1
            c, d = a + nx + 1, b + nx + 1
            tris += [[a, b, d], [a, d, c]]
    return TriMesh(V, np.array(tris))


def lattice_points(lo, hi, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Points at the centres of a square lattice of ``spacing`` filling the box lo..hi; (x [n,2], vol [n])."""
    xs = np.arange(lo[0] + spacing / 2, hi[0], spacing)
    ys = np.arange(lo[1] + spacing / 2, hi[1], spacing)
    X, Y = np.meshgrid(xs, ys)
    x = np.stack([X.ravel(), Y.ravel()], 1)
    return x, np.full(len(x), spacing**2)
