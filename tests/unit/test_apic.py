"""APIC helpers (mpm/apic.py): warp functions against their NumPy twins and the B-spline closed form D = h^2/4 I."""

import numpy as np
import pytest
import warp as wp

from blastfrac._warp import init_warp
from blastfrac.mpm import GridSpec
from blastfrac.mpm.apic import affine_from_moments, affine_from_moments_np, affine_inertia, affine_inertia_np
from blastfrac.mpm.shape import SHAPE_IDS, stencil_1d

F64 = wp.float64


@wp.kernel
def _apic(x: wp.array(dtype=wp.vec2d), B: wp.array(dtype=wp.mat22d), x0: wp.float64, y0: wp.float64, h: wp.float64,
          kind: int, l: wp.float64, D: wp.array(dtype=wp.mat22d), C: wp.array(dtype=wp.mat22d)):
    i = wp.tid()
    fx = (x[i][0] - x0) / h
    fy = (x[i][1] - y0) / h
    bx, wx, dwx = stencil_1d(fx, kind, l)
    by, wy, dwy = stencil_1d(fy, kind, l)
    Dm = affine_inertia(wx, wy, F64(bx) - fx, F64(by) - fy, h)
    D[i] = Dm
    C[i] = affine_from_moments(B[i], Dm)


@pytest.mark.parametrize("kind", ["bspline2", "ugimp"])
def test_affine_inertia_and_affine_velocity_warp_vs_numpy(kind):
    init_warp()
    h = 2e-3
    spec = GridSpec(x0=-0.01, y0=-0.02, h=h, nx=20, ny=30)
    rng = np.random.default_rng(5)
    x = rng.uniform([0.0, -0.01], [0.01, 0.02], (500, 2))
    B = rng.normal(size=(500, 2, 2)) * h**2
    D, C = wp.zeros(500, dtype=wp.mat22d, device="cpu"), wp.zeros(500, dtype=wp.mat22d, device="cpu")
    wp.launch(_apic, dim=500, inputs=[wp.array(x, dtype=wp.vec2d, device="cpu"), wp.array(B, dtype=wp.mat22d, device="cpu"),
                                      F64(spec.x0), F64(spec.y0), F64(h), SHAPE_IDS[kind], F64(0.25)], outputs=[D, C], device="cpu")
    D_np = affine_inertia_np(x, spec, kind, 0.25)
    np.testing.assert_allclose(D.numpy(), D_np, rtol=1e-12, atol=1e-12 * h**2)
    np.testing.assert_allclose(C.numpy(), affine_from_moments_np(B, D_np), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(D_np[:, 0, 1], 0.0, atol=1e-15 * h**2)  # linear reproduction: no off-diagonal
    if kind == "bspline2":
        np.testing.assert_allclose(D_np, np.broadcast_to(h**2 / 4 * np.eye(2), D_np.shape), rtol=1e-12, atol=1e-15 * h**2)
    else:  # uGIMP: varies with the place in the cell, between l h^2/2 (on a node) and h^2/4 (half-way)
        d = D_np[:, 0, 0] / h**2
        assert d.min() >= 0.125 - 1e-12 and d.max() <= 0.25 + 1e-12 and d.max() - d.min() > 0.1
