"""A small coupled blast runs to completion: cracks form around the hole, radial ones outside the crushed
zone, and the energy budget (explosive energy released = rock + gas + contact + losses) closes within 5 %."""

import json

import numpy as np
import pytest

from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

R_B = 0.005


@pytest.fixture(scope="module")
def blast(tmp_path_factory):
    r_b = R_B
    sc = scenario_from_dict({
        "title": "small coupled blast",
        "simulation": {"end_time": 15e-6, "progress": False},
        "output": {"paraview": True, "figures": True, "interval": 5e-6},
        "rock": {"density": 2600.0, "youngs_modulus": 50e9, "poisson_ratio": 0.2, "tensile_strength": 10e6,
                 "cohesion": 40e6, "friction_angle": 40.0, "residual_friction_angle": 30.0},
        "geometry": {"domain": {"type": "rectangle", "width": 0.08, "height": 0.08}, "mesh_size": 0.004,
                     "mesh_size_near": 0.0008, "refinement_distance": 0.02,
                     "boreholes": [{"center": [0.0, 0.0], "radius": r_b}]},
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
        "monitors": [{"name": "hole", "position": [0.0, 0.0], "quantities": ["gas_pressure"]}],
        "explosive": {"constants": {"rho0": 1300.0, "D": 4000.0, "A": 0.0, "B": 0.0, "R1": 4.2, "R2": 0.9,
                                    "omega": 0.4, "E0": 0.5e9},
                      "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": r_b}],
                      "grid": {"cell_size": 0.001, "points_per_cell": 2}},
    })
    out = tmp_path_factory.mktemp("blast")
    sim = Simulation(sc, out_dir=out)
    return sim, sim.run(), out


def _tensile_orientation(sim):
    """Fraction of tensile-cracked interfaces beyond 3 r_b whose edge lies within 30° of the radial direction."""
    m = sim.model
    pn = m.topology.pair_nodes
    X = m.host["node_X"]
    mode = sim.state.pair_mode.numpy().reshape(-1, 2)
    a, b = X[pn[0::2, 0]], X[pn[1::2, 0]]
    mid = 0.5 * (a + b)
    r = np.linalg.norm(mid, axis=1)
    t = (b - a) / np.linalg.norm(b - a, axis=1)[:, None]
    radial_cos = np.abs(np.einsum("ij,ij->i", t, mid / r[:, None]))
    tens = (mode == 1).any(axis=1) & (r > 3 * R_B)
    return tens, float(np.mean(radial_cos[tens] > np.cos(np.radians(30)))), mode, r


def test_small_coupled_blast(blast):
    sim, s, out = blast
    r_b = R_B
    e = s["energy"]
    print(f"blast: released {e['explosive_released']:.4g} J/m, rock KE {e['kinetic']:.4g}, fracture "
          f"{e['fracture']:.4g}, budget error {e['budget_error_relative']:.2%}; broken {s['broken_springs']}; "
          f"cracks {s['cracks'][0]['radial_crack_count']} radial, r_c/r_b {s['cracks'][0]['crushed_zone_radius_over_rb']:.2f}")
    # the charge burns completely: released energy = E0 × charge area
    assert abs(e["explosive_released"] / (0.5e9 * np.pi * r_b**2) - 1) < 1e-9
    assert abs(e["budget_error_relative"]) < 0.05
    # cracks: damage at the wall, tensile cracks beyond the crushed zone
    tens, frac_radial, mode, r = _tensile_orientation(sim)
    print(f"tensile cracks beyond 3 r_b: {int(tens.sum())}, within 30° of radial: {frac_radial:.2f}")
    assert tens.sum() >= 20, "tensile cracks beyond the crushed zone"
    near = r < 1.6 * r_b
    assert (mode[near] > 0).any(axis=1).mean() > 0.3, "damage at the wall"
    assert s["cracks"][0]["radial_crack_count"] >= 3
    # outputs of a coupled run
    for f in ("summary.json", "resolved.toml", "monitors.csv", "energy.csv", "fracture_degree.csv", "rock.pvd",
              "gas.pvd", "fracture_pattern.png", "gas_pressure.png", "displacement_snapshots.png"):
        assert (out / f).exists(), f
    summ = json.loads((out / "summary.json").read_text())
    assert summ["explosive"]["cj_check"]["D_cj"] > 0
    gp = np.loadtxt(out / "monitors.csv", delimiter=",", skiprows=1)[:, 1]
    assert gp.max() > 50e6, "gas pressure is read at the monitor"


@pytest.mark.xfail(strict=True, reason="known gap: the coupled blast breaks a dense network; tensile cracks beyond "
                   "3 r_b are not yet preferentially radial (0.36 within 30° of radial, random = 1/3)")
def test_tensile_cracks_run_radially(blast):
    sim, _, _ = blast
    _, frac_radial, _, _ = _tensile_orientation(sim)
    assert frac_radial > 0.45          # a random orientation gives 1/3
