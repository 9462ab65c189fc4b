"""A small coupled blast runs to completion: the rock about the hole cracked along every radius (and, a known gap, not
crushed: the crushed zone lies below the empirical bracket), radial tensile cracks beyond, and an energy budget
(explosive energy released = rock + gas + contact + losses) that closes within 5 %.

Setup: a 3 mm hole filled with the paper's emulsion (Table 1) in a 12 cm square of its Table 2 rock with
non-reflecting sides, 20 µs; the rock law of the shipped blast examples (shock viscosity, spring dashpots,
fracture energies; docs/scenario.md, "Blast damping and fracture energy").
"""

import json
import math

import numpy as np
import pytest

from blastfrac.analysis.cracks import radial_interfaces
from blastfrac.explosives.library import get_explosive
from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

R_B = 0.003
ROCK = {"density": 2600.0, "youngs_modulus": 50e9, "poisson_ratio": 0.2, "tensile_strength": 10e6,
        "cohesion": 40e6, "friction_angle": 40.0, "residual_friction_angle": 30.0}
E0_TABLE1 = 4.2e9          # emulsion detonation energy per unit volume, Yue et al. Table 1 [J/m³]


def small_blast(rock_extra: dict | None = None, scale: float = 1.0, paraview: bool = True) -> dict:
    """The scenario of this module (also examples/rock_fronts/crushing_study.py): the wall mesh and the MPM cell are
    h = r_b/(5·scale), the far mesh 8 r_b/5; rock_extra is added to the rock table."""
    h = R_B / 5 / scale
    return scenario_from_dict({
        "title": "small coupled blast",
        "simulation": {"end_time": 20e-6, "progress": False},
        "output": {"paraview": paraview, "figures": True, "interval": 5e-6},
        "rock": {**ROCK, "bulk_viscosity_linear": 0.02, "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.15,
                 "tensile_fracture_energy": 50.0, "shear_fracture_energy": 500.0, **(rock_extra or {})},
        "geometry": {"domain": {"type": "rectangle", "width": 0.12, "height": 0.12}, "mesh_size": 8 * R_B / 5,
                     "mesh_size_near": h, "refinement_distance": 0.036,
                     "boreholes": [{"center": [0.0, 0.0], "radius": R_B}]},
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
        "monitors": [{"name": "hole", "position": [0.0, 0.0], "quantities": ["gas_pressure"]}],
        "explosive": {"name": "emulsion", "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": R_B}],
                      "grid": {"cell_size": h, "points_per_cell": 2,
                               "bounds": [[-6 * R_B, -6 * R_B], [6 * R_B, 6 * R_B]]}},
    })


@pytest.fixture(scope="module")
def blast(tmp_path_factory):
    out = tmp_path_factory.mktemp("blast")
    sim = Simulation(small_blast(), out_dir=out)
    return sim, sim.run(), out


def crushed_zone_bracket() -> tuple[float, float]:
    """r_c/r_b from Esen et al. (2003) and from power-law attenuation to the UCS (VALIDATION §4)."""
    ex = get_explosive("emulsion")
    E, nu = ROCK["youngs_modulus"], ROCK["poisson_ratio"]
    phi = math.radians(ROCK["friction_angle"])
    ucs = 2 * ROCK["cohesion"] * math.cos(phi) / (1 - math.sin(phi))           # Mohr–Coulomb UCS
    p_b = ex.rho0 * ex.D**2 / 8                                                   # borehole pressure
    czi = p_b**3 / (E / (1 + nu) * ucs**2)
    esen = 0.812 * czi**0.219
    c_p = math.sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / ROCK["density"])
    p_cj = ex.rho0 * ex.D**2 / 4                                                 # γ = 3 CJ pressure at the given D
    p_w = 2 * p_cj / (1 + ex.rho0 * ex.D / (ROCK["density"] * c_p))              # impedance-matched wall pressure
    power = (p_w / ucs) ** (1 / (2 + nu / (1 - nu)))
    return esen, power


def _interfaces(sim):
    """Both ends a, b [m] of each interface, its midpoint radius r [m] and the modes of its two springs [Q, 2]."""
    m = sim.model
    pn = m.topology.pair_nodes
    X = m.host["node_X"]
    a, b = X[pn[0::2, 0]], X[pn[1::2, 0]]
    return a, b, np.linalg.norm(0.5 * (a + b), axis=1), sim.state.pair_mode.numpy().reshape(-1, 2)


def radial_cracked_fraction(sim, r0, r1):
    """Fraction of the radial interfaces (within 45° of the radius; analysis.cracks.radial_interfaces) with midpoint
    radius in [r0, r1) that have a broken spring."""
    a, b, r, mode = _interfaces(sim)
    sel = radial_interfaces(a, b, np.zeros(2)) & (r >= r0) & (r < r1)
    return float((mode > 0).any(axis=1)[sel].mean())


def tensile_orientation(sim, r_min):
    """Fraction of tensile-cracked interfaces beyond r_min whose edge lies within 30° of the radial direction."""
    a, b, r, mode = _interfaces(sim)
    mid = 0.5 * (a + b)
    t = (b - a) / np.linalg.norm(b - a, axis=1)[:, None]
    radial_cos = np.abs(np.einsum("ij,ij->i", t, mid / r[:, None]))
    tens = (mode == 1).any(axis=1) & (r > r_min)
    return int(tens.sum()), float(np.mean(radial_cos[tens] > np.cos(np.radians(30))))


def test_small_coupled_blast(blast):
    sim, s, out = blast
    e = s["energy"]
    c = s["cracks"][0]
    lo, hi = crushed_zone_bracket()
    n_tens, frac_radial = tensile_orientation(sim, 2 * c["dense_cracking_radius"])
    near_radial = radial_cracked_fraction(sim, R_B, 2 * R_B)
    print(f"blast: released {e['explosive_released']:.4g} J/m, rock KE {e['kinetic']:.4g}, fracture "
          f"{e['fracture']:.4g}, budget error {e['budget_error_relative']:.2%}; broken {s['broken_springs']}; "
          f"r_c/r_b {c['crushed_zone_radius_over_rb']:.2f} (bracket {lo:.2f}–{hi:.2f}); {c['radial_crack_count']} "
          f"radial cracks, longest {c['longest_radial_crack'] * 1e3:.1f} mm; {n_tens} tensile cracked interfaces "
          f"beyond 2 r_k, {frac_radial:.2f} of them within 30° of radial; {near_radial:.2f} of the radial interfaces "
          f"within 2 r_b cracked")
    # the charge burns completely: released energy = E0 × charge area
    assert abs(e["explosive_released"] / (E0_TABLE1 * np.pi * R_B**2) - 1) < 1e-9
    assert abs(e["budget_error_relative"]) < 0.05
    # the hoop tension behind the outgoing front exceeds σ_t well beyond the hole (the stress-wave cracking radius of
    # docs/validation.md §4 is ~12 r_b), so nearly every radial interface next to the wall cracks; whether the rock
    # there is also crushed (broken in every direction) is the next test, a known gap
    assert near_radial > 0.8
    # radial cracks outside it: several, reaching well beyond the crushed zone, tensile ones mostly radial
    assert c["radial_crack_count"] >= 6                  # 6–12 dominant radial cracks is the rule of thumb
    assert c["longest_radial_crack"] > 3 * c["dense_cracking_radius"]
    assert frac_radial > 0.45                            # a random orientation gives 1/3
    # outputs of a coupled run
    for f in ("summary.json", "resolved.toml", "monitors.csv", "energy.csv", "fracture_degree.csv", "rock.pvd",
              "gas.pvd", "fracture_pattern.png", "gas_pressure.png", "displacement_snapshots.png", "crack_profile.png"):
        assert (out / f).exists(), f
    summ = json.loads((out / "summary.json").read_text())
    assert summ["explosive"]["cj_check"]["D_cj"] > 0
    gp = np.loadtxt(out / "monitors.csv", delimiter=",", skiprows=1)[:, 1]
    assert gp.max() > 1e9, "detonation-product pressure is read at the monitor"


@pytest.mark.xfail(strict=True, reason="known gap (issue 11): the crushed zone is below the empirical bracket. "
                   "Crushed rock is broken in every direction (docs/results.md, r_c); here the radial interfaces next "
                   "to the wall crack (84-100 %) and the circumferential ones do not (4-19 % in 0.6 mm rings), so "
                   "r_c = 1.00 r_b, with the rock mesh and the MPM cell halved too (the former rule, all interfaces at "
                   "one half, gave 1.24 and 1.12 r_b: the share of radial interfaces in a ring). Mohr-Coulomb springs "
                   "cannot crush in uniaxial strain; the opt-in cap rock.crushing_strength puts r_c where the peak "
                   "stress passed it (docs/scenario.md, 'Crushing'), which is not a prediction of the default law")
def test_crushed_zone_in_the_empirical_bracket(blast):
    _, s, _ = blast
    lo, hi = crushed_zone_bracket()
    assert lo <= s["cracks"][0]["crushed_zone_radius_over_rb"] <= hi


def test_crushing_cap_keeps_the_energy_budget_and_reports_its_springs(tmp_path):
    """With rock.crushing_strength at the Mohr-Coulomb UCS the crushed springs carry on as closed broken springs, so
    no energy appears or goes missing: released = rock + gas + contact + losses within 2 % (the default law's run
    above: 5 %). Their count is reported apart and adds up; the zone is larger than the default law's."""
    phi = math.radians(ROCK["friction_angle"])
    ucs = 2 * ROCK["cohesion"] * math.cos(phi) / (1 - math.sin(phi))
    sim = Simulation(small_blast({"crushing_strength": ucs}, paraview=False), out_dir=tmp_path)
    s = sim.run()
    mode = sim.state.pair_mode.numpy()
    b, fd = s["broken_springs"], s["fracture_degree"]
    print(f"\n  cap at the UCS: budget error {s['energy']['budget_error_relative']:.3%}; broken {b}; "
          f"r_c/r_b {s['cracks'][0]['crushed_zone_radius_over_rb']:.2f}")
    assert abs(s["energy"]["budget_error_relative"]) < 0.02
    assert b["crushed"] == int((mode == 3).sum()) > 0
    assert b["total"] == b["tensile"] + b["shear"] + b["crushed"] == int((mode > 0).sum())
    assert fd["D_crushed"] == pytest.approx(b["crushed"] / len(mode), rel=1e-12)
    assert s["cracks"][0]["crushed_zone_radius_over_rb"] > crushed_zone_bracket()[0]


def test_crushed_zone_holds_when_the_mesh_is_halved(tmp_path):
    """Issue 11 item 3 where there is crushing: with the compressive cap at 4 UCS the small blast crushes well beyond
    the wall, and the crushed-zone radius (rings broken in every direction) changes by less than 15 % when the rock
    mesh and the MPM cell are halved (measured 5.29 → 5.24 r_b; the former rule, r_k, 8.15 → 7.64)."""
    phi = math.radians(ROCK["friction_angle"])
    ucs = 2 * ROCK["cohesion"] * math.cos(phi) / (1 - math.sin(phi))
    rc = []
    for scale in (1.0, 2.0):
        s = Simulation(small_blast({"crushing_strength": 4 * ucs}, scale=scale, paraview=False),
                       out_dir=tmp_path / f"s{scale:g}").run()
        rc.append(s["cracks"][0]["crushed_zone_radius_over_rb"])
    print(f"\n  cap 4 UCS: r_c/r_b {rc[0]:.2f} at h = r_b/5, {rc[1]:.2f} at h/2 ({rc[1] / rc[0] - 1:+.1%})")
    assert min(rc) > 2.0                                  # a crushed zone, not the wall ring
    assert abs(rc[1] / rc[0] - 1) < 0.15
