"""Shape functions: partition of unity, linear reproduction, gradients, warp vs numpy; P2G/G2P invariants."""

import numpy as np
import pytest
import warp as wp

from blastfrac._warp import init_warp
from blastfrac.mpm.shape import SHAPE_IDS, shape_1d_np, stencil_1d, stencil_1d_np

F64 = wp.float64


@wp.kernel
def _stencil(f: wp.array(dtype=wp.float64), kind: int, l: wp.float64, base: wp.array(dtype=int), w: wp.array(dtype=wp.vec3d), dw: wp.array(dtype=wp.vec3d)):
    i = wp.tid()
    b, ww, dd = stencil_1d(f[i], kind, l)
    base[i] = b
    w[i] = ww
    dw[i] = dd


@pytest.mark.parametrize("kind", ["bspline2", "ugimp"])
def test_partition_of_unity_and_linear_reproduction(kind):
    f = np.random.default_rng(1).uniform(2.0, 9.0, 2000)
    base, w, dw = stencil_1d_np(f, kind, 0.25)
    nodes = base[:, None] + np.arange(3)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(dw.sum(axis=1), 0.0, atol=1e-13)
    np.testing.assert_allclose((w * nodes).sum(axis=1), f, atol=1e-12)  # sum N x_I = x
    np.testing.assert_allclose((dw * nodes).sum(axis=1), 1.0, atol=1e-12)  # sum dN x_I = 1
    assert (w >= 0).all()


@pytest.mark.parametrize("kind", ["bspline2", "ugimp"])
def test_gradient_is_derivative_and_c0(kind):
    r = np.linspace(-1.7, 1.7, 3401)
    w, dw = shape_1d_np(r, kind, 0.25)
    e = 1e-7
    fd = (shape_1d_np(r + e, kind, 0.25)[0] - shape_1d_np(r - e, kind, 0.25)[0]) / (2 * e)
    np.testing.assert_allclose(dw, fd, atol=1e-5)
    assert np.max(np.abs(np.diff(w))) < 2.1 * (r[1] - r[0])  # continuous


def test_bspline_values_closed_form():
    # quadratic B-spline: N(0) = 3/4, N(+-1/2) = 1/2, N(+-1) = 1/8, N(+-3/2) = 0
    w, _ = shape_1d_np(np.array([0.0, 0.5, -0.5, 1.0, -1.0, 1.5]), "bspline2")
    np.testing.assert_allclose(w, [0.75, 0.5, 0.5, 0.125, 0.125, 0.0], atol=1e-15)


@pytest.mark.parametrize("kind", ["bspline2", "ugimp"])
def test_warp_twin(kind):
    init_warp()
    f = np.random.default_rng(2).uniform(2.0, 9.0, 300)
    b, w, dw = wp.zeros(300, dtype=int), wp.zeros(300, dtype=wp.vec3d), wp.zeros(300, dtype=wp.vec3d)
    wp.launch(_stencil, dim=300, inputs=[wp.array(f, dtype=F64), SHAPE_IDS[kind], F64(0.25), b, w, dw])
    base, wn, dwn = stencil_1d_np(f, kind, 0.25)
    np.testing.assert_array_equal(b.numpy(), base)
    np.testing.assert_allclose(w.numpy(), wn, atol=1e-14)
    np.testing.assert_allclose(dw.numpy(), dwn, atol=1e-14)


def test_p2g_conserves_mass_momentum_and_reproduces_linear_velocity():
    """P2G mass/momentum sums equal the particle sums; a linear velocity field gives L exactly."""
    from blastfrac.materials.linear_elastic_mp import LinearElasticMP
    from blastfrac.mpm import GridSpec, MPMOptions, MPMSolver

    rng = np.random.default_rng(3)
    spec = GridSpec.from_bounds((0, 0), (1, 1), 0.05)
    x = rng.uniform(0.1, 0.9, (500, 2))
    vol = rng.uniform(1, 2, 500) * 1e-4
    G = np.array([[0.3, -0.2], [0.5, 0.1]])
    v = x @ G.T + [1.0, -2.0]
    s = MPMSolver.from_arrays(x, vol, spec, LinearElasticMP(1e6, 0.3, 1000.0), MPMOptions(flip_bodies=0.0), v=v)
    s.to_grid(1e-9)
    m = s.mass.numpy()
    assert abs(s.grid.mass.numpy().sum() / m.sum() - 1) < 1e-13
    np.testing.assert_allclose(s.grid.mom.numpy().sum(axis=0), (m[:, None] * v).sum(axis=0), rtol=1e-12)
    # total internal force vanishes (partition of unity) for any stress
    s.stress.assign(rng.normal(size=(500, 2, 2)))
    s.to_grid(1e-9)
    assert np.abs(s.grid.force.numpy().sum(axis=0)).max() < 1e-12
    # a linear grid velocity field is reproduced by the velocity gradient (kinematics kernel alone)
    from blastfrac.mpm.kernels_g2p import update_particle_kinematics

    pos = spec.node_positions()
    s.grid.vel.assign(pos @ G.T + [1.0, -2.0])
    dead = wp.zeros(1, dtype=wp.int32)
    wp.launch(update_particle_kinematics, dim=500,
              inputs=[s.active, s.mass, s.grid.vel, s.v_pic, s.geo, wp.float64(1e-9)],
              outputs=[s.x, s.vol, s.vol_prev, s.rho, s.grad_v, dead, s.grid.extent])
    np.testing.assert_allclose(s.grad_v.numpy(), np.broadcast_to(G, (500, 2, 2)), atol=1e-10)
    np.testing.assert_allclose(s.vol.numpy() / s.vol_prev.numpy(), np.linalg.det(np.eye(2) + 1e-9 * G), rtol=1e-14)


def test_seeding_polygon_circle_and_overlap():
    from blastfrac.mpm import GridSpec
    from blastfrac.mpm.seeding import seed_charges

    spec = GridSpec.from_bounds((-1, -1), (1, 1), 0.01)
    tri = {"kind": "polygon", "vertices": [(0.0, 0.0), (0.5, 0.0), (0.0, 0.4)]}
    circ = {"kind": "circle", "center": [0.0, 0.0], "radius": 0.2}  # overlaps the triangle
    x, vol, cid = seed_charges([tri, circ], spec, 2)
    assert abs(vol[cid == 0].sum() - 0.5 * 0.5 * 0.4) < 1e-12  # exact polygon area
    key = np.round(x / 0.005, 6)
    assert len(np.unique(key, axis=0)) == len(x)  # no duplicate points in the overlap
    assert abs((cid == 1).sum() * 0.005**2 - (np.pi * 0.04 - 0.25 * np.pi * 0.04)) < 0.02 * np.pi * 0.04
    assert np.all(np.linalg.norm(x[cid == 1], axis=1) < 0.2)


def test_pressure_at_uniform_field():
    from blastfrac.explosives.library import get_explosive
    from blastfrac.mpm import GridSpec, MPMOptions, MPMSolver
    from blastfrac.mpm.seeding import seed_charges

    P = get_explosive("tnt")
    spec = GridSpec.from_bounds((-0.05, -0.05), (0.05, 0.05), 2e-3)
    x, vol, _ = seed_charges([{"kind": "circle", "center": [0.0, 0.0], "radius": 0.02}], spec, 2)
    s = MPMSolver.from_arrays(x, vol, spec, P, MPMOptions(), burn=np.ones(len(x)))
    p0 = P.A * (1 - P.omega / P.R1) * np.exp(-P.R1) + P.B * (1 - P.omega / P.R2) * np.exp(-P.R2) + P.omega * P.E0
    out = s.pressure_at(np.array([[0.0, 0.0], [0.01, -0.005], [0.04, 0.04]]))
    np.testing.assert_allclose(out[:2], p0, rtol=1e-12)
    assert out[2] == 0.0
    f = s.particle_fields()
    assert set(f) >= {"position", "velocity", "pressure", "density", "burn_fraction"}
    assert f["position"].shape == (len(x), 2)
