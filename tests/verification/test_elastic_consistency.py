"""The block–spring assembly answers as the input rock (issue: elastic consistency in the model itself).

With the rock given by its macro properties (penalty springs, the default), P and S plane waves in three
directions and the Lamé cylinder must match the *input* E, ν within 1 % at three mesh sizes. Expected
values are the plane-strain formulas of the input rock, computed here; no spring-compliance correction
is applied in the test (the builder compensates the block moduli, model/compliance.py).

Front speed: an initial plane velocity pulse g(s)·ê (no stress) splits into two halves running at ±c;
the kinetic-energy centroid of the forward half in a band about the axis moves at the energy-weighted
group velocity. A lumped-mass lattice lags by about h²/(16 w²) for a Gaussian of width w (energy spectrum
e^{−k²w²}, lag (kh)²/8 per mode; printed as the "dispersion estimate"); the default averaged mass cancels that
leading term, so what remains (±0.2 %) is the mesh's anisotropy, and the mean error over the three directions
must still fall from the coarsest to the finest mesh.
"""

import math

import numpy as np
import pytest

from blastfrac.cdem.solver import CDEMSolver
from blastfrac.model.builder import ModelBuilder
from conftest import ROCK, scenario
from verification.static_helpers import static_pressurised_hole

E, NU, RHO = ROCK["youngs_modulus"], ROCK["poisson_ratio"], ROCK["density"]
LAM, MU = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
C_P, C_S = math.sqrt((LAM + 2 * MU) / RHO), math.sqrt(MU / RHO)
SIZES = (0.002, 0.0014, 0.001)          # three mesh sizes [m]
WIDTH = 0.006                           # Gaussian width of the pulse [m]


def _default_rock():
    """Table 2 rock with the default (penalty, compensated) springs."""
    return {"stiffness_mode": "penalty", "spring_penalty": 20.0}


def front_speed(h: float, angle_deg: float, wave: str, rock: dict | None = None) -> float:
    """Measured speed [m/s] of a plane P ('p') or S ('s') pulse travelling at angle_deg on a mesh of size h."""
    sc = scenario(rock=rock or _default_rock(),
                  geometry={"domain": {"type": "rectangle", "width": 0.16, "height": 0.16}, "mesh_size": h})
    m = ModelBuilder(sc).finalize("cpu")
    st, solver = m.state(), CDEMSolver(m, block_contact=False)
    d = np.array([math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))])
    perp = np.array([-d[1], d[0]])
    X = m.host["node_X"]
    s, q = X @ d, X @ perp
    pol = d if wave == "p" else perp
    st.v.assign(np.outer(np.exp(-0.5 * (s / WIDTH) ** 2), pol))
    mass = m.host["node_mass"] * (np.abs(q) < 0.025)
    c_guess = C_P if wave == "p" else C_S
    dt = 0.8 * m.stable_dt
    t, samples = 0.0, []
    t_end = 0.05 / c_guess
    step = 0
    while t < t_end:
        solver.forces(st, dt, t)
        solver.integrate(st, dt)
        t += dt
        step += 1
        if t > 0.3 * t_end and step % 4 == 0:
            x, v = st.x.numpy(), st.v.numpy()
            w = mass * np.einsum("ij,ij->i", v, v) * ((x @ d) > 0.25 * c_guess * t)
            samples.append((t, float(np.sum(w * (x @ d)) / np.sum(w))))
    tt, xx = np.array(samples).T
    return float(np.polyfit(tt, xx, 1)[0])


@pytest.mark.parametrize("wave", ["p", "s"])
def test_plane_front_speeds_match_input_rock_in_three_directions_at_three_mesh_sizes(wave):
    c_ref = C_P if wave == "p" else C_S
    errs = {}
    for h in SIZES:
        for ang in (0.0, 30.0, 75.0):
            errs[(h, ang)] = front_speed(h, ang, wave) / c_ref - 1.0
    for h in SIZES:
        print(f"\n  {wave.upper()} wave, h = {h * 1e3:.2f} mm: "
              + ", ".join(f"{a:>4.0f}°: {errs[(h, a)]:+.3%}" for a in (0.0, 30.0, 75.0))
              + f"   (dispersion estimate −h²/16w² = {-(h / WIDTH) ** 2 / 16:+.3%})")
    assert max(abs(e) for e in errs.values()) < 0.01
    # the error is the lattice's dispersion, not a stiffness defect: it shrinks as the mesh is refined
    mean_err = [np.mean([abs(errs[(h, a)]) for a in (0.0, 30.0, 75.0)]) for h in SIZES]
    assert mean_err[-1] < mean_err[0]


def test_uncompensated_springs_are_measurably_slow_and_the_report_says_by_how_much():
    """Without compensation the assembly is softer (the defect fixed here); the builder's report predicts it."""
    rock = {**_default_rock(), "compensate_spring_compliance": False}
    c = front_speed(0.0014, 0.0, "p", rock)
    sc = scenario(rock=rock, geometry={"domain": {"type": "rectangle", "width": 0.16, "height": 0.16},
                                       "mesh_size": 0.0014})
    rep = ModelBuilder(sc).elastic
    cp_rep, _ = rep.assembly_speeds
    print(f"\n  uncompensated: c_p = {c:.1f} m/s ({c / C_P - 1:+.2%} against the input {C_P:.1f}); "
          f"reported assembly c_p {cp_rep:.1f} m/s ({cp_rep / C_P - 1:+.2%})")
    assert c / C_P - 1.0 < -0.02                      # the test can see the defect
    assert c == pytest.approx(cp_rep, rel=0.01)       # and the report measures it


def lame_wall_displacement(h_near: float, rock: dict | None = None) -> tuple[float, float, float]:
    """Static Lamé cylinder (a = 5 mm, b = 50 mm, inner pressure p) of the model's linear stiffness.

    Returns (mean radial wall displacement [m], Lamé's u(a) for the input rock [m], mean u at r = 2a [m]
    against Lamé there, as a ratio). The solve is verification/static_helpers.static_pressurised_hole.
    """
    a, b, p = 0.005, 0.05, 100e6
    sc = scenario(rock=rock or _default_rock(),
                  geometry={"domain": {"type": "disc", "radius": b}, "boreholes": [{"radius": a}],
                            "mesh_size": 4 * h_near, "mesh_size_near": h_near, "refinement_distance": 0.02})
    m = ModelBuilder(sc).finalize("cpu")
    X = m.host["node_X"]
    U = static_pressurised_hole(m, a, p)
    r = np.hypot(X[:, 0], X[:, 1])
    ur = np.einsum("ij,ij->i", U, X / r[:, None])
    nu = NU

    def u_lame(rr):
        return (1 + nu) * p * a**2 / (E * (b**2 - a**2)) * ((1 - 2 * nu) * rr + b**2 / rr)

    wall = r < a * 1.0001
    mid = np.abs(r - 2 * a) < 0.1 * a
    return float(ur[wall].mean()), float(u_lame(a)), float(np.mean(ur[mid]) / np.mean(u_lame(r[mid])))


def test_lame_wall_displacement_matches_input_rock_at_three_mesh_sizes():
    """u(a) of the default (compensated) assembly within 1 % of Lamé with the input E, ν at three meshes;
    the uncompensated springs of the same mesh give the 4–5 % excess an independent check found."""
    errs = []
    for h in (0.0005, 0.00035, 0.00025):         # a/h = 10, 14, 20
        uw, ul, ratio_mid = lame_wall_displacement(h)
        errs.append(uw / ul - 1.0)
        print(f"\n  Lamé, h at wall {h * 1e3:.2f} mm: u(a) = {uw * 1e6:.4f} µm, Lamé {ul * 1e6:.4f} µm "
              f"({errs[-1]:+.3%}); u(2a)/Lamé {ratio_mid - 1:+.3%}")
        assert abs(errs[-1]) < 0.01
        assert abs(ratio_mid - 1.0) < 0.01
    assert abs(errs[-1]) < abs(errs[0])          # CST discretisation error falls with h
    uw, ul, _ = lame_wall_displacement(0.0005, {**_default_rock(), "compensate_spring_compliance": False})
    print(f"  uncompensated springs, h 0.50 mm: u(a) {uw / ul - 1:+.3%}")
    assert uw / ul - 1.0 > 0.03
