"""Pieces of the gas–rock contact: the pressure offset of the contact radius (Warp vs NumPy twin), the
transfer of a force applied off the particle centre (P2G moment), and the conformal seeding of circles."""

import numpy as np
import pytest
import warp as wp

from blastfrac.coupling.particle_edge import MAX_PRESSURE_OFFSET_NP, pressure_offset, pressure_offset_np
from blastfrac.materials.jwl import JWLParams
from blastfrac.mpm.grid import GridSpec
from blastfrac.mpm.seeding import circle_rings, seed_charges
from blastfrac.mpm.solver import MPMOptions, MPMSolver


@wp.kernel
def _offset_kernel(p: wp.array(dtype=wp.float64), rp: wp.array(dtype=wp.float64), kc: wp.float64,
                   out: wp.array(dtype=wp.float64)):
    i = wp.tid()
    out[i] = pressure_offset(p[i], rp[i], kc)


def test_pressure_offset_twin_and_closed_form():
    kc = 8e9
    p = np.array([-1e6, 0.0, 2e8, 1e9, 5e9])
    rp = np.full(len(p), 2.5e-4)
    out = wp.zeros(len(p), dtype=wp.float64, device="cpu")
    wp.launch(_offset_kernel, dim=len(p), inputs=[wp.array(p, dtype=wp.float64, device="cpu"),
                                                  wp.array(rp, dtype=wp.float64, device="cpu"), kc],
              outputs=[out], device="cpu")
    twin = np.array([pressure_offset_np(a, b, kc) for a, b in zip(p, rp)])
    np.testing.assert_allclose(out.numpy(), twin, rtol=1e-15, atol=0.0)
    # k_c·offset = p·2r_p: a touching particle pushes with its pressure over its width; no pull, capped
    closed = np.minimum(np.maximum(p, 0.0) * 2 * rp / kc, MAX_PRESSURE_OFFSET_NP * rp)
    np.testing.assert_allclose(twin, closed, rtol=1e-15)
    assert twin[2] * kc == pytest.approx(2e8 * 2 * 2.5e-4)


def _one_particle(xp, f, arm):
    """Grid force [N/m] of one particle at rest, no stress, external force f applied at xp + arm."""
    P = JWLParams(rho0=1000.0, D=1000.0, A=0.0, B=0.0, R1=4.0, R2=1.0, omega=0.4, E0=1e6)
    spec = GridSpec.from_bounds((-0.01, -0.01), (0.01, 0.01), 1e-3)
    s = MPMSolver.from_arrays(np.array([xp]), np.array([1e-7]), spec, P, MPMOptions())
    s.f_ext_p.assign(np.array([f], float))
    s.f_ext_moment.assign(np.outer(f, arm)[None])
    s.to_grid(1e-9)
    xi = np.stack(np.meshgrid(spec.x0 + spec.h * np.arange(spec.nx), spec.y0 + spec.h * np.arange(spec.ny),
                              indexing="xy"), -1).reshape(-1, 2)
    return xi, s.grid.force.numpy(), spec


def test_force_moment_acts_at_the_contact_point():
    """f·N_I + (f⊗o)·∇N_I: total force f, torque (x_p + o) × f exactly; nodal forces = f·N_I(x_p + o) + O(|o|²)."""
    from blastfrac.mpm.shape import shape_1d_np

    xp = np.array([0.37e-3, -0.21e-3])
    f = np.array([-3.0e4, 1.2e4])
    errs = []
    for o_len in (2.5e-4, 1.25e-4):
        arm = o_len * np.array([0.8, 0.6])
        xi, fi, spec = _one_particle(xp, f, arm)
        np.testing.assert_allclose(fi.sum(0), f, rtol=1e-13)
        cross = lambda a, b: a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]  # noqa: E731
        assert cross(xi, fi).sum() == pytest.approx(float(cross(xp + arm, f)), rel=1e-12)
        r = (xp + arm - xi) / spec.h
        exact = (shape_1d_np(r[:, 0])[0] * shape_1d_np(r[:, 1])[0])[:, None] * f
        errs.append(np.abs(fi - exact).max() / np.abs(f).max())
    assert errs[0] < 0.05
    assert errs[0] / errs[1] > 3.0, "second order in the lever arm (first order would give 2)"


@pytest.mark.parametrize("R,s", [(0.005, 5e-4), (0.003225, 2.5e-4), (0.01, 4e-4), (6e-4, 5e-4)])
def test_circle_rings_fill_the_circle(R, s):
    x, vol = circle_rings((0.01, -0.02), R, s)
    r = np.linalg.norm(x - [0.01, -0.02], axis=1)
    assert vol.sum() == pytest.approx(np.pi * R * R, rel=1e-12)         # exact area
    assert np.all(r < R)
    assert np.all(np.abs(np.sqrt(vol) / s - 1) < 0.2) or len(x) < 10   # about s² each
    rp = 0.5 * np.sqrt(vol)
    outer = r > R - s
    # the outer ring's disks touch the circle: no void at a borehole wall
    assert np.abs(r[outer] + rp[outer] - R).max() < 0.01 * s or len(x) < 10
    # within each ring the spacing is about s
    if len(x) > 10:
        ring = r[outer]
        n = len(ring)
        assert abs(2 * np.pi * ring.mean() / n / s - 1) < 0.05


def test_conformal_seeding_keeps_overlaps_single_and_lattice_for_polygons():
    spec = GridSpec.from_bounds((-0.05, -0.05), (0.05, 0.05), 1e-3)
    c1 = {"kind": "circle", "center": [0.0, 0.0], "radius": 0.01}
    c2 = {"kind": "circle", "center": [0.012, 0.0], "radius": 0.005}       # overlaps c1
    sq = {"kind": "polygon", "vertices": [(0.02, 0.02), (0.03, 0.02), (0.03, 0.03), (0.02, 0.03)]}
    x, vol, cid = seed_charges([c1, c2, sq], spec, 2, mode="conformal")
    assert vol[cid == 0].sum() == pytest.approx(np.pi * 0.01**2, rel=1e-12)
    assert not np.any(np.linalg.norm(x[cid == 1], axis=1) < 0.01), "c2 drops what c1 seeded"
    assert vol[cid == 2].sum() == pytest.approx(1e-4, rel=1e-12)
    lat = (x[cid == 2] - [spec.x0, spec.y0]) / 5e-4 - 0.5
    np.testing.assert_allclose(lat, np.round(lat), atol=1e-9)             # polygon on the lattice
    with pytest.raises(ValueError):
        seed_charges([c1], spec, 2, mode="rings")
