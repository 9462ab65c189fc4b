"""Heterogeneous rock (issue 15 item 1): Weibull spring properties per interface (model/heterogeneity.py).

- The drawn field has the asked moments: mean 1·(the scenario's value) and CV(m) within 4 standard errors
  of the actual number of interfaces (delta method on the exact Weibull moments), for m = 2, 5, 10, and passes
  a Kolmogorov–Smirnov test against the Weibull CDF.
- Same seed → identical field, different seed → different; both springs of an interface are equal; no
  heterogeneity (the default) is bit-identical to the homogeneous model; correlated = false gives independent
  T and c, and each property keeps its own stream.
- Stiffness: the stable step is the Gershgorin bound of the drawn stiffnesses (below 2/ω_max of the assembled
  K, M, whereas the homogeneous step is above it) and still covers block contact; the compliance
  compensation uses Σ L/k of the drawn springs, and the exact static modulus of a compensated prism then
  stays within 1 % of the input for m ≥ 3.
- Fracture energy: one softening rate from the rms strength; each interface dissipates G_f·(T_q/T_rms)²
  (integrated with the NumPy spring law), area-weighted mean G_f.
- Validation names the key; the options appear in resolved.toml.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from blastfrac.model.builder import ModelBuilder
from blastfrac.model.heterogeneity import (fracture_energy_per_area, interface_factors, mean_inverse, weibull_cdf,
                                           weibull_cv, weibull_scale)
from blastfrac.scenario import ScenarioError, scenario_from_dict
from blastfrac.scenario.load import resolved_dict
from conftest import scenario

T_MEAN, C_MEAN = 10e6, 40e6          # RockConfig defaults
BIG = {"domain": {"type": "rectangle", "width": 0.2, "height": 0.2}, "mesh_size": 0.004}   # ~9900 interfaces
SMALL = {"domain": {"type": "rectangle", "width": 0.04, "height": 0.04}, "mesh_size": 0.003}


@pytest.fixture(scope="module")
def big_mesh():
    from blastfrac.geometry.mesh import generate_mesh

    return generate_mesh(scenario(geometry=BIG).geometry)


def build(mesh=None, seed=0, geometry=BIG, **rock):
    sc = scenario(rock={"unbreakable": False, **rock}, geometry=geometry, simulation={"seed": seed})
    return ModelBuilder(sc, mesh)


def weibull_moment(m: float, k: int) -> float:
    """E[w^k] of the unit-mean Weibull variable: λ^k Γ(1 + k/m)."""
    return weibull_scale(m) ** k * math.gamma(1.0 + k / m)


def cv_standard_error(m: float, n: int) -> float:
    """Standard error of the sample CV of n unit-mean Weibull draws (delta method on (x̄, mean x²))."""
    m1, m2, m3, m4 = (weibull_moment(m, k) for k in (1, 2, 3, 4))
    sig = math.sqrt(m2 - m1**2)
    grad = np.array([-1.0 / sig - sig / m1**2, 1.0 / (2.0 * sig * m1)])
    cov = np.array([[m2 - m1**2, m3 - m1 * m2], [m3 - m1 * m2, m4 - m2**2]])
    return math.sqrt(grad @ cov @ grad / n)


def test_weibull_helpers():
    assert weibull_cv(1.0) == pytest.approx(1.0, rel=1e-12)                 # exponential
    assert weibull_cv(2.0) == pytest.approx(math.sqrt(4 / math.pi - 1), rel=1e-12)   # Rayleigh
    assert weibull_cv(1e4) < 2e-4
    for m in (0.5, 2.0, 5.0, 10.0):
        assert weibull_moment(m, 1) == pytest.approx(1.0, rel=1e-12)        # unit mean
        # the CDF integrates to the same unit mean: ∫(1 − F) dw
        w = np.linspace(0.0, 40.0 if m < 1 else 8.0, 400001)
        assert np.trapezoid(1.0 - weibull_cdf(w, m), w) == pytest.approx(1.0, rel=2e-3)
    assert mean_inverse(2.0) == pytest.approx(math.pi / 2, rel=1e-12) and mean_inverse(1.0) == math.inf


@pytest.mark.parametrize("m", [2.0, 5.0, 10.0])
def test_sampled_field_has_the_weibull_moments_and_distribution(big_mesh, m):
    from scipy.stats import kstest

    b = build(big_mesh, heterogeneity={"weibull_modulus": m})
    t, c = b.host["pair_t0"], b.host["pair_c0"]
    w = t[0::2] / T_MEAN
    n = len(w)
    mean, cv = w.mean(), w.std(ddof=1) / w.mean()
    se_mean, se_cv = weibull_cv(m) / math.sqrt(n), cv_standard_error(m, n)
    ks = kstest(w, lambda x: weibull_cdf(x, m))
    print(f"m = {m:g}: {n} interfaces, mean {mean:.4f} (±{se_mean:.4f}), CV {cv:.4f} vs CV(m) {weibull_cv(m):.4f} "
          f"(±{se_cv:.4f}), KS D = {ks.statistic:.4f}, p = {ks.pvalue:.3f}")
    assert n > 9000
    assert abs(mean - 1.0) < 4 * se_mean
    assert abs(cv - weibull_cv(m)) < 4 * se_cv
    assert ks.pvalue > 0.01
    # both springs of an interface carry the same draw; correlated (default): c has the same factor as T
    np.testing.assert_array_equal(t[0::2], t[1::2])
    np.testing.assert_array_equal(c[0::2], c[1::2])
    np.testing.assert_allclose(c[0::2] / C_MEAN, w, rtol=1e-14)
    # the stiffness is not listed by default: homogeneous springs
    np.testing.assert_array_equal(b.host["pair_kn"], build(big_mesh).host["pair_kn"])


def test_seeded_reproducible_and_homogeneous_by_default(big_mesh):
    het = {"weibull_modulus": 3.0}
    a, a2, b = build(big_mesh, 0, heterogeneity=het), build(big_mesh, 0, heterogeneity=het), build(big_mesh, 1, heterogeneity=het)
    np.testing.assert_array_equal(a.host["pair_t0"], a2.host["pair_t0"])
    assert np.mean(a.host["pair_t0"] != b.host["pair_t0"]) > 0.99
    # default (weibull_modulus None) and an explicit None: exactly the homogeneous model
    h0 = build(big_mesh)
    h1 = build(big_mesh, heterogeneity={"weibull_modulus": None, "fields": ["tensile_strength", "stiffness"]})
    assert not h0.factors and not h1.factors
    for h in (h0, h1):
        assert np.all(h.host["pair_t0"] == T_MEAN) and np.all(h.host["pair_c0"] == C_MEAN)
    for key in ("pair_kn", "pair_ks", "pair_t0", "pair_c0", "pair_kn_area"):
        np.testing.assert_array_equal(h0.host[key], h1.host[key])
    assert (h0.stable_dt, h0.slope_t, h0.slope_c) == (h1.stable_dt, h1.slope_t, h1.slope_c)


def test_independent_draws_and_per_property_streams(big_mesh):
    corr = build(big_mesh, heterogeneity={"weibull_modulus": 5.0})
    ind = build(big_mesh, heterogeneity={"weibull_modulus": 5.0, "correlated": False})
    wt, wc = ind.host["pair_t0"][0::2] / T_MEAN, ind.host["pair_c0"][0::2] / C_MEAN
    r = np.corrcoef(wt, wc)[0, 1]
    print(f"independent T, c: correlation {r:+.4f} (4/√N = {4 / math.sqrt(len(wt)):.4f})")
    assert abs(r) < 4 / math.sqrt(len(wt))
    assert abs(wc.std() / wc.mean() - weibull_cv(5.0)) < 4 * cv_standard_error(5.0, len(wc))
    # T keeps its stream whether c is correlated with it or not, and whatever else is listed
    np.testing.assert_array_equal(corr.host["pair_t0"], ind.host["pair_t0"])
    only_c = build(big_mesh, heterogeneity={"weibull_modulus": 5.0, "fields": ["cohesion"], "correlated": False})
    np.testing.assert_array_equal(only_c.host["pair_c0"], ind.host["pair_c0"])
    assert np.all(only_c.host["pair_t0"] == T_MEAN)


def test_stiffness_field_scales_both_springs_and_the_compliance(big_mesh):
    base = build(big_mesh)
    b = build(big_mesh, heterogeneity={"weibull_modulus": 3.0, "fields": ["stiffness"]})
    w = b.factors["stiffness"]
    for key in ("pair_kn", "pair_ks", "pair_kn_area"):
        np.testing.assert_allclose(b.host[key], base.host[key] * np.repeat(w, 2), rtol=1e-14)
    assert np.all(b.host["pair_t0"] == T_MEAN)
    # the mean stiffness is kept: Σ k_q w_q / Σ k_q = 1 within 4 standard errors CV(m)·√(Σ k_q²)/Σ k_q
    k0 = base.host["pair_kn"][0::2]
    ratio = b.host["pair_kn"].mean() / base.host["pair_kn"].mean()
    assert abs(ratio - 1.0) < 4 * weibull_cv(3.0) * math.sqrt(np.sum(k0**2)) / np.sum(k0)
    # the compensation sees the drawn compliances Σ L/k, ≈ E[1/w] = Γ(2/3)Γ(4/3) = 1.209 times the nominal
    s_ratio = b.elastic.s_n / base.elastic.s_n
    print(f"stiffness m = 3: mean k ratio {ratio:.4f}, compliance ratio {s_ratio:.4f} (E[1/w] {mean_inverse(3.0):.4f}),"
          f" block E {base.elastic.block_E / 1e9:.2f} → {b.elastic.block_E / 1e9:.2f} GPa, "
          f"stable step {base.stable_dt:.3e} → {b.stable_dt:.3e} s")
    assert s_ratio == pytest.approx(mean_inverse(3.0), rel=0.05)
    assert b.elastic.block_E > base.elastic.block_E
    assert b.elastic.assembly_E == pytest.approx(50e9, rel=1e-12)
    assert b.stable_dt < base.stable_dt


def test_stable_step_uses_the_drawn_stiffness():
    """Lumped mass, unbreakable springs (no contact allowance): Gershgorin ≤ 2/ω_max of the assembled K, M.
    The homogeneous model's step would exceed the heterogeneous model's true limit."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from blastfrac.calibration.elastic import stiffness_matrix

    def exact_dt(model):
        K = stiffness_matrix(model)
        M = sp.diags(np.repeat(model.host["node_mass"], 2))
        return 2.0 / math.sqrt(spla.eigsh(K, k=1, M=M, which="LA", return_eigenvectors=False)[0])

    rock = {"unbreakable": True, "mass_matrix": "lumped"}
    hom = build(geometry=SMALL, **rock).finalize("cpu")
    for m in (3.0, 1.5):
        het = build(geometry=SMALL, heterogeneity={"weibull_modulus": m, "fields": ["stiffness"]}, **rock).finalize("cpu")
        exact = exact_dt(het)
        print(f"m = {m:g}: Gershgorin {het.stable_dt:.4e} s, 2/ω_max {exact:.4e} s, homogeneous Gershgorin "
              f"{hom.stable_dt:.4e} s (its own 2/ω_max {exact_dt(hom):.4e} s)")
        assert het.stable_dt <= exact
        assert het.stable_dt > 0.8 * exact                      # and not needlessly small
        assert hom.stable_dt > exact                            # the homogeneous step would be unstable


def test_stable_step_covers_block_contact_with_drawn_stiffness():
    """METHOD §1.7 with heterogeneous springs: the contact penalty uses the mean kn, the builder's allowance the
    node's own springs; the model step must stay below the bound with every node in contact."""
    from blastfrac.cdem.solver import CDEMSolver

    geom = {"domain": {"type": "disc", "radius": 0.02}, "boreholes": [{"radius": 0.004}],
            "mesh_size": 0.003, "mesh_size_near": 0.001, "refinement_distance": 0.01}
    for m in (3.0, 1.5):
        mod = build(geometry=geom, heterogeneity={"weibull_modulus": m, "fields": ["stiffness"]}).finalize("cpu")
        bound = CDEMSolver(mod).contact.stable_dt()
        print(f"m = {m:g}: stable step {mod.stable_dt:.4e} s, bound with every node in contact {bound:.4e} s")
        assert mod.stable_dt <= bound


def test_compensated_prism_keeps_the_input_modulus_with_drawn_stiffness():
    """Exact static solve of a compensated UCS prism (penalty springs β = 20): within 1 % of the input E' for
    m ≥ 3 (the harmonic-mean compensation is a series estimate: the lattice comes out slightly stiffer)."""
    from blastfrac.calibration.elastic import static_moduli
    from blastfrac.calibration.specimens import ucs_specimen
    from blastfrac.scenario.schema import RockConfig

    Ep_in = 50e9 / (1 - 0.2**2)
    out = {}
    for m in (None, 10.0, 3.0):
        het = {} if m is None else {"heterogeneity": {"weibull_modulus": m, "fields": ["stiffness"]}}
        rock = RockConfig(density=2600.0, youngs_modulus=50e9, poisson_ratio=0.2, unbreakable=True, **het)
        out[m] = static_moduli(ucs_specimen(rock, 0.003))[0] / Ep_in
    print("static E'/E'_input: " + ", ".join(f"m = {k}: {v:.4f}" for k, v in out.items()))
    assert out[None] == pytest.approx(1.0, abs=1e-3)
    for m in (10.0, 3.0):
        assert 0.999 < out[m] < 1.01
    assert out[3.0] > out[10.0]


def test_fracture_energy_mean_kept_and_scaled_by_strength_squared(big_mesh):
    """One softening rate s = T_rms²/(2(G_f − T_rms²/2k)): per_area springs (uniform k), so interface q
    dissipates G_f·(T_q/T_rms)² exactly and the area-weighted mean is G_f. Checked against the spring law."""
    from blastfrac.materials.interface import np_spring_update_intact

    gf, k = 50.0, 2e14
    b = build(big_mesh, stiffness_mode="per_area", kn=k, ks=k, tensile_fracture_energy=gf,
              shear_fracture_energy=10 * gf, heterogeneity={"weibull_modulus": 3.0})
    t = b.host["pair_t0"][0::2]
    L = b.host["pair_l0"][0::2]
    e = fracture_energy_per_area(t, k, b.slope_t)
    t_rms = math.sqrt(np.sum(L * t**2) / np.sum(L))
    np.testing.assert_allclose(e, gf * (t / t_rms) ** 2, rtol=1e-12)
    assert np.sum(L * e) / np.sum(L) == pytest.approx(gf, rel=1e-12)
    c = b.host["pair_c0"][0::2]
    assert np.sum(L * fracture_energy_per_area(c, k, b.slope_c)) / np.sum(L) == pytest.approx(10 * gf, rel=1e-12)
    # the spring law itself: open the weakest, a median and the strongest interface to failure, integrate σ dn
    for q in (int(np.argmin(t)), int(np.argsort(t)[len(t) // 2]), int(np.argmax(t))):
        dn, fn, st, work = t[q] / k / 2000.0, 0.0, t[q], 0.0
        for _ in range(10**6):
            fn_new, _, st, _, mode = np_spring_update_intact(fn, 0.0, st, 1e12, dn, 0.0, k, k, 1.0, 0.0, 0.0,
                                                             b.slope_t, 0.0)
            work += 0.5 * (-fn - fn_new) * dn
            fn = fn_new
            if mode:
                break
        print(f"T_q = {t[q] / 1e6:.2f} MPa: dissipated {work:.3f} J/m², G_f·(T_q/T_rms)² = {e[q]:.3f} J/m²")
        assert work == pytest.approx(e[q], rel=2e-3)


def test_bad_values_name_the_key_and_options_are_resolved():
    def sc(het):
        return scenario_from_dict({"rock": {"heterogeneity": het},
                                   "geometry": {"domain": {"type": "rectangle", "width": 0.02, "height": 0.02},
                                                "mesh_size": 0.005}})

    for het, msg in (({"weibull_modulus": 0.0}, r"rock\.heterogeneity\.weibull_modulus: .*greater than 0"),
                     ({"weibull_modulus": -2.0}, r"rock\.heterogeneity\.weibull_modulus"),
                     ({"weibull_modulus": float("nan")}, r"rock\.heterogeneity\.weibull_modulus: must be a finite"),
                     ({"weibull_modulus": 3.0, "fields": ["tensile"]}, r"rock\.heterogeneity\.fields\[0\]: .*'stiffness'"),
                     ({"weibull_modulus": 3.0, "fields": []}, r"rock\.heterogeneity\.fields"),
                     ({"fields": ["cohesion", "cohesion"]}, r"rock\.heterogeneity\.fields: 'cohesion' is listed twice"),
                     ({"weibull_modulus": 1.0, "fields": ["stiffness"]},
                      r"rock\.heterogeneity\.weibull_modulus: 1\.0 is too small for 'stiffness'"),
                     ({"modulus": 3.0}, r"rock\.heterogeneity\.modulus: unknown key"),
                     ({"correlated": "sometimes"}, r"rock\.heterogeneity\.correlated")):
        with pytest.raises(ScenarioError, match=msg):
            sc(het)
    ok = sc({"weibull_modulus": 0.5})        # any m > 0 for the strengths
    assert ok.rock.heterogeneity.active
    r = resolved_dict(ok)["rock"]["heterogeneity"]
    assert r == {"weibull_modulus": 0.5, "fields": ["tensile_strength", "cohesion"], "correlated": True}
    assert resolved_dict(sc({}))["rock"]["heterogeneity"] == {"fields": ["tensile_strength", "cohesion"],
                                                              "correlated": True}
    assert interface_factors(sc({}).rock.heterogeneity, 10, 0) == {}
