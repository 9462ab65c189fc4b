"""Spring laws: Warp functions against their NumPy twins, failure thresholds, softening energy."""

import math

import numpy as np
import pytest
import warp as wp

from blastfrac.materials import interface as law


@wp.kernel
def _run_intact(inp: wp.array2d(dtype=wp.float64), flag: wp.array(dtype=wp.int32), out: wp.array2d(dtype=wp.float64)):
    i = wp.tid()
    r = law.spring_update_intact(inp[i, 0], inp[i, 1], inp[i, 2], inp[i, 3], inp[i, 4], inp[i, 5], inp[i, 6],
                                 inp[i, 7], inp[i, 8], inp[i, 9], inp[i, 10], inp[i, 11], inp[i, 12], flag[i],
                                 inp[i, 13])
    for k in range(5):
        out[i, k] = r[k]


@wp.kernel
def _run_broken(inp: wp.array2d(dtype=wp.float64), out: wp.array2d(dtype=wp.float64)):
    i = wp.tid()
    r = law.spring_update_broken(inp[i, 0], inp[i, 1], inp[i, 2], inp[i, 3], inp[i, 4], inp[i, 5], inp[i, 6])
    out[i, 0] = r[0]
    out[i, 1] = r[1]


def _random_intact_cases(n, rng):
    ac = rng.uniform(1e-4, 1e-3, n)
    kn = rng.uniform(1e13, 1e15, n) * ac
    ks = rng.uniform(1e13, 1e15, n) * ac
    t0 = rng.uniform(1e6, 2e7, n)
    c0 = rng.uniform(1e6, 5e7, n)
    # forces around the strength envelope so that all branches are visited
    fn = rng.uniform(-2.0, 4.0, n) * t0 * ac
    fs = rng.uniform(-3.0, 3.0, n) * c0 * ac
    dn = rng.normal(0, 1, n) * t0 * ac / kn
    ds = rng.normal(0, 1, n) * c0 * ac / ks
    tanp = np.tan(np.radians(rng.uniform(10, 60, n)))
    tanr = np.tan(np.radians(rng.uniform(5, 40, n)))
    slope_t = np.where(rng.random(n) < 0.5, 0.0, t0**2 / (2 * rng.uniform(10, 200, n)))
    slope_c = np.where(rng.random(n) < 0.5, 0.0, c0**2 / (2 * rng.uniform(50, 2000, n)))
    # crushing strength: none for half the cases, else within the compressive range of fn
    crush = np.where(rng.random(n) < 0.5, 0.0, rng.uniform(1.0, 4.0, n) * t0)
    return np.stack([fn, fs, t0, c0, dn, ds, kn, ks, ac, tanp, tanr, slope_t, slope_c, crush], 1)


def test_intact_law_matches_numpy_twin():
    rng = np.random.default_rng(1)
    inp = _random_intact_cases(4000, rng)
    flag = np.ones(len(inp), np.int32)
    flag[::7] = 0
    out = wp.zeros((len(inp), 5), dtype=wp.float64, device="cpu")
    wp.launch(_run_intact, dim=len(inp), inputs=[wp.array(inp, dtype=wp.float64, device="cpu"),
                                                 wp.array(flag, dtype=wp.int32, device="cpu")], outputs=[out], device="cpu")
    got = out.numpy()
    want = np.array([law.np_spring_update_intact(*row[:13], breakable=f, crush=row[13]) for row, f in zip(inp, flag)],
                    dtype=float)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-300)
    modes = set(want[:, 4].astype(int))
    assert modes == {law.INTACT, law.TENSILE, law.SHEAR, law.CRUSHED}, "the random cases must exercise every branch"


def test_broken_law_matches_numpy_twin():
    rng = np.random.default_rng(2)
    n = 2000
    kn = rng.uniform(1e10, 1e12, n)
    inp = np.stack([rng.normal(0, 1e4, n), rng.normal(0, 1e-6, n), rng.normal(0, 1e-7, n), rng.normal(0, 1e-6, n),
                    kn, kn * rng.uniform(0.5, 1.0, n), np.tan(np.radians(rng.uniform(0, 45, n)))], 1)
    out = wp.zeros((n, 2), dtype=wp.float64, device="cpu")
    wp.launch(_run_broken, dim=n, inputs=[wp.array(inp, dtype=wp.float64, device="cpu")], outputs=[out], device="cpu")
    want = np.array([law.np_spring_update_broken(*row) for row in inp])
    np.testing.assert_allclose(out.numpy(), want, rtol=1e-12, atol=1e-300)
    assert np.all(want[:, 0] >= 0), "a broken spring never pulls"


def test_tensile_threshold_eq19():
    T, ac, kn, ks = 10e6, 1e-3, 1e15 * 1e-3, 1e15 * 1e-3
    w_peak = T / 1e15                      # opening at which σ_n reaches T
    args = dict(t_str=T, c_str=40e6, ds=0.0, kn=kn, ks=ks, ac=ac, tan_phi=math.tan(math.radians(40)),
                tan_phi_r=0.5, slope_t=0.0, slope_c=0.0)
    below = law.np_spring_update_intact(0.0, 0.0, dn=0.999 * w_peak, **args)
    above = law.np_spring_update_intact(0.0, 0.0, dn=1.001 * w_peak, **args)
    assert below[4] == law.INTACT and math.isclose(-below[0] / ac, 0.999 * T, rel_tol=1e-12)
    assert above[4] == law.TENSILE and above[0] == 0.0 and above[1] == 0.0


def test_mohr_coulomb_threshold_eq20():
    c, phi, ac, k = 26e6, 60.0, 1e-3, 1e15
    sn = 50e6                                     # compression on the interface [Pa]
    tau_f = sn * math.tan(math.radians(phi)) + c  # Eq. 20 strength
    ks = k * ac
    args = dict(t_str=14e6, c_str=c, dn=0.0, kn=k * ac, ks=ks, ac=ac, tan_phi=math.tan(math.radians(phi)),
                tan_phi_r=math.tan(math.radians(50)), slope_t=0.0, slope_c=0.0)
    ok = law.np_spring_update_intact(sn * ac, 0.0, ds=-0.999 * tau_f * ac / ks, **args)
    broke = law.np_spring_update_intact(sn * ac, 0.0, ds=-1.001 * tau_f * ac / ks, **args)
    assert ok[4] == law.INTACT
    assert broke[4] == law.SHEAR
    # after a shear break the residual friction carries the load: |Fs| = Fn tan φ_r
    assert math.isclose(abs(broke[1]), sn * ac * math.tan(math.radians(50)), rel_tol=1e-12)


def test_crushing_cap_threshold_keeps_the_normal_force():
    """Fn/Ac reaching σ_cr crushes the spring; the normal force is kept, the shear capped at Fn·tanφ_r, and a cap
    of 0 (the paper's law) never crushes, however far the spring is compressed."""
    crush, ac, k = 150e6, 1e-3, 1e15
    tan_r = math.tan(math.radians(30))
    args = dict(t_str=10e6, c_str=40e6, ds=0.0, kn=k * ac, ks=k * ac, ac=ac, tan_phi=math.tan(math.radians(40)),
                tan_phi_r=tan_r, slope_t=0.0, slope_c=0.0)
    dn = -crush / k                               # closing that brings σ_n to σ_cr
    fs0 = 0.9 * crush * ac                        # shear below Mohr-Coulomb at σ_cr, above residual friction
    below = law.np_spring_update_intact(0.0, fs0, dn=0.999 * dn, crush=crush, **args)
    above = law.np_spring_update_intact(0.0, fs0, dn=1.001 * dn, crush=crush, **args)
    paper = law.np_spring_update_intact(0.0, 0.0, dn=100 * dn, crush=0.0, **args)
    assert below[4] == law.INTACT and above[4] == law.CRUSHED
    assert math.isclose(above[0], 1.001 * crush * ac, rel_tol=1e-12)
    assert math.isclose(above[1], above[0] * tan_r, rel_tol=1e-12)
    assert paper[4] == law.INTACT
    assert law.crushing_failure(above[0], crush, ac) and not law.crushing_failure(below[0], crush, ac)


@pytest.mark.parametrize("gf", [20.0, 100.0])
def test_tension_softening_dissipates_gf(gf):
    """Work done on one spring opened until it breaks equals G_f·Ac (+ nothing stored)."""
    T, ac, k = 10e6, 1e-3, 1e15
    kn = k * ac
    slope = law.softening_slope(T, gf, k)
    fn, t, work, mode = 0.0, T, 0.0, law.INTACT
    dn = T / k / 200.0                              # 200 steps to the peak
    steps = 0
    while mode == law.INTACT:
        fn_new, _, t, _, mode = law.np_spring_update_intact(fn, 0.0, t, 40e6, dn, 0.0, kn, kn, ac, 0.7, 0.5, slope, 0.0)
        work += -0.5 * (fn + fn_new) * dn
        fn = fn_new
        steps += 1
    assert steps > 1000, "the softening branch must be resolved by many increments"
    assert work == pytest.approx(gf * ac, rel=0.05)
    # the crack opened by about w_c = 2 G_f / T before breaking
    assert steps * dn == pytest.approx(2 * gf / T, rel=0.05)


def test_snap_back_is_rejected():
    with pytest.raises(ValueError, match="snap back"):
        law.softening_slope(10e6, 1e-3, 1e12)


def test_spring_dashpot_matches_numpy_twin_and_dissipates():
    """Warp dashpot force equals its NumPy twin; it always opposes the relative velocity (power ≤ 0)."""
    import warp as wp

    from blastfrac.materials.interface import np_spring_dashpot, spring_dashpot

    @wp.kernel
    def k(dv: wp.array(dtype=wp.vec2d), out: wp.array(dtype=wp.vec2d)):
        i = wp.tid()
        t = wp.normalize(wp.vec2d(wp.float64(1.0), wp.float64(2.0)))
        n = wp.vec2d(t[1], -t[0])
        out[i] = spring_dashpot(dv[i], n, t, wp.float64(3e11), wp.float64(1e11), wp.float64(2e-3),
                                wp.float64(5e-3), wp.float64(0.1))

    rng = np.random.default_rng(1)
    dv = rng.normal(size=(20, 2)) * 100
    out = wp.zeros(20, dtype=wp.vec2d, device="cpu")
    wp.launch(k, dim=20, inputs=[wp.array(dv, dtype=wp.vec2d, device="cpu")], outputs=[out], device="cpu")
    t = np.array([1.0, 2.0]) / np.sqrt(5)
    n = np.array([t[1], -t[0]])
    want = np.array([np_spring_dashpot(d, n, t, 3e11, 1e11, 2e-3, 5e-3, 0.1) for d in dv])
    np.testing.assert_allclose(out.numpy(), want, rtol=1e-12)
    m_eff = 2e-3 * 5e-3 / 7e-3
    cn = 2 * 0.1 * np.sqrt(m_eff * 3e11)                 # 2ζ√(m_eff K) from the definition
    np.testing.assert_allclose(want @ n, -cn * (dv @ n), rtol=1e-12)
    assert np.all(np.einsum("ij,ij->i", want, dv) <= 0)
