"""Uniaxial-strain strips for the steep-front cases: overshoot, spurious fracture and spalling.

A strip along x between rollers (top, bottom) is loaded by a pressure history on its left end; the right
end is viscous (non-reflecting) or free. Away from the ends this is a 1D uniaxial-strain wave problem
whose continuum answer is d'Alembert's: σ_xx(x, t) = −p(t − x/c_p) for the incident wave.
"""

from __future__ import annotations

import math

import numpy as np

from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

#: Table 2 rock with the default interface law (T 10 MPa, c 40 MPa, φ 40°, φ_r 30°)
ROCK = dict(density=2600.0, youngs_modulus=50e9, poisson_ratio=0.2, tensile_strength=10e6, cohesion=40e6,
            friction_angle=40.0, residual_friction_angle=30.0)


def p_wave_speed(rock: dict = ROCK) -> float:
    """Plane-strain c_p = √((λ + 2G)/ρ) [m/s] of the input rock."""
    E, nu, rho = rock["youngs_modulus"], rock["poisson_ratio"], rock["density"]
    return math.sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho)


def strip(h: float, pulse: dict, end_time: float, rock_extra: dict | None = None, length: float = 0.12,
          right: str = "viscous", rows: int = 6) -> Simulation:
    """A strip `length` × rows·h [m] meshed at h [m], pressure `pulse` on the left, `right` boundary on the right."""
    sc = scenario_from_dict({
        "simulation": {"end_time": end_time, "progress": False},
        "output": {"paraview": False, "figures": False},
        "rock": {**ROCK, **(rock_extra or {})},
        "geometry": {"domain": {"type": "rectangle", "width": length, "height": rows * h,
                                "center": [length / 2, 0.0]}, "mesh_size": h},
        "boundaries": {"left": {"type": "pressure", "pulse": pulse}, "right": {"type": right},
                       "top": {"type": "roller"}, "bottom": {"type": "roller"}},
    })
    return Simulation(sc, out_dir="/tmp/blastfrac_front_tests")


def centroids(sim: Simulation) -> np.ndarray:
    X = sim.model.host["node_X"]
    return (X[0::3] + X[1::3] + X[2::3]) / 3


def run_front(h: float, pulse: dict, amplitude: float, end_time: float, rock_extra: dict | None = None,
              probe: tuple[float, float] = (0.04, 0.08), **kw) -> dict:
    """Run a strip; per element in the probe band record the largest compression and tension over time.

    Returns overshoot_max / overshoot_mean (largest compression / amplitude − 1, the worst element and the
    mean over elements), tension_max (largest tension / amplitude), broken (springs) and springs.
    """
    sim = strip(h, pulse, end_time, rock_extra, **kw)
    c = centroids(sim)
    sel = np.flatnonzero((c[:, 0] > probe[0]) & (c[:, 0] < probe[1]))
    cmax, tmax = np.zeros(len(sel)), np.zeros(len(sel))
    for _ in range(int(math.ceil(end_time / sim.dt))):
        sim.step()
        s = sim.state.sigma.numpy()[sel, 0]
        cmax, tmax = np.maximum(cmax, -s), np.maximum(tmax, s)
    mode = sim.state.pair_mode.numpy()
    return {"overshoot_max": float(cmax.max() / amplitude - 1), "overshoot_mean": float(cmax.mean() / amplitude - 1),
            "tension_max": float(tmax.max() / amplitude), "broken": int((mode > 0).sum()), "springs": len(mode),
            "sim": sim}
