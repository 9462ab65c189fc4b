"""Elastic wave speeds (VALIDATION §2): bar (free-sided strip) and plane P waves in three directions.

Expected speeds come from the plane-strain moduli corrected for the spring compliance
(METHOD §1.2), computed in the test from the mesh's interior edge density.
"""

import math

import numpy as np
import pytest

from blastfrac.cdem.solver import CDEMSolver
from blastfrac.model.builder import ModelBuilder
from conftest import ROCK, effective_plane_strain_moduli, interior_edge_density, scenario

K_SPRING = 2.0e15   # Pa/m, stiff springs: the compliance correction stays small (≈1 %)


def _rock():
    return {"stiffness_mode": "per_area", "kn": K_SPRING, "ks": K_SPRING}


def test_bar_wave_speed():
    """A smooth pressure ramp on the end of a thin strip travels at √(E'_eff/ρ) (plane-strain plate)."""
    L, W, h = 0.4, 0.008, 0.002
    sc = scenario(rock=_rock(),
                  geometry={"domain": {"type": "rectangle", "width": L, "height": W, "center": [L / 2, 0.0]}, "mesh_size": h},
                  boundaries={"left": {"type": "pressure", "pulse": {"type": "table", "times": [0.0, 10e-6, 1.0],
                                                                      "values": [0.0, 10e6, 10e6]}}})
    m = ModelBuilder(sc).finalize("cpu")
    st, solver = m.state(), CDEMSolver(m)
    Ep_eff, _ = effective_plane_strain_moduli(ROCK["youngs_modulus"], ROCK["poisson_ratio"],
                                              interior_edge_density(m), K_SPRING, K_SPRING)
    c_expected = math.sqrt(Ep_eff / ROCK["density"])
    X = m.host["node_X"]
    stations = [0.12, 0.28]
    masks = [np.abs(X[:, 0] - s) < h for s in stations]
    dt = 0.8 * m.stable_dt
    t_end = 0.35 / c_expected + 10e-6
    times, hist = [], [[], []]
    t = 0.0
    while t < t_end:
        solver.forces(st, dt, t)
        solver.integrate(st, dt)
        t += dt
        v = st.v.numpy()[:, 0]
        times.append(t)
        for k in range(2):
            hist[k].append(v[masks[k]].mean())
    times = np.array(times)
    v_plateau = 10e6 / (ROCK["density"] * c_expected)        # σ = ρ c v
    arrivals = []
    for k in range(2):
        # pressure on the left end pushes in +x: particle velocity σ/(ρc); time of half the plateau
        h_k = np.array(hist[k])
        i = np.flatnonzero(h_k >= 0.5 * v_plateau)[0]
        arrivals.append(np.interp(0.5 * v_plateau, h_k[i - 1:i + 1], times[i - 1:i + 1]))
    c_measured = (stations[1] - stations[0]) / (arrivals[1] - arrivals[0])
    print(f"bar: c = {c_measured:.1f} m/s, expected {c_expected:.1f} m/s (uncorrected {math.sqrt(ROCK['youngs_modulus'] / (1 - 0.04) / 2600):.1f})")
    assert c_measured == pytest.approx(c_expected, rel=0.02)
    # amplitude: plateau velocity behind the front, σ = ρ c v (T2.1)
    assert np.array(hist[0])[-1] == pytest.approx(v_plateau, rel=0.03)


@pytest.mark.parametrize("angle_deg", [0.0, 30.0, 75.0])
def test_plane_p_wave_speed_in_three_directions(angle_deg):
    """An initial plane velocity pulse splits in two P waves; its forward half moves at c_p,eff."""
    h = 0.0025
    sc = scenario(rock=_rock(), geometry={"domain": {"type": "rectangle", "width": 0.4, "height": 0.4}, "mesh_size": h})
    m = ModelBuilder(sc).finalize("cpu")
    st, solver = m.state(), CDEMSolver(m)
    Ep_eff, nup_eff = effective_plane_strain_moduli(ROCK["youngs_modulus"], ROCK["poisson_ratio"],
                                                    interior_edge_density(m), K_SPRING, K_SPRING)
    c_expected = math.sqrt(Ep_eff / (ROCK["density"] * (1 - nup_eff**2)))      # (λ+2G)_eff = E'/(1−ν'²)
    d = np.array([math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))])
    perp = np.array([-d[1], d[0]])
    X = m.host["node_X"]
    s, q = X @ d, X @ perp
    width = 0.008
    st.v.assign(np.outer(np.exp(-0.5 * (s / width) ** 2), d))
    mass = m.host["node_mass"]
    band = np.abs(q) < 0.05

    def front_position():
        v = st.v.numpy() @ d
        w = mass * v * v * band * (s > 0)
        return float(np.sum(w * (st.x.numpy() @ d)) / np.sum(w))

    dt = 0.8 * m.stable_dt
    t, samples = 0.0, []
    while t < 22e-6:
        solver.forces(st, dt, t)
        solver.integrate(st, dt)
        t += dt
        if t > 6e-6 and len(samples) < 1000:
            samples.append((t, front_position()))
    tt, xx = np.array(samples).T
    c_measured = np.polyfit(tt, xx, 1)[0]
    print(f"P wave at {angle_deg}°: c = {c_measured:.1f} m/s, expected {c_expected:.1f} m/s")
    assert c_measured == pytest.approx(c_expected, rel=0.02)
