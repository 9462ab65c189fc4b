"""Vibration (analysis/ppv.py): the integration kernel keeps each node's peak speed exactly; the attenuation fit
recovers K and β of a field with known peaks; the damage radius is where the field crosses σ_t c_p/E."""

import math

import numpy as np
import pytest
import warp as wp

from blastfrac.analysis.ppv import ppv_critical, vibration_report


def test_the_integration_keeps_the_peak_speed_of_every_node():
    """The rock's integration kernel updates the PPV as it writes v^{n+1/2} (one thread and two, constrained and
    free blocks): after each step ppv must be the running max of |v| over the steps, node by node."""
    from blastfrac.cdem.solver import CDEMSolver
    from blastfrac.model.builder import ModelBuilder
    from conftest import scenario

    m = ModelBuilder(scenario(geometry={"domain": {"type": "rectangle", "width": 0.04, "height": 0.04},
                                        "mesh_size": 0.004},
                              boundaries={"left": {"type": "viscous"}, "bottom": {"type": "fixed"}})).finalize("cpu")
    rng = np.random.default_rng(3)
    for threads in (1, 2):
        st, cdem = m.state(), CDEMSolver(m)
        cdem.ppv_out = wp.zeros(m.node_count, dtype=wp.float64)
        if threads == 2:
            from concurrent.futures import ThreadPoolExecutor
            cdem.pool, cdem.split_min = ThreadPoolExecutor(max_workers=1), 0
        peak = np.zeros(m.node_count)
        for _ in range(40):
            st.v.assign(rng.normal(0, 5, (m.node_count, 2)))
            st.f.assign(rng.normal(0, 1e3, (m.node_count, 2)))
            cdem.integrate(st, 0.1 * m.stable_dt)
            peak = np.maximum(peak, np.linalg.norm(st.v.numpy(), axis=1))
            np.testing.assert_array_equal(cdem.ppv_out.numpy(), peak)
        assert 0 < (peak == 0.0).sum() < 0.2 * m.node_count      # the fixed side's nodes stay at rest, the rest move


def test_attenuation_fit_and_damage_radius_on_a_field_with_known_peaks():
    """PPV = K (R/√Q)^-β on nodes scattered over a disc round a hole: the ring medians give K, β back, and the
    damage radius is the ring where the field crosses PPV_crit = σ_t c_p/E."""
    K, beta, Q, r_b = 0.134, 1.4, 0.1, 0.005          # crosses PPV_crit ≈ 0.92 m/s near R = 80 mm
    rng = np.random.default_rng(0)
    R = np.sqrt(rng.uniform(r_b**2, 0.2**2, 60_000))
    th = rng.uniform(0, 2 * np.pi, R.size)
    X = np.stack([R * np.cos(th), R * np.sin(th)], 1)
    ppv = K * (R / math.sqrt(Q)) ** (-beta)

    class Rock:
        tensile_strength, youngs_modulus, p_wave_speed = 10e6, 50e9, 4600.0

    rep, prof = vibration_report(X, ppv, [((0.0, 0.0), r_b)], Q, Rock)
    assert rep["attenuation"]["K"] == pytest.approx(K, rel=0.02)
    assert rep["attenuation"]["beta"] == pytest.approx(beta, rel=0.01)
    crit = ppv_critical(10e6, 50e9, 4600.0)
    assert crit == pytest.approx(10e6 * 4600 / 50e9)
    r_exact = math.sqrt(Q) * (K / crit) ** (1 / beta)            # where the field equals PPV_crit
    assert not rep["damage_beyond_model"]
    ratio = math.exp(math.log(R.max() / r_b) / 30)                # ring width in log
    assert r_exact / ratio**1.5 <= rep["damage_radius"] <= r_exact * ratio   # within the ring resolution
