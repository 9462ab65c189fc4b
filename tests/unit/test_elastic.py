"""CST elasticity: Jaumann update and strain energy, Warp vs NumPy and closed forms."""

import numpy as np
import warp as wp

from blastfrac.materials import elastic


@wp.kernel
def _update(sig: wp.array(dtype=wp.vec3d), g: wp.array(dtype=wp.mat22d), dt: wp.float64, lam: wp.float64,
            mu: wp.float64, out: wp.array(dtype=wp.vec3d), w: wp.array(dtype=wp.float64)):
    i = wp.tid()
    out[i] = elastic.jaumann_stress_update(sig[i], g[i], dt, lam, mu)
    w[i] = elastic.strain_energy_density(sig[i], lam, mu)


def test_jaumann_and_energy_match_twins():
    rng = np.random.default_rng(0)
    n = 500
    lam, mu = elastic.lame(50e9, 0.2)
    sig = rng.normal(0, 1e7, (n, 3))
    g = rng.normal(0, 1e3, (n, 2, 2))
    out = wp.zeros(n, dtype=wp.vec3d, device="cpu")
    w = wp.zeros(n, dtype=wp.float64, device="cpu")
    wp.launch(_update, dim=n, inputs=[wp.array(sig, dtype=wp.vec3d, device="cpu"), wp.array(g, dtype=wp.mat22d, device="cpu"),
                                      1e-7, lam, mu], outputs=[out, w], device="cpu")
    want = np.array([elastic.np_jaumann_stress_update(s, gg, 1e-7, lam, mu) for s, gg in zip(sig, g)])
    np.testing.assert_allclose(out.numpy(), want, rtol=1e-12, atol=1e-6)
    np.testing.assert_allclose(w.numpy(), [elastic.np_strain_energy_density(s, lam, mu) for s in sig], rtol=1e-12)


def test_uniaxial_strain_gives_p_wave_modulus():
    """A pure ε_xx increment gives σxx = (λ+2G)ε and σyy = λε (plane strain)."""
    E, nu = 50e9, 0.2
    lam, mu = elastic.lame(E, nu)
    g = np.array([[1.0, 0.0], [0.0, 0.0]])  # ∂vx/∂x = 1/s for 1e-6 s
    s = elastic.np_jaumann_stress_update(np.zeros(3), g, 1e-6, lam, mu)
    M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    np.testing.assert_allclose(s, [M * 1e-6, nu / (1 - nu) * M * 1e-6, 0.0], rtol=1e-12)
    # energy density ½ M ε²
    np.testing.assert_allclose(elastic.np_strain_energy_density(s, lam, mu), 0.5 * M * 1e-12, rtol=1e-12)


def test_bulk_viscosity_formula():
    """q = C_q ρ l² (trD)² − C_l ρ l c trD in compression, 0 in expansion (von Neumann–Richtmyer + Landshoff)."""
    from blastfrac.materials.artificial_viscosity import np_bulk_viscosity

    rho, l, c = 2600.0, 1e-3, 5000.0
    assert np_bulk_viscosity(1e4, rho, l, c, 1.5, 0.5) == 0.0
    trD = -2e5
    assert abs(np_bulk_viscosity(trD, rho, l, c, 1.5, 0.5) - (1.5 * rho * l**2 * 4e10 + 0.5 * rho * l * c * 2e5)) < 1e-6
