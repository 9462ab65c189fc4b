"""A compressive plane wave that no continuum stress state could break must not break the springs.

Uniaxial strain (rollers top and bottom), 1 GPa triangular pressure pulse (0.5 µs rise, 4 µs long) on the
left of a 80 x 20 mm block of the paper's Table 3 rock (T = 14 MPa, c = 26 MPa, φ = 60°). In uniaxial
strain σ_yy = ν/(1−ν)·σ_xx, so the worst interface orientation has
    max_θ [τ − σ_n tanφ] = R − C·sinφ ... < c·cosφ
with centre C = (1+k)/2·S and radius R = (1−k)/2·S, k = ν/(1−ν), for every compressive amplitude S when
(1−k) < (1+k)·sinφ (checked below): neither Y19 nor Y20 can be met anywhere while the pulse passes, and
behind it the stress returns to zero. Whatever breaks is numerical ringing behind the steep front, whose
tensile overshoot only has to reach 1.4 % of the amplitude to exceed T.

Expected: the paper's lattice (lumped mass, no damping) breaks a large fraction (the defect this guards
against: 21 % in our runs); with the default averaged mass and the blast damping of the shipped examples
(shock viscosity C_l = 0.02, C_q = 1.5, spring dashpots ζ = 0.15; docs/rock_fronts.md) less than 3 % (2.6 %,
next to the loaded face, where this pulse's 0.5 µs front still spans only about three elements; 2.3 % with the
former C_l 0.03, ζ 0.1), and the damping must not eat the wave: 30 mm in, the peak is 917 MPa against 1031 MPa
undamped (the v0.1 damping with C_l = 0.5 gave 767 MPa), so the test asserts no more than 30 % loss.
"""

import math

import numpy as np

from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

NU, PHI, PEAK = 0.16, 60.0, 1e9


def _run(**rock_extra):
    sc = scenario_from_dict({
        "simulation": {"end_time": 12e-6, "progress": False},
        "output": {"paraview": False, "figures": False},
        "rock": {"density": 2640.0, "youngs_modulus": 51e9, "poisson_ratio": NU, "stiffness_mode": "per_area",
                 "kn": 1.8e15, "ks": 1.6e15, "tensile_strength": 14e6, "cohesion": 26e6, "friction_angle": PHI,
                 "residual_friction_angle": 30.0, **rock_extra},
        "geometry": {"domain": {"type": "rectangle", "width": 0.08, "height": 0.02}, "mesh_size": 0.0008},
        "boundaries": {"left": {"type": "pressure", "pulse": {"type": "triangle", "peak": PEAK, "rise_time": 0.5e-6,
                                                              "duration": 4e-6}},
                       "right": {"type": "viscous"}, "top": {"type": "roller"}, "bottom": {"type": "roller"}},
        "monitors": [{"name": "m", "position": [-0.01, 0.0], "quantities": ["sxx"]}],
    })
    sim = Simulation(sc, out_dir="/tmp/blastfrac_test_rock_viscosity")
    X = sim.model.host["node_X"]
    probe = np.where(np.abs(X[:, 0] + 0.01) < 0.001)[0] // 3
    peak = 0.0
    n = int(math.ceil(sc.simulation.end_time / sim.dt))
    for _ in range(n):
        sim.step()
        peak = max(peak, float(-sim.state.sigma.numpy()[probe, 0].mean()))
    broken = float(np.mean(sim.state.pair_mode.numpy() != 0))
    return broken, peak


def test_plane_compression_wave_breaks_no_springs_with_shock_damping():
    k = NU / (1 - NU)
    assert (1 - k) < (1 + k) * math.sin(math.radians(PHI))   # no orientation can fail in uniaxial compression
    bare, peak_bare = _run(mass_matrix="lumped")
    damped, peak = _run(bulk_viscosity_linear=0.02, bulk_viscosity_quadratic=1.5, spring_damping=0.15)
    print(f"\n  broken fraction: undamped {bare:.3f}, damped {damped:.4f}; peak sxx 30 mm in: undamped "
          f"{peak_bare / 1e6:.0f} MPa, damped {peak / 1e6:.0f} MPa")
    assert bare > 0.10                                       # the test can see the defect
    assert damped < 0.03
    assert peak > 0.7 * peak_bare
