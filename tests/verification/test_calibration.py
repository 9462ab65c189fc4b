"""Simulated laboratory tests (issue 5): coarse UCS and Brazilian runs.

- The elastic slope of the UCS test matches the analytic effective modulus of the block–spring
  system (METHOD §1.2, computed here from the formula) within 5 %.
- Strengths are positive and finite, and move by less than STRENGTH_RTOL when the platen speed
  is halved (quasi-static control).
- The Brazilian disc splits: its first tensile failures lie in the central part of the disc.
- The platen contact force (Warp) equals its NumPy twin.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from blastfrac.calibration import LoadSettings, run_brazilian, run_ucs
from blastfrac.calibration.curves import first_peak, plane_strain_to_3d
from blastfrac.scenario.schema import RockConfig
from conftest import effective_plane_strain_moduli, interior_edge_density

KN, KS = 2e14, 1e14            # Pa/m: soft enough that the springs add ~10 % compliance
ROCK = RockConfig(density=2600.0, youngs_modulus=50e9, poisson_ratio=0.2, stiffness_mode="per_area", kn=KN, ks=KS,
                  tensile_strength=5e6, cohesion=12e6, friction_angle=30.0)
MESH = 0.006                    # m: 432-element prism, coarse disc
SPEED = 0.02                    # m/s per platen
# Allowed change of UCS and σt when the speed is halved. Measured on this coarse disc the
# damped strength falls about linearly with speed (3.83, 3.47, 3.21 MPa at 0.1, 0.05, 0.025 m/s),
# so 0.02 → 0.01 m/s should move it by ~3 %; 5 % leaves room for mesh-scale noise.
STRENGTH_RTOL = 0.05


@pytest.fixture(scope="module")
def ucs_pair():
    s = LoadSettings(speed=SPEED)
    return run_ucs(ROCK, s, MESH), run_ucs(ROCK, replace(s, speed=SPEED / 2), MESH)


@pytest.fixture(scope="module")
def braz_pair():
    s = LoadSettings(speed=SPEED, jaw_ratio=1.0, loading_arc=15.0, sample_strain=2e-6, max_strain=0.005)
    return run_brazilian(ROCK, s, MESH), run_brazilian(ROCK, replace(s, speed=SPEED / 2), MESH)


def test_ucs_elastic_modulus_matches_spring_compliance_formula(ucs_pair):
    r = ucs_pair[1]
    Ep_eff, nup_eff = effective_plane_strain_moduli(ROCK.youngs_modulus, ROCK.poisson_ratio,
                                                    interior_edge_density(r.specimen.model), KN, KS)
    Ep_blocks = ROCK.youngs_modulus / (1 - ROCK.poisson_ratio**2)
    print(f"E' measured {r.youngs_modulus_ps / 1e9:.2f} GPa, analytic {Ep_eff / 1e9:.2f} GPa "
          f"(blocks alone {Ep_blocks / 1e9:.2f}); ν' {r.poisson_ratio_ps:.4f} vs {nup_eff:.4f}")
    # the springs must soften the blocks visibly, or this test could not tell the formula from E'
    assert Ep_eff < 0.96 * Ep_blocks
    assert r.youngs_modulus_ps == pytest.approx(Ep_eff, rel=0.05)
    assert r.poisson_ratio_ps == pytest.approx(nup_eff, abs=0.03)
    E, nu = plane_strain_to_3d(r.youngs_modulus_ps, r.poisson_ratio_ps)
    assert (r.youngs_modulus, r.poisson_ratio) == pytest.approx((E, nu))


def test_ucs_strength_is_finite_and_quasi_static(ucs_pair):
    full, half = ucs_pair
    for r in ucs_pair:
        assert math.isfinite(r.ucs) and r.ucs > 0
        assert r.run.stopped in ("post_peak_drop", "post_peak_strain")
        assert r.peak_index < len(r.stress) - 1         # a real peak, followed by failure
    change = (half.ucs - full.ucs) / full.ucs
    print(f"UCS {full.ucs / 1e6:.2f} MPa at {SPEED} m/s, {half.ucs / 1e6:.2f} MPa at half speed ({change:+.2%})")
    assert abs(change) < STRENGTH_RTOL


def test_brazilian_strength_and_central_initiation(braz_pair):
    full, half = braz_pair
    for r in braz_pair:
        assert math.isfinite(r.tensile_strength) and r.tensile_strength > 0
        # 2P/(πD) at the recorded peak load
        assert r.tensile_strength == pytest.approx(2 * r.load.max() / (math.pi * 0.054), rel=0.2)
    change = (half.tensile_strength - full.tensile_strength) / full.tensile_strength
    print(f"σt {full.tensile_strength / 1e6:.2f} MPa, half speed {half.tensile_strength / 1e6:.2f} MPa "
          f"({change:+.2%}); first tensile failures median r/R = {half.initiation_radius:.2f}")
    assert abs(change) < STRENGTH_RTOL
    xy = half.first_tensile_xy
    assert len(xy) > 0
    # splitting: the first tensile failures lie near the loaded diameter, not at the platens' ends
    assert np.median(np.abs(xy[:, 0])) < 0.25 * 0.027
    assert half.initiation_radius < 0.6


def test_first_peak_ignores_post_failure_rehardening():
    s = np.array([0, 10, 20, 30, 29, 25, 31, 40, 10.0])
    assert first_peak(s, 0.02) == 3
    assert first_peak(np.array([0, 1, 2, 3.0]), 0.02) == 3


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
