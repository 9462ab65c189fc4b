"""Shape functions of the background grid: quadratic B-spline (default) and uGIMP.

Choice (METHOD §2.1).  The default is the **quadratic B-spline** (``SHAPE_BSPLINE2``):

* its gradient is continuous, so a particle crossing a cell face does not produce the
  force jumps ("cell-crossing noise") that linear hat functions give under the fast
  expansion of detonation products;
* it needs no particle size, whereas uGIMP keeps a fixed half-width l_p that no longer
  matches the particle once the gas has expanded tenfold, which is the normal state here;
* it touches exactly 3 x 3 nodes, the same stencil as uGIMP with l_p <= h/2, with no
  branches on the particle's position inside the cell (fast on CPU and GPU).

uGIMP (Bardenhagen & Kober 2004, fixed l_p = h / (2 ppc)) is kept as an option
(``SHAPE_UGIMP``) for comparison.  Both are tensor products of 1D functions S(r) of
r = (x_p - x_I)/h; the gradient w.r.t. x_p is S'(r)/h.  In 1D the stencil of a
particle at fractional grid coordinate f = (x_p - x_0)/h is the nodes
base, base+1, base+2 with base = floor(f - 0.5).
"""

from __future__ import annotations

import numpy as np
import warp as wp

F64 = wp.float64

SHAPE_BSPLINE2 = 0
SHAPE_UGIMP = 1
SHAPE_IDS = {"bspline2": SHAPE_BSPLINE2, "ugimp": SHAPE_UGIMP}


@wp.struct
class GridGeometry:
    """The background grid as the transfer kernels see it: origin (x0, y0) [m], 1/h [1/m], nodes per side,
    periodicity per axis (1: periodic), shape function (SHAPE_*) and uGIMP's l_p/h [-]."""

    x0: wp.float64
    y0: wp.float64
    inv_h: wp.float64
    nx: int
    ny: int
    px: int
    py: int
    kind: int
    l: wp.float64


def grid_geometry(x0: float, y0: float, inv_h: float, nx: int, ny: int, px: int, py: int, kind: int,
                  l: float) -> GridGeometry:
    """A GridGeometry from its values (MPMSolver builds one per run)."""
    g = GridGeometry()
    g.x0, g.y0, g.inv_h, g.nx, g.ny, g.px, g.py, g.kind, g.l = x0, y0, inv_h, nx, ny, px, py, kind, l
    return g


@wp.func
def shape_1d(r: wp.float64, kind: int, l: wp.float64):
    """1D weight S(r) and dS/dr at r = (x_p - x_I)/h; l = l_p/h for uGIMP. Returns vec2d(S, dS/dr)."""
    a = wp.abs(r)
    s = F64(1.0)
    if r < F64(0.0):
        s = F64(-1.0)
    w = F64(0.0)
    dw = F64(0.0)
    if kind == 0:
        if a < F64(0.5):
            w = F64(0.75) - r * r
            dw = F64(-2.0) * r
        elif a < F64(1.5):
            w = F64(0.5) * (F64(1.5) - a) * (F64(1.5) - a)
            dw = -s * (F64(1.5) - a)
    else:
        if a < l:
            w = F64(1.0) - (r * r + l * l) / (F64(2.0) * l)
            dw = -r / l
        elif a < F64(1.0) - l:
            w = F64(1.0) - a
            dw = -s
        elif a < F64(1.0) + l:
            w = (F64(1.0) + l - a) * (F64(1.0) + l - a) / (F64(4.0) * l)
            dw = -s * (F64(1.0) + l - a) / (F64(2.0) * l)
    return wp.vec2d(w, dw)


@wp.func
def stencil_1d(f: wp.float64, kind: int, l: wp.float64):
    """Stencil of a particle at fractional grid coordinate f: (base, weights vec3d, dweights/df vec3d)."""
    base = int(wp.floor(f - F64(0.5)))
    w = wp.vec3d()
    dw = wp.vec3d()
    for k in range(3):
        s = shape_1d(f - wp.float64(base + k), kind, l)
        w[k] = s[0]
        dw[k] = s[1]
    return base, w, dw


@wp.func
def wrap_index(i: int, n: int, periodic: int):
    """Node index along one axis; wrapped modulo n on a periodic axis."""
    if periodic != 0:
        return ((i % n) + n) % n
    return i


# ----------------------------------------------------------------------------- numpy twin
def shape_1d_np(r, kind: str = "bspline2", l: float = 0.25):
    """NumPy twin of :func:`shape_1d`; returns (S, dS/dr) arrays."""
    r = np.asarray(r, dtype=np.float64)
    a, s = np.abs(r), np.where(r < 0, -1.0, 1.0)
    w, dw = np.zeros_like(r), np.zeros_like(r)
    if kind == "bspline2":
        m1, m2 = a < 0.5, (a >= 0.5) & (a < 1.5)
        w[m1], dw[m1] = 0.75 - r[m1] ** 2, -2.0 * r[m1]
        w[m2], dw[m2] = 0.5 * (1.5 - a[m2]) ** 2, -s[m2] * (1.5 - a[m2])
    elif kind == "ugimp":
        m1 = a < l
        m2 = (a >= l) & (a < 1 - l)
        m3 = (a >= 1 - l) & (a < 1 + l)
        w[m1], dw[m1] = 1 - (r[m1] ** 2 + l * l) / (2 * l), -r[m1] / l
        w[m2], dw[m2] = 1 - a[m2], -s[m2]
        w[m3], dw[m3] = (1 + l - a[m3]) ** 2 / (4 * l), -s[m3] * (1 + l - a[m3]) / (2 * l)
    else:
        raise ValueError(f"unknown shape '{kind}'")
    return w, dw


def stencil_1d_np(f, kind: str = "bspline2", l: float = 0.25):
    """NumPy twin of :func:`stencil_1d`: base [n], w [n,3], dw/df [n,3]."""
    f = np.atleast_1d(np.asarray(f, dtype=np.float64))
    base = np.floor(f - 0.5).astype(np.int64)
    r = f[:, None] - (base[:, None] + np.arange(3)[None, :])
    w, dw = shape_1d_np(r, kind, l)
    return base, w, dw
