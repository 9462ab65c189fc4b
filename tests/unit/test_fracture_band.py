"""The fracture band (rock.fracture_band_width w_c): on blocks thinner than w_c an interface carries the share
h̄/w_c of the fracture energies (h̄ = (A1 + A2)/L, the mean height of its two blocks).

- The spring law itself (NumPy twin, opened to failure in tension and in shear) dissipates G_f·min(1, h̄/w_c)
  per unit area, with h̄ computed in the test from the mesh's triangles.
- Fragmenting a whole domain finer than w_c then costs (G_f/w_c)·Σ_q (A1 + A2) = (G_f/w_c)·(3A − A_boundary)
  (each triangle has three edges; A_boundary counts a triangle once per edge on the domain boundary): the same
  per unit area on a mesh and on its half within the boundary share, where without the band it doubles.
- Blocks thicker than w_c keep G_f; joints stay brittle; the option is validated and resolved.
"""

from __future__ import annotations

import numpy as np
import pytest

from blastfrac.materials.interface import np_spring_update_intact
from blastfrac.model.builder import ModelBuilder
from blastfrac.scenario import ScenarioError, scenario_from_dict
from blastfrac.scenario.load import resolved_dict
from conftest import scenario

GI, GII, K = 50.0, 500.0, 2e14
DOMAIN = {"domain": {"type": "rectangle", "width": 0.04, "height": 0.04}}


def build(h, band=None, **rock):
    r = {"unbreakable": False, "stiffness_mode": "per_area", "kn": K, "ks": K, "tensile_fracture_energy": GI,
         "shear_fracture_energy": GII, "fracture_band_width": band, **rock}
    return ModelBuilder(scenario(rock=r, geometry={**DOMAIN, "mesh_size": h}))


def heights(b):
    """h̄ of every interface from the triangles themselves [m]."""
    X, tri = b.mesh.vertices, b.mesh.triangles
    p = X[tri]
    area = 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                        - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    e1, e2 = b.topology.iface_elems[:, 0], b.topology.iface_elems[:, 1]
    return (area[e1] + area[e2]) / b.host["pair_l0"][0::2], area


def dissipated(strength, slope, shear):
    """Work per unit area [J/m²] of one spring opened (or slid) to failure with the NumPy law."""
    d, f, st, work = strength / K / 4000.0, 0.0, strength, 0.0
    for _ in range(10**6):
        if shear:
            _, f_new, _, st, mode = np_spring_update_intact(-1.0, f, 1e12, st, 0.0, d, K, K, 1.0, 0.0, 0.0,
                                                            0.0, slope)
            work += 0.5 * (-f - f_new) * d              # the spring force opposes the slip
        else:
            f_new, _, st, _, mode = np_spring_update_intact(f, 0.0, st, 1e12, d, 0.0, K, K, 1.0, 0.0, 0.0,
                                                            slope, 0.0)
            work += 0.5 * (-f - f_new) * d
        f = f_new
        if mode:
            return work
    raise AssertionError("the spring did not fail")


def test_each_interface_dissipates_its_share_of_the_fracture_energy():
    w_c = 0.0025
    b = build(0.003, band=w_c)
    hbar, _ = heights(b)
    share = np.minimum(1.0, hbar / w_c)
    assert share.min() < 0.9 and np.any(share == 1.0)             # both kinds of interface are present
    law = b.host["pair_law"]
    t, c = b.host["pair_t0"][0::2], b.host["pair_c0"][0::2]
    for q in (int(np.argmin(share)), int(np.argsort(share)[len(share) // 2]), int(np.argmax(hbar))):
        wt = dissipated(t[q], law[2 * q, 2], shear=False)
        ws = dissipated(c[q], law[2 * q, 3], shear=True)
        print(f"h̄ = {hbar[q] * 1e3:.2f} mm: mode I {wt:.3f} J/m² (G·share {GI * share[q]:.3f}), "
              f"mode II {ws:.2f} (G·share {GII * share[q]:.2f})")
        assert wt == pytest.approx(GI * share[q], rel=2e-3)
        assert ws == pytest.approx(GII * share[q], rel=2e-3)
        np.testing.assert_array_equal(law[2 * q], law[2 * q + 1])   # both springs of the interface


def test_fragmenting_a_region_costs_the_same_on_a_mesh_and_on_its_half():
    """Σ_q G_q L_q / A: with the band (every block thinner than w_c) the exact identity (G/w_c)(3A − A_bd)/A,
    equal on h and h/2 within the boundary share; without it the ratio is ≈ 2 (one more crack per element)."""
    w_c = 0.02
    per_area, plain = [], []
    for h in (0.002, 0.001):
        b, b0 = build(h, band=w_c), build(h)
        hbar, area = heights(b)
        assert hbar.max() < w_c
        L = b.host["pair_l0"][0::2]
        e = GI * np.minimum(1.0, hbar / w_c) * L                   # the law's own energy, first test
        tri = b.mesh.triangles
        edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        _, inv, cnt = np.unique(edges, axis=0, return_inverse=True, return_counts=True)
        on_boundary = (cnt[inv.ravel()] == 1).reshape(3, -1).sum(0)  # boundary edges of each triangle
        exact = GI / w_c * (3 * area.sum() - np.sum(on_boundary * area))
        assert e.sum() == pytest.approx(exact, rel=1e-10)
        per_area.append(e.sum() / area.sum())
        plain.append(GI * b0.host["pair_l0"][0::2].sum() / area.sum())
    print(f"\nwith the band: {per_area[0]:.0f} → {per_area[1]:.0f} J/m³ (3G/w_c = {3 * GI / w_c:.0f}); "
          f"without: {plain[0]:.0f} → {plain[1]:.0f}")
    assert per_area[1] / per_area[0] == pytest.approx(1.0, abs=0.05)
    assert abs(per_area[1] - 3 * GI / w_c) < 0.05 * 3 * GI / w_c
    assert plain[1] / plain[0] > 1.8


def test_thick_blocks_keep_the_energy_joints_stay_brittle_and_the_option_is_checked():
    b_wide, b0 = build(0.003, band=1e-4), build(0.003)            # every block thicker than w_c
    np.testing.assert_allclose(b_wide.host["pair_law"][:, 2], b0.slope_t, rtol=1e-12)
    np.testing.assert_allclose(b_wide.host["pair_law"][:, 3], b0.slope_c, rtol=1e-12)
    assert "pair_law" not in b0.host                               # no band: the scalar law, as before
    # a joint through the middle: its interfaces stay brittle (slopes 0), the rock's keep the band's share
    jb = ModelBuilder(scenario(
        rock={"unbreakable": False, "tensile_fracture_energy": GI, "fracture_band_width": 0.01},
        geometry={**DOMAIN, "mesh_size": 0.004, "joints": [{"segments": [[[-0.01, 0.001], [0.01, 0.001]]]}]}))
    on = jb.host["pair_joint"] >= 0
    assert on.any() and np.all(jb.host["pair_law"][on, 2:] == 0.0)
    assert np.all(jb.host["pair_law"][~on, 2] > 0.0)
    geo = {**DOMAIN, "mesh_size": 0.004}
    with pytest.raises(ScenarioError, match="fracture_band_width"):
        scenario_from_dict({"rock": {"fracture_band_width": 0.002}, "geometry": geo})
    with pytest.raises(ScenarioError, match=r"rock\.fracture_band_width"):
        scenario_from_dict({"rock": {"fracture_band_width": -0.001, "tensile_fracture_energy": 50.0}, "geometry": geo})
    # 0 is "no band" (so that --set can switch off a band a scenario file sets): the scalar law, as with None
    off = scenario_from_dict({"rock": {"fracture_band_width": 0.0, "tensile_fracture_energy": 50.0}, "geometry": geo})
    assert off.rock.fracture_band_width is None and "fracture_band_width" not in resolved_dict(off)["rock"]
    assert "pair_law" not in build(0.003, band=0.0).host
    r = resolved_dict(scenario_from_dict({"rock": {"fracture_band_width": 0.002, "tensile_fracture_energy": 50.0},
                                          "geometry": geo}))["rock"]
    assert r["fracture_band_width"] == 0.002
