"""Crack-gas laws (materials/crack_flow.py, coupling/kernels_crack_gas.py) against formulas: the choked mass flux
of an isentropic nozzle, the cubic law, the Warp functions against their NumPy twins, and the face load of a
crack cell as the virtual work of its pressure."""

import numpy as np
import pytest
import warp as wp

from blastfrac.coupling.kernels_crack_gas import quad_area, quad_area_gradient
from blastfrac.materials.crack_flow import (choke_factor, choke_factor_np, crack_mass_flux, crack_mass_flux_np)


def test_choke_factor_is_the_isentropic_critical_mass_flux():
    """Φ = ρ*u*/(ρ0c0) = (2/(γ+1))^((γ+1)/(2(γ−1))) from ρ*/ρ0 = (2/(γ+1))^(1/(γ−1)) and u*/c0 = √(2/(γ+1))."""
    for g in (1.2, 1.4, 3.0):
        rho_ratio = (2 / (g + 1)) ** (1 / (g - 1))
        u_ratio = np.sqrt(2 / (g + 1))
        assert choke_factor_np(g) == pytest.approx(rho_ratio * u_ratio, rel=1e-12)
    assert choke_factor_np(1.4) == pytest.approx(0.5787, abs=1e-4)     # textbook value for air


@wp.kernel
def _eval(rho: wp.array(dtype=wp.float64), c: wp.array(dtype=wp.float64), g: wp.array(dtype=wp.float64),
          w: wp.array(dtype=wp.float64), dp: wp.array(dtype=wp.float64), mu: wp.float64, dx: wp.float64,
          out: wp.array(dtype=wp.float64), phi: wp.array(dtype=wp.float64)):
    i = wp.tid()
    out[i] = crack_mass_flux(rho[i], c[i], g[i], w[i], dp[i], mu, dx)
    phi[i] = choke_factor(g[i])


def test_mass_flux_kernel_matches_twin_and_limits():
    rng = np.random.default_rng(0)
    n = 200
    rho = rng.uniform(1, 1500, n)
    c = rng.uniform(300, 5000, n)
    g = rng.uniform(1.1, 3.5, n)
    w = 10 ** rng.uniform(-7, -3, n)
    dp = 10 ** rng.uniform(2, 9, n)
    mu, dx = 1e-4, 1e-3
    arr = [wp.array(a, dtype=wp.float64) for a in (rho, c, g, w, dp)]
    out, phi = wp.zeros(n, dtype=wp.float64), wp.zeros(n, dtype=wp.float64)
    wp.launch(_eval, dim=n, inputs=[*arr, wp.float64(mu), wp.float64(dx)], outputs=[out, phi])
    ref = crack_mass_flux_np(rho, c, g, w, dp, mu, dx)
    np.testing.assert_allclose(out.numpy(), ref, rtol=1e-12)
    np.testing.assert_allclose(phi.numpy(), choke_factor_np(g), rtol=1e-12)
    visc = rho * w**3 * dp / (12 * mu * dx)                 # cubic law
    choked = rho * w * choke_factor_np(g) * c
    np.testing.assert_allclose(ref, np.minimum(visc, choked), rtol=1e-12)
    assert (ref < visc * (1 - 1e-9)).any() and (ref < choked * (1 - 1e-9)).any()   # both regimes sampled
    assert crack_mass_flux_np(1000.0, 3000.0, 3.0, 0.0, 1e8, mu, dx) == 0.0         # closed crack
    assert crack_mass_flux_np(1000.0, 3000.0, 3.0, 1e-4, -1e8, mu, dx) == 0.0       # the donor is the other side


@wp.kernel
def _quad(x: wp.array(dtype=wp.vec2d), area: wp.array(dtype=wp.float64), grad: wp.array(dtype=wp.vec2d)):
    area[0] = quad_area(x[0], x[1], x[2], x[3])
    grad[0] = quad_area_gradient(x[3], x[1])
    grad[1] = quad_area_gradient(x[0], x[2])
    grad[2] = quad_area_gradient(x[1], x[3])
    grad[3] = quad_area_gradient(x[2], x[0])


def test_face_load_is_the_virtual_work_of_the_pressure():
    """f_k = p ∂V/∂x_k: for any small motion δx, Σ f·δx = p δV (central difference of the shoelace area), and the
    four forces sum to zero (no net force from a gas held between two faces)."""
    rng = np.random.default_rng(1)
    for _ in range(20):
        x = np.array([[1.0, 0.1], [0.0, 0.1], [0.0, 0.0], [1.0, 0.0]]) * 1e-3 + rng.normal(0, 2e-5, (4, 2))

        def area(xx):
            a, g = wp.zeros(1, dtype=wp.float64), wp.zeros(4, dtype=wp.vec2d)
            wp.launch(_quad, dim=1, inputs=[wp.array(xx, dtype=wp.vec2d)], outputs=[a, g])
            return a.numpy()[0], g.numpy()

        A, G = area(x)
        d = rng.normal(0, 1e-9, (4, 2))
        dV = area(x + d)[0] - area(x - d)[0]
        assert np.sum(G * 2 * d) == pytest.approx(dV, rel=1e-6)
        np.testing.assert_allclose(G.sum(0), 0.0, atol=1e-18)
        shoelace = 0.5 * np.sum(x[:, 0] * np.roll(x[:, 1], -1) - np.roll(x[:, 0], -1) * x[:, 1])
        assert A == pytest.approx(shoelace, rel=1e-12)
