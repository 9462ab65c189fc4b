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
- Weakest-link size scaling (reference_length, issue 11 item 3): the builder's strengths are the unscaled draw
  times (L_ref/L_q)^(1/m) exactly (stiffness untouched); the survival of a chain of interfaces of total length
  ℓ under a uniform stress is exp(−(ℓ/L_ref)(σ/(λT̄))^m) whether it is cut into n, 2n or unequal pieces (Monte
  Carlo over 200 seeds, 4 standard errors), while the unscaled field gives exp(−n(σ/(λT̄))^m).
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


# ---------------------------------------------------------------- weakest-link size scaling (issue 11 item 3)
def het_cfg(m, reference_length=None, **kw):
    from blastfrac.scenario.schema import HeterogeneityConfig

    return HeterogeneityConfig(weibull_modulus=m, reference_length=reference_length, **kw)


def chain_strengths(cfg, pieces: np.ndarray, seeds, chains_per_seed: int) -> np.ndarray:
    """Strength [Pa] of chains of interfaces of lengths ``pieces`` [m] in series (the weakest interface),
    ``chains_per_seed`` chains from each seed's field: T̄ · min_q factor_q."""
    out = []
    for seed in seeds:
        lengths = np.tile(pieces, chains_per_seed)
        f = interface_factors(cfg, len(lengths), seed, lengths)["tensile_strength"]
        out.append(T_MEAN * f.reshape(chains_per_seed, len(pieces)).min(axis=1))
    return np.concatenate(out)


def test_size_scaled_factor_is_exactly_the_weakest_link_scale(big_mesh):
    """Per interface: T_q = T̄·w_q·(L_ref/L_q)^(1/m) (and c_q alike), w_q the unscaled draw of the same seed;
    the stiffness, when listed, is not scaled; the unit-mean field is recovered by dividing the scale out."""
    from blastfrac.model.heterogeneity import size_factor

    m, l_ref = 5.0, 0.003
    fields = ["tensile_strength", "cohesion", "stiffness"]
    plain = build(big_mesh, heterogeneity={"weibull_modulus": m, "fields": fields})
    scaled = build(big_mesh, heterogeneity={"weibull_modulus": m, "fields": fields, "reference_length": l_ref})
    L = scaled.host["pair_l0"][0::2]
    expect = (l_ref / L) ** (1.0 / m)
    np.testing.assert_allclose(size_factor(L, l_ref, m), expect, rtol=1e-15)
    for key in ("pair_t0", "pair_c0"):
        np.testing.assert_allclose(scaled.host[key][0::2] / plain.host[key][0::2], expect, rtol=1e-13)
        np.testing.assert_array_equal(scaled.host[key][0::2], scaled.host[key][1::2])
    for key in ("pair_kn", "pair_ks", "pair_kn_area"):
        np.testing.assert_array_equal(scaled.host[key], plain.host[key])
    assert scaled.stable_dt == plain.stable_dt
    w = scaled.host["pair_t0"][0::2] / T_MEAN / expect
    se = weibull_cv(m) / math.sqrt(len(w))
    print(f"L_q {L.min() * 1e3:.2f}–{L.max() * 1e3:.2f} mm, scale {expect.min():.4f}–{expect.max():.4f}; "
          f"mean of T_q/(T̄ s_q) {w.mean():.4f} (±{se:.4f})")
    assert abs(w.mean() - 1.0) < 4 * se
    # an interface of length L_ref has the mean T̄: the scale is 1 there
    assert size_factor(np.array([l_ref]), l_ref, m)[0] == 1.0
    # T only listed: c stays homogeneous (unscaled) even with the size scaling
    only_t = build(big_mesh, heterogeneity={"weibull_modulus": m, "fields": ["tensile_strength"],
                                            "reference_length": l_ref})
    assert np.all(only_t.host["pair_c0"] == C_MEAN)


@pytest.mark.parametrize("m", [3.0, 5.0])
def test_weakest_link_survival_does_not_depend_on_how_a_crack_is_cut(m):
    """A crack path of total length ℓ = 8 mm in series (the weakest interface breaks it), cut into n = 4 or
    2n = 8 equal interfaces, or into unequal ones (0.5, 1.5, 2, 4 mm), under a uniform stress σ. With
    reference_length L_ref = 1.5 mm the survival fraction over 200 seeds × 100 chains is
    P_s = exp(−(ℓ/L_ref)(σ/(λT̄))^m) for every cut (within 4 standard errors √(P(1−P)/N)); the mean chain
    strength is T̄(L_ref/ℓ)^(1/m) (within 4 s.e. CV(m)·mean/√N). Without the scaling the same draws give
    P_s = exp(−n(σ/(λT̄))^m): a chain of 2n interfaces is weaker."""
    from blastfrac.model.heterogeneity import weakest_link_survival

    ell, l_ref, seeds, per_seed = 0.008, 0.0015, range(200), 100
    cuts = {"n = 4": np.full(4, ell / 4), "2n = 8": np.full(8, ell / 8),
            "unequal": np.array([0.0005, 0.0015, 0.002, 0.004])}
    lam = weibull_scale(m)
    # stresses at which P_s = 0.8, 0.5, 0.2 for the scaled chain
    stresses = [lam * T_MEAN * (-math.log(p) * l_ref / ell) ** (1.0 / m) for p in (0.8, 0.5, 0.2)]
    scaled, plain = het_cfg(m, l_ref), het_cfg(m)
    surv = {}
    for name, pieces in cuts.items():
        s = chain_strengths(scaled, pieces, seeds, per_seed)
        n_chain = len(s)
        mean_expect = T_MEAN * (l_ref / ell) ** (1.0 / m)
        se_mean = weibull_cv(m) * mean_expect / math.sqrt(n_chain)
        print(f"m = {m:g}, {name}: mean chain strength {s.mean() / 1e6:.4f} MPa, T̄(L_ref/ℓ)^(1/m) = "
              f"{mean_expect / 1e6:.4f} (±{se_mean / 1e6:.4f})")
        assert abs(s.mean() - mean_expect) < 4 * se_mean
        for sig in stresses:
            p_hat, p = float(np.mean(s > sig)), weakest_link_survival(sig, ell, T_MEAN, m, l_ref)
            se = math.sqrt(p * (1.0 - p) / n_chain)
            print(f"    σ = {sig / 1e6:.3f} MPa: P_s {p_hat:.4f}, formula {p:.4f} (±{se:.4f})")
            assert abs(p_hat - p) < 4 * se
            surv[name, sig] = p_hat
        # without the size scaling: the survival of n i.i.d. unit-length-free interfaces
        if name != "unequal":
            u = chain_strengths(plain, pieces, seeds, per_seed)
            sig = stresses[1]
            p_u = math.exp(-len(pieces) * (sig / (lam * T_MEAN)) ** m)
            p_hat_u = float(np.mean(u > sig))
            print(f"    unscaled, σ = {sig / 1e6:.3f} MPa: P_s {p_hat_u:.4f}, exp(−n(σ/λT̄)^m) = {p_u:.4f}")
            assert abs(p_hat_u - p_u) < 4 * math.sqrt(p_u * (1.0 - p_u) / len(u))
            surv["plain", name] = p_hat_u
    # the scaled survival of the n and 2n cuts agree within 4 s.e. of a difference; the unscaled ones do not
    for sig in stresses:
        d = surv["n = 4", sig] - surv["2n = 8", sig]
        p = weakest_link_survival(sig, ell, T_MEAN, m, l_ref)
        assert abs(d) < 4 * math.sqrt(2 * p * (1 - p) / (len(seeds) * per_seed))
    assert surv["plain", "n = 4"] - surv["plain", "2n = 8"] > 0.1


def test_reference_length_is_validated_and_resolved():
    def sc(het):
        return scenario_from_dict({"rock": {"heterogeneity": het},
                                   "geometry": {"domain": {"type": "rectangle", "width": 0.02, "height": 0.02},
                                                "mesh_size": 0.005}})

    for bad, msg in ((0.0, r"rock\.heterogeneity\.reference_length: .*greater than 0"),
                     (-1e-3, r"rock\.heterogeneity\.reference_length"),
                     (float("inf"), r"rock\.heterogeneity\.reference_length"),
                     ("1 mm", r"rock\.heterogeneity\.reference_length")):
        with pytest.raises(ScenarioError, match=msg):
            sc({"weibull_modulus": 5.0, "reference_length": bad})
    r = resolved_dict(sc({"weibull_modulus": 5.0, "reference_length": 0.005}))["rock"]["heterogeneity"]
    assert r == {"weibull_modulus": 5.0, "fields": ["tensile_strength", "cohesion"], "correlated": True,
                 "reference_length": 0.005}
    # off unless weibull_modulus is given; the factors need the lengths
    assert interface_factors(sc({"reference_length": 0.005}).rock.heterogeneity, 10, 0) == {}
    with pytest.raises(ValueError, match="reference_length"):
        interface_factors(het_cfg(5.0, 0.005), 10, 0)


# ---------------------------------------------------------------------------------------------------------------
# Spatially correlated field (correlation_length, issue 11 item 3): a Gaussian field of covariance
# exp(−r²/(2ℓ²)) sampled at the interface midpoints, mapped onto the Weibull marginal

def gaussian_covariance_bounds(r: float, ell: float, modes: int) -> tuple[float, float]:
    """The ensemble covariance exp(−r²/(2ℓ²)) of the field at lag r, and the standard deviation of a
    realisation's spatial covariance (1/N)Σcos(k_j·r), k_j ~ N(0, I/ℓ²): √(Var[cos(k·r)]/N), with
    E[cos²(k·r)] = (1 + exp(−2r²/ℓ²))/2."""
    rho = math.exp(-r**2 / (2 * ell**2))
    var = 0.5 * (1.0 + math.exp(-2 * r**2 / ell**2)) - rho**2
    return rho, math.sqrt(var / modes)


def test_correlated_field_has_unit_variance_and_the_gaussian_covariance():
    from blastfrac.model.heterogeneity import FOURIER_MODES, GaussianField, stream

    ell = 0.004
    g = GaussianField(ell, stream(0, "tensile_strength"))
    # a 400ℓ square sampled every ℓ/2: spatial averages stand for the ensemble's
    s = np.arange(0.0, 400 * ell, 0.5 * ell)
    xx, yy = np.meshgrid(s, s, indexing="ij")
    p = np.stack([xx.ravel(), yy.ravel()], 1)
    v = g(p).reshape(xx.shape)
    print(f"\nmean {v.mean():+.4f}, variance {v.var():.4f}")
    assert abs(v.mean()) < 0.02 and abs(v.var() - 1.0) < 0.02
    for lag in (1, 2, 4, 8):                      # lags of ℓ/2 … 4ℓ along x and along y
        r = 0.5 * ell * lag
        rho, sd = gaussian_covariance_bounds(r, ell, FOURIER_MODES)
        cx = np.mean(v[lag:, :] * v[:-lag, :])
        cy = np.mean(v[:, lag:] * v[:, :-lag])
        print(f"r = {r / ell:.1f} ℓ: covariance x {cx:.4f}, y {cy:.4f}, exp(−r²/2ℓ²) = {rho:.4f} (± {sd:.4f})")
        for c in (cx, cy):
            assert abs(c - rho) < 4 * sd + 0.02


def test_gaussian_to_weibull_map_gives_the_weibull_distribution():
    from scipy.stats import kstest

    from blastfrac.model.heterogeneity import weibull_from_gaussian

    g = np.random.default_rng(3).standard_normal(200_000)
    for m in (2.0, 5.0, 10.0):
        w = weibull_from_gaussian(g, m)
        ks = kstest(w, lambda x: weibull_cdf(x, m))
        se = weibull_cv(m) / math.sqrt(len(w))
        print(f"m = {m:g}: mean {w.mean():.4f} (± {se:.4f}), CV {w.std() / w.mean():.4f} vs {weibull_cv(m):.4f}, "
              f"KS p = {ks.pvalue:.3f}")
        assert ks.pvalue > 0.01 and abs(w.mean() - 1.0) < 4 * se
        assert np.all(np.diff(w[np.argsort(g)]) >= 0.0)        # monotone: the quantile is kept
    # far upper tail through Φ(−g): finite and increasing where 1 − Φ(g) underflows in double
    w = weibull_from_gaussian(np.array([8.0, 12.0, 38.0, 40.0]), 5.0)
    assert np.all(np.isfinite(w)) and np.all(np.diff(w) > 0)


def test_correlated_field_is_the_same_at_the_same_place_on_two_meshes():
    """Same seed, two meshes of one domain (h and h/2): interfaces whose midpoints lie within ℓ/20 of each
    other carry factors that differ by at most the field's variation over that distance, whereas the i.i.d.
    field's factors are uncorrelated; neighbours within ℓ/4 on one mesh are strongly correlated."""
    from scipy.spatial import cKDTree

    ell = 0.01
    het = {"weibull_modulus": 5.0, "correlation_length": ell}
    coarse = build(heterogeneity=het, geometry={**BIG, "mesh_size": 0.008})
    fine = build(heterogeneity=het, geometry=BIG)

    def mids(b):
        X, s1 = b.host["node_X"], b.topology.iface_slots[:, 0]
        nb = 3 * (s1 // 3) + (s1 % 3 + 1) % 3
        return 0.5 * (X[s1] + X[nb]), b.host["pair_t0"][0::2] / T_MEAN

    (pc, wc), (pf, wf) = mids(coarse), mids(fine)
    d, j = cKDTree(pf).query(pc)
    near = d < ell / 20
    assert near.sum() > 100
    corr = np.corrcoef(wc[near], wf[j[near]])[0, 1]
    iid = {"weibull_modulus": 5.0}
    wci, wfi = (b.host["pair_t0"][0::2] / T_MEAN for b in (build(heterogeneity=iid, geometry={**BIG, "mesh_size": 0.008}),
                                                            build(heterogeneity=iid, geometry=BIG)))
    corr_iid = np.corrcoef(wci[near], wfi[j[near]])[0, 1]
    # within one mesh: pairs of interfaces closer than ℓ/4
    pairs = cKDTree(pf).query_pairs(ell / 4, output_type="ndarray")
    corr_nb = np.corrcoef(wf[pairs[:, 0]], wf[pairs[:, 1]])[0, 1]
    rho_nb = math.exp(-(ell / 8) ** 2 / (2 * ell**2))          # at a typical lag ℓ/8 of those pairs
    print(f"\n{near.sum()} coincident interfaces: correlation {corr:.4f} (i.i.d. {corr_iid:+.4f}); "
          f"{len(pairs)} pairs within ℓ/4: {corr_nb:.3f} (Gaussian covariance at ℓ/8: {rho_nb:.3f})")
    assert corr > 0.99 and abs(corr_iid) < 0.2 and corr_nb > 0.9
    # the builder's strengths are the field at the midpoints exactly
    from blastfrac.model.heterogeneity import correlated_draw

    np.testing.assert_allclose(wf, correlated_draw(5.0, pf, ell, 0), rtol=1e-13)
    # and the mean over the 0.2 m square (20 ℓ a side) is the rock's value within the field's own scatter
    assert abs(wf.mean() - 1.0) < 0.1


def test_correlation_length_is_validated_and_resolved():
    def sc(het):
        return scenario_from_dict({"rock": {"heterogeneity": het},
                                   "geometry": {"domain": {"type": "rectangle", "width": 0.02, "height": 0.02},
                                                "mesh_size": 0.005}})

    for het, msg in [({"weibull_modulus": 5.0, "correlation_length": 0.0},
                      r"rock\.heterogeneity\.correlation_length: .*greater than 0"),
                     ({"weibull_modulus": 5.0, "correlation_length": 0.01, "reference_length": 0.005},
                      "exclusive")]:
        with pytest.raises(ScenarioError, match=msg):
            sc(het)
    r = resolved_dict(sc({"weibull_modulus": 5.0, "correlation_length": 0.003}))["rock"]["heterogeneity"]
    assert r["correlation_length"] == 0.003
