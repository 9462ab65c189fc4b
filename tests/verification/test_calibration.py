"""Simulated laboratory tests (issue 5): a coarse UCS and a coarse Brazilian run.

- The elastic slope of the UCS run matches the analytic effective modulus of the block–spring
  medium (METHOD §1.2, written out below) within 5 %.
- The strengths are positive and finite and move by at most 2 % when the platen speed is halved
  (the documented quasi-static control: LoadSettings() defaults, undamped, 0.05 m/s per platen).
- The Brazilian disc splits: its first tensile failures lie in the central part of the disc.
- The exact static solve of the prism agrees with the formula and, with the paper's stiff springs,
  stays below the blocks' modulus (springs only add compliance).
- At the Table 3 strengths σt is set by Mohr–Coulomb under tension (switching T off changes nothing)
  and sits just below the continuum limit c·cosφ/(2 − sinφ); with tension alone it sits below T.
- Helpers: first-peak reading, the fit's 1-D root finder, the platen contact force (Warp = NumPy).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from blastfrac.calibration import LoadSettings, run_brazilian, run_ucs
from blastfrac.calibration.brazilian import brazilian_settings
from blastfrac.calibration.curves import first_peak, plane_strain_to_3d
from blastfrac.scenario.schema import RockConfig

E_BLOCK, NU_BLOCK = 50e9, 0.2  # Table 2 blocks
KN, KS = 2e14, 1e14            # Pa/m: soft enough that the springs add ~9 % compliance on the prism
# the paper's Table 3 strengths on these softer springs
ROCK = RockConfig(density=2600.0, youngs_modulus=E_BLOCK, poisson_ratio=NU_BLOCK, stiffness_mode="per_area",
                  kn=KN, ks=KS, tensile_strength=14e6, cohesion=26e6, friction_angle=60.0)
UCS_MESH = 0.006                # m: 432-element prism
DISC_MESH = 0.003               # m: ~780-element disc (coarser discs fail at the jaws before they split)
SPEED = LoadSettings().speed    # the documented quasi-static control
HALVING_RTOL = 0.02             # issue 5: halving the speed moves the peak by at most 2 %


def analytic_plane_strain_moduli(E: float, nu: float, ell: float, kn: float, ks: float) -> tuple[float, float]:
    """METHOD §1.2: 1/E'_eff = 1/E' + ℓ(3/(8kn) + 1/(8ks)), ν'_eff/E'_eff = ν'/E' − ℓ(1/kn − 1/ks)/8."""
    Ep, nup = E / (1 - nu**2), nu / (1 - nu)
    Ep_eff = 1.0 / (1.0 / Ep + ell * (3.0 / (8.0 * kn) + 1.0 / (8.0 * ks)))
    return Ep_eff, Ep_eff * (nup / Ep - ell * (1.0 / kn - 1.0 / ks) / 8.0)


def edge_density(model) -> float:
    """ℓ: interior edge length per unit area of the mesh [1/m]."""
    return float(model.host["pair_l0"][0::2].sum() / model.host["elem_area0"].sum())


@pytest.fixture(scope="module")
def ucs_pair():
    s = LoadSettings()
    return run_ucs(ROCK, s, UCS_MESH), run_ucs(ROCK, replace(s, speed=SPEED / 2), UCS_MESH)


@pytest.fixture(scope="module")
def braz_pair():
    s = brazilian_settings()
    return run_brazilian(ROCK, s, DISC_MESH), run_brazilian(ROCK, replace(s, speed=SPEED / 2), DISC_MESH)


def test_ucs_elastic_modulus_matches_analytic_effective_modulus(ucs_pair):
    ell = edge_density(ucs_pair[0].specimen.model)
    Ep_eff, nup_eff = analytic_plane_strain_moduli(E_BLOCK, NU_BLOCK, ell, KN, KS)
    Ep_blocks = E_BLOCK / (1 - NU_BLOCK**2)
    # the springs must soften the blocks visibly, or the test could not tell the formula from E'
    assert Ep_eff < 0.95 * Ep_blocks
    for r in ucs_pair:
        print(f"v = {r.settings.speed} m/s: E' measured {r.youngs_modulus_ps / 1e9:.3f} GPa, analytic "
              f"{Ep_eff / 1e9:.3f} GPa (blocks alone {Ep_blocks / 1e9:.2f}); ν' {r.poisson_ratio_ps:.4f} vs "
              f"{nup_eff:.4f}")
        assert r.youngs_modulus_ps == pytest.approx(Ep_eff, rel=0.05)
        assert r.youngs_modulus_ps < Ep_blocks
        assert r.poisson_ratio_ps == pytest.approx(nup_eff, abs=0.02)
        E, nu = plane_strain_to_3d(r.youngs_modulus_ps, r.poisson_ratio_ps)
        assert (r.youngs_modulus, r.poisson_ratio) == pytest.approx((E, nu))


def test_ucs_strength_positive_finite_and_stable_at_half_speed(ucs_pair):
    full, half = ucs_pair
    for r in ucs_pair:
        assert math.isfinite(r.ucs) and r.ucs > 0
        assert r.run.stopped in ("post_peak_drop", "post_peak_strain")
        assert r.peak_index < len(r.stress) - 1         # a real peak, followed by failure
    change = (half.ucs - full.ucs) / full.ucs
    print(f"UCS {full.ucs / 1e6:.2f} MPa at {SPEED} m/s, {half.ucs / 1e6:.2f} MPa at half speed ({change:+.2%})")
    assert abs(change) <= HALVING_RTOL


def test_brazilian_strength_positive_finite_stable_and_central(braz_pair):
    full, half = braz_pair
    for r in braz_pair:
        assert math.isfinite(r.tensile_strength) and r.tensile_strength > 0
        assert r.tensile_strength == pytest.approx(2 * r.load[r.peak_index] / (math.pi * 0.054), rel=1e-12)
    change = (half.tensile_strength - full.tensile_strength) / full.tensile_strength
    print(f"σt {full.tensile_strength / 1e6:.3f} MPa, half speed {half.tensile_strength / 1e6:.3f} MPa "
          f"({change:+.2%}); first tensile failures median r/R = {full.initiation_radius:.2f}, "
          f"{half.initiation_radius:.2f}")
    assert abs(change) <= HALVING_RTOL
    for r in braz_pair:
        xy = r.first_tensile_xy
        assert len(xy) > 0
        # splitting: the first tensile failures lie near the loaded diameter, in the central part
        assert np.median(np.abs(xy[:, 0])) < 0.25 * 0.027
        assert r.initiation_radius < 0.6


def test_static_solve_matches_formula_and_stays_below_blocks_with_table3_springs():
    """The paper's Table 3 springs (kn 1.8e15, ks 1.6e15 Pa/m) are stiff: E' must sit just below the
    blocks' E' (the excess once measured with local damping α = 0.8 was a loading artefact)."""
    from blastfrac.calibration.elastic import static_moduli
    from blastfrac.calibration.specimens import ucs_specimen

    for kn, ks in ((1.8e15, 1.6e15), (KN, KS)):
        rock = ROCK.model_copy(update={"kn": kn, "ks": ks, "unbreakable": True})
        spec = ucs_specimen(rock, UCS_MESH)
        Ep, nup = static_moduli(spec)
        Ep_eff, nup_eff = analytic_plane_strain_moduli(E_BLOCK, NU_BLOCK, edge_density(spec.model), kn, ks)
        assert Ep < E_BLOCK / (1 - NU_BLOCK**2)
        assert Ep == pytest.approx(Ep_eff, rel=0.005)
        assert nup == pytest.approx(nup_eff, abs=0.002)


def test_first_peak_ignores_post_failure_rehardening():
    s = np.array([0, 10, 20, 30, 29, 25, 31, 40, 10.0])
    assert first_peak(s, 0.02) == 3
    assert first_peak(np.array([0, 1, 2, 3.0]), 0.02) == 3


def test_fit_root_finder_power_law_and_flat_response():
    from blastfrac.calibration.fit import fit_scalar

    x, y, pts = fit_scalar(lambda T: 0.6 * T**0.9, 20.0, 7.4, 0.005, 6, log=lambda *_: None)
    assert abs(y - 7.4) <= 0.005 * 7.4 and len(pts) <= 3
    # a response that saturates (coarse disc failing at the jaws): stop, do not run away
    x, y, pts = fit_scalar(lambda T: min(0.5 * T, 7.5), 8.0, 8.0, 0.02, 6, log=lambda *_: None)
    assert len(pts) <= 3 and all(p[0] <= 8.0 * 3.0**2 for p in pts)


def test_platen_force_warp_matches_numpy():
    import warp as wp

    from blastfrac.calibration.loading import platen_contact_force, platen_contact_force_np

    @wp.kernel
    def k(x: wp.array(dtype=wp.vec2d), apex: wp.float64, side: wp.float64, radius: wp.float64, kp: wp.float64,
          out: wp.array(dtype=wp.vec3d)):
        i = wp.tid()
        out[i] = platen_contact_force(x[i], apex, side, radius, kp)

    rng = np.random.default_rng(1)
    pts = rng.uniform(-0.03, 0.03, (200, 2))
    for side, radius in ((1.0, 0.0), (-1.0, 0.0), (1.0, 0.027), (-1.0, 0.04)):
        apex = 0.01 * side
        out = wp.zeros(len(pts), dtype=wp.vec3d, device="cpu")
        wp.launch(k, dim=len(pts), inputs=[wp.array(pts, dtype=wp.vec2d, device="cpu"), apex, side, radius, 1e12],
                  outputs=[out], device="cpu")
        ref = platen_contact_force_np(pts, apex, side, radius, 1e12)
        assert np.any(ref[:, 2] > 0) and np.any(ref[:, 2] == 0)
        np.testing.assert_allclose(out.numpy(), ref, rtol=1e-12, atol=1e-3)
        # the force pushes the node out of the platen: opposite to the side for flat platens
        assert np.all(side * ref[:, 1] <= 0)


def test_brazilian_strength_follows_the_governing_spring_criterion(braz_pair):
    """Issue 5 (why σt differs from Table 4): at the Table 3 strengths the disc is broken by Mohr–Coulomb
    under tension, not by T. Switching tension off must leave σt unchanged, and σt must sit just below
    the continuum limit c·cosφ/(2 − sinφ) of Mohr–Coulomb at the disc centre (σx = σt, σy = −3σt);
    with Mohr–Coulomb switched off, σt must sit just below T instead."""
    full = braz_pair[0]
    phi = math.radians(ROCK.friction_angle)
    mc_limit = ROCK.cohesion * math.cos(phi) / (2 - math.sin(phi))          # 11.46 MPa < T = 14 MPa
    s = brazilian_settings()
    mc_only = run_brazilian(ROCK.model_copy(update={"tensile_strength": 10e9}), s, DISC_MESH)
    t_only = run_brazilian(ROCK.model_copy(update={"cohesion": 10e9}), s, DISC_MESH)
    print(f"σt: both criteria {full.tensile_strength / 1e6:.3f}, Mohr–Coulomb only {mc_only.tensile_strength / 1e6:.3f} "
          f"(limit {mc_limit / 1e6:.2f}), tension only {t_only.tensile_strength / 1e6:.3f} MPa (T 14)")
    # this coarse disc with soft springs reaches 0.86 and 0.79 of the limits (paper disc: 0.93 and 0.94)
    assert mc_only.tensile_strength == pytest.approx(full.tensile_strength, rel=0.01)
    assert 0.75 * mc_limit < full.tensile_strength < mc_limit
    assert 0.75 * ROCK.tensile_strength < t_only.tensile_strength < ROCK.tensile_strength
    assert t_only.tensile_strength > 1.1 * full.tensile_strength
