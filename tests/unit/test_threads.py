"""simulation.threads = 2 runs the gas stages beside the rock's in a second thread, and the springs (and the CST, the
integration and block contact's pass) in two halves:
the same arithmetic, so the same motion, spring states and energy accounts, bit for bit (a coupled blast with crack
gas, cracking, dashpots and bulk viscosity: each spring and block keeps its own damping account, so no total is
summed in another order by the second thread)."""

import numpy as np

from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation


def _scenario(threads: int) -> dict:
    r_b, h = 0.003, 0.00075
    return {
        "title": "threads", "simulation": {"end_time": 4e-6, "progress": False, "threads": threads},
        "output": {"paraview": False, "figures": False},
        "rock": {"density": 2600.0, "youngs_modulus": 50e9, "poisson_ratio": 0.2, "tensile_strength": 10e6,
                 "cohesion": 40e6, "friction_angle": 40.0, "residual_friction_angle": 30.0,
                 "bulk_viscosity_linear": 0.02, "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.15},
        "geometry": {"domain": {"type": "rectangle", "width": 0.04, "height": 0.04}, "mesh_size": 5 * h,
                     "mesh_size_near": h, "refinement_distance": 0.012,
                     "boreholes": [{"center": [0.0, 0.0], "radius": r_b}]},
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
        "explosive": {"name": "emulsion", "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": r_b}],
                      "grid": {"cell_size": h, "points_per_cell": 2, "bounds": [[-0.012, -0.012], [0.012, 0.012]]}},
        "crack_gas": {"enabled": True},
    }


def test_two_threads_give_the_same_results_as_one(tmp_path):
    out = {}
    for n in (1, 2):
        sim = Simulation(scenario_from_dict(_scenario(n)), out_dir=tmp_path / str(n))
        assert (sim._pool is None) == (n == 1)
        sim.cdem.split_min = 0                             # split the springs of this small model too
        if sim._second is not None:
            sim._second.WINDOWS = 0                        # no timing trial: every step after the first uses both
        sim.run()
        if n == 2:   # the integration ran in two parts beside the gas's advance, its split point moving (balanced),
            assert sim.cdem._share.get("integrate", 0.5) != 0.5
            assert sim.cdem.contact.passes_in_parts > 0     # and block contact's pass over its list in two halves
        out[n] = {"x": sim.state.x.numpy(), "v": sim.state.v.numpy(), "mode": sim.state.pair_mode.numpy(),
                  "gas_x": sim.gas.x.numpy(), "gas_ie": sim.gas.ie.numpy(), "crack": sim.crack_gas.gas.mass.numpy(),
                  "ppv": sim.ppv.values(), "energy": sim.state.energy_acc.numpy(),
                  "pair_damp": sim.state.pair_damp.numpy(), "elem_damp": sim.state.elem_damp.numpy(),
                  "budget": sim.energies()}
    assert out[1]["mode"].any() and out[1]["crack"].sum() > 0
    assert out[1]["pair_damp"].sum() > 0 and out[1]["elem_damp"].sum() > 0      # both damping terms did work
    for k in out[1]:
        if k == "budget":
            assert out[1][k] == out[2][k]
        else:
            assert np.array_equal(out[1][k], out[2][k]), k
