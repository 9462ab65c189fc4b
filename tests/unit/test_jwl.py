"""JWL EOS, isentrope, energy update and CJ state (VALIDATION §1, T1.1)."""

import numpy as np
import pytest
import warp as wp

from blastfrac._warp import init_warp
from blastfrac.explosives.library import cj_report, get_explosive
from blastfrac.materials.cj import cj_state, hugoniot_pressure
from blastfrac.materials.jwl import (
    isentrope_constant,
    isentrope_energy_np,
    isentrope_pressure_np,
    jwl_energy_update,
    jwl_energy_update_np,
    jwl_pressure,
    jwl_pressure_np,
    jwl_sound_speed_sq,
    jwl_sound_speed_sq_np,
)

F64 = wp.float64
PETN = get_explosive("petn")
EMUL = get_explosive("emulsion")


@wp.kernel
def _eval_eos(
    V: wp.array(dtype=wp.float64),
    E: wp.array(dtype=wp.float64),
    c: wp.array(dtype=wp.float64),
    p_out: wp.array(dtype=wp.float64),
    c2_out: wp.array(dtype=wp.float64),
):
    i = wp.tid()
    p = jwl_pressure(V[i], E[i], c[0], c[1], c[2], c[3], c[4])
    p_out[i] = p
    c2_out[i] = jwl_sound_speed_sq(V[i], E[i], p, c[5], c[0], c[1], c[2], c[3], c[4])


@wp.kernel
def _eval_update(
    a: wp.array(dtype=wp.float64, ndim=2), c: wp.array(dtype=wp.float64), out: wp.array(dtype=wp.float64, ndim=2)
):
    i = wp.tid()
    r = jwl_energy_update(a[i, 0], a[i, 1], a[i, 2], a[i, 3], a[i, 4], a[i, 5], a[i, 6], a[i, 7], c[0], c[1], c[2], c[3], c[4])
    out[i, 0] = r[0]
    out[i, 1] = r[1]


def _closed_form_p(V, E, P):
    w = P.omega
    return P.A * (1 - w / (P.R1 * V)) * np.exp(-P.R1 * V) + P.B * (1 - w / (P.R2 * V)) * np.exp(-P.R2 * V) + w * E / V


@pytest.mark.parametrize("P", [PETN, EMUL], ids=["petn", "emulsion"])
def test_pressure_and_sound_speed_warp_vs_numpy_vs_closed_form(P):
    init_warp()
    V = np.linspace(0.5, 12.0, 57)
    E = P.E0 * np.linspace(1.2, 0.1, 57)
    consts = wp.array([P.A, P.B, P.R1, P.R2, P.omega, P.rho0], dtype=wp.float64)
    p_w, c2_w = wp.zeros(57, dtype=wp.float64), wp.zeros(57, dtype=wp.float64)
    wp.launch(_eval_eos, dim=57, inputs=[wp.array(V, dtype=F64), wp.array(E, dtype=F64), consts, p_w, c2_w])
    p_np = jwl_pressure_np(V, E, P.A, P.B, P.R1, P.R2, P.omega)
    np.testing.assert_allclose(p_np, _closed_form_p(V, E, P), rtol=1e-12)
    np.testing.assert_allclose(p_w.numpy(), p_np, rtol=1e-12)
    c2_np = jwl_sound_speed_sq_np(V, E, p_np, P.rho0, P.A, P.B, P.R1, P.R2, P.omega)
    np.testing.assert_allclose(c2_w.numpy(), c2_np, rtol=1e-12)
    # closed form: c^2 = -(V^2/rho0) dp/dV along the isentrope through (V, E): dp/dV = p_V - p p_E
    dV = 1e-6 * V
    dpdV_E = (jwl_pressure_np(V + dV, E, P.A, P.B, P.R1, P.R2, P.omega) - jwl_pressure_np(V - dV, E, P.A, P.B, P.R1, P.R2, P.omega)) / (2 * dV)
    dpdE = P.omega / V
    c2_ref = -(V**2) / P.rho0 * (dpdV_E - p_np * dpdE)
    np.testing.assert_allclose(c2_np, c2_ref, rtol=1e-6)


@pytest.mark.parametrize("P", [PETN, EMUL], ids=["petn", "emulsion"])
def test_isentrope_is_consistent(P):
    C = isentrope_constant(P)
    V = np.linspace(0.6, 20.0, 200)
    Es = isentrope_energy_np(V, P, C)
    np.testing.assert_allclose(isentrope_energy_np(1.0, P, C), P.E0, rtol=1e-14)
    np.testing.assert_allclose(jwl_pressure_np(V, Es, P.A, P.B, P.R1, P.R2, P.omega), isentrope_pressure_np(V, P, C), rtol=1e-10)
    dV = 1e-6 * V
    dEdV = (isentrope_energy_np(V + dV, P, C) - isentrope_energy_np(V - dV, P, C)) / (2 * dV)
    np.testing.assert_allclose(-dEdV, isentrope_pressure_np(V, P, C), rtol=1e-6)


def test_isentrope_table_of_validation_md():
    """VALIDATION.md T1.4 table (rounded to 3-4 digits there): p [MPa] and work [% E0]."""
    V = np.array([1.0, 1.5, 2.0, 3.0, 5.0, 10.0])
    table = {
        "emulsion": ([3792, 756, 305, 155, 81.0, 35.6], [0, 21.4, 27.0, 32.0, 37.2, 43.5]),
        "petn": ([13706, 4259, 2063, 725, 180, 58.2], [0, 38.1, 52.7, 65.1, 72.3, 77.0]),
    }
    for name, (p_ref, w_ref) in table.items():
        P = get_explosive(name)
        C = isentrope_constant(P)
        np.testing.assert_allclose(isentrope_pressure_np(V, P, C) / 1e6, p_ref, rtol=3e-3)
        work = 100 * (P.E0 - isentrope_energy_np(V, P, C)) / P.E0
        np.testing.assert_allclose(work, w_ref, atol=0.06)


def test_energy_update_warp_vs_numpy_and_isentropic_limit():
    init_warp()
    P = PETN
    rng = np.random.default_rng(0)
    n = 50
    vol0 = np.full(n, 1e-6)
    vold = vol0 * rng.uniform(0.8, 3.0, n)
    vnew = vold * rng.uniform(0.97, 1.03, n)
    ie = P.E0 * vol0 * rng.uniform(0.3, 1.0, n)
    p_old = rng.uniform(0, 5e9, n)
    q = rng.uniform(0, 1e8, n)
    F = rng.uniform(0, 1, n)
    a = np.stack([vnew / vol0, vnew, vold, vol0, ie, p_old, q, F], axis=1)
    out = wp.zeros((n, 2), dtype=wp.float64)
    wp.launch(_eval_update, dim=n, inputs=[wp.array(a, dtype=F64), wp.array([P.A, P.B, P.R1, P.R2, P.omega], dtype=F64), out])
    p_np, ie_np = jwl_energy_update_np(vnew / vol0, vnew, vold, vol0, ie, p_old, q, F, P.A, P.B, P.R1, P.R2, P.omega)
    np.testing.assert_allclose(out.numpy()[:, 0], p_np, rtol=1e-12)
    np.testing.assert_allclose(out.numpy()[:, 1], ie_np, rtol=1e-12)
    # the returned pair satisfies the (burn-scaled) EOS exactly, and ie changes by -(p_avg + q) dV
    Vn = vnew / vol0
    np.testing.assert_allclose(p_np, F * jwl_pressure_np(Vn, ie_np / vol0, P.A, P.B, P.R1, P.R2, P.omega), rtol=1e-10)
    np.testing.assert_allclose(ie_np - ie, -(vnew - vold) * (0.5 * (p_old + p_np) + q), rtol=1e-10, atol=1e-12 * P.E0 * 1e-6)


def test_energy_update_follows_isentrope_in_many_steps():
    """Integrating dV in 2000 steps from (1, E0) to V=7 reproduces E_s(V) to 1e-5."""
    P = EMUL
    C = isentrope_constant(P)
    vol0 = 1.0
    Vs = np.geomspace(1.0, 7.0, 2001)
    ie, p = P.E0 * vol0, float(jwl_pressure_np(1.0, P.E0, P.A, P.B, P.R1, P.R2, P.omega))
    for k in range(1, len(Vs)):
        p, ie = jwl_energy_update_np(Vs[k], Vs[k], Vs[k - 1], vol0, ie, p, 0.0, 1.0, P.A, P.B, P.R1, P.R2, P.omega)
    assert abs(ie / vol0 - isentrope_energy_np(7.0, P, C)) < 1e-5 * P.E0
    assert abs(p / isentrope_pressure_np(7.0, P, C) - 1) < 1e-4


def test_pressure_floor():
    P = PETN
    p, ie = jwl_energy_update_np(50.0, 50.0, 49.0, 1.0, -1e9, 0.0, 0.0, 1.0, P.A, P.B, P.R1, P.R2, P.omega)
    assert p == 0.0


def test_cj_state_petn_handbook():
    cj = cj_state(PETN)
    print(f"\n  PETN 1.77 CJ from its JWL Hugoniot: D = {cj.D:.1f} m/s ({cj.D / 8300 - 1:+.3%} vs handbook 8300), "
          f"P = {cj.p / 1e9:.3f} GPa ({cj.p / 33.5e9 - 1:+.3%} vs 33.5), V = {cj.V:.4f}")
    assert abs(cj.D / 8300.0 - 1) < 0.005, cj.D
    assert abs(cj.p / 33.5e9 - 1) < 0.005, cj.p
    # tangency of the Rayleigh line and the Hugoniot at the CJ point
    assert abs(PETN.rho0 * cj.D**2 * (1 - cj.V) / cj.p - 1) < 1e-9
    dV = 1e-6
    slope = (hugoniot_pressure(cj.V + dV, PETN) - hugoniot_pressure(cj.V - dV, PETN)) / (2 * dV)
    assert abs(-slope / (PETN.rho0 * cj.D**2) - 1) < 1e-5
    # CJ identity: gamma_CJ = -(V/p) dp_s/dV on the isentrope through the CJ point = V/(1-V)
    C = isentrope_constant(PETN, cj.V, cj.E)
    dps = (isentrope_pressure_np(cj.V + dV, PETN, C) - isentrope_pressure_np(cj.V - dV, PETN, C)) / (2 * dV)
    assert abs(-cj.V / cj.p * dps / (cj.V / (1 - cj.V)) - 1) < 1e-5


def test_cj_state_tnt_handbook():
    """TNT 1.63 (same handbook): D = 6930 m/s, P_CJ = 21.0 GPa."""
    cj = cj_state(get_explosive("tnt"))
    assert abs(cj.D / 6930.0 - 1) < 0.005 and abs(cj.p / 21.0e9 - 1) < 0.01, (cj.D, cj.p)


def test_cj_emulsion_flags_inconsistent_D():
    r = cj_report(EMUL, "emulsion")
    assert r["warn"] and abs(r["D_cj"] / 5522 - 1) < 1e-3 and abs(r["p_cj"] / 9.91e9 - 1) < 2e-3
    assert not cj_report(PETN, "petn")["warn"]
    for name in ("tnt", "anfo"):
        assert not cj_report(get_explosive(name), name)["warn"]
