"""A contact that appears already deep must not fire the gas particle (particle_edge.initial_overlap).

Gas particles at rest and at (almost) zero pressure are placed on a ring just inside a borehole wall so
that each overlaps the wall by about 0.8 r_p on the first step — what happens when an interface becomes
exposed under an expanded particle, or a fragment sweeps over one. With the full penalty law each would
leave at v ≈ δ·√(k_c/m_p) (its penalty energy ½k_c·δ² turned into kinetic energy: about 8·v_allow here).
Expected: only the part of the overlap a new contact may have (0.1 r_p) pushes, so the gas ends up with no
more kinetic energy than the ½k_c(0.1 r_p)² per particle that the slack allows, and particle speeds stay
near v_allow = 0.1·r_p·√(k_c/m_p) (the release of that slack into one particle; the grid spreads a
contact force over neighbouring particles, so single speeds may exceed it a little: 1.5 v_allow is allowed).
"""

import numpy as np

from blastfrac.coupling.particle_edge import NEW_CONTACT_SLACK_NP, edge_overlap_np
from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

R_B = 0.004
KC = 60e9


def _sim():
    sc = scenario_from_dict({
        "simulation": {"end_time": 1e-5, "progress": False},
        "output": {"paraview": False, "figures": False},
        "rock": {"density": 2600.0, "youngs_modulus": 5e9, "poisson_ratio": 0.2, "unbreakable": True},
        "geometry": {"domain": {"type": "rectangle", "width": 0.03, "height": 0.03}, "mesh_size": 0.002,
                     "mesh_size_near": 0.0005, "refinement_distance": 0.01,
                     "boreholes": [{"center": [0.0, 0.0], "radius": R_B}]},
        "explosive": {"constants": {"rho0": 1000.0, "D": 5000.0, "A": 0.0, "B": 0.0, "R1": 4.0, "R2": 1.0,
                                    "omega": 0.4, "E0": 1e3},
                      "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": R_B}],
                      "grid": {"cell_size": 0.0005, "points_per_cell": 2}, "burn": {"mode": "instant"}},
        "coupling": {"contact_stiffness": KC, "wall_clearance": 0.0, "rebuild_interval": 1},
    })
    return Simulation(sc, out_dir="/tmp/blastfrac_test_overlap")


def _wall_overlaps(sim, x, rp):
    """Largest overlap [m] of each point with the borehole wall edges (computed here from the mesh)."""
    X = sim.model.host["node_X"]
    slots = sim.model.topology.boundary_slots
    best = np.zeros(len(x))
    for s in slots:
        a, b = X[s], X[3 * (s // 3) + (s % 3 + 1) % 3]
        if np.linalg.norm(0.5 * (a + b)) > 2 * R_B:
            continue
        for i, p in enumerate(x):
            d = edge_overlap_np(p, rp, a, b)[0]
            best[i] = max(best[i], d)
    return best


def test_deep_first_contact_does_not_fire_particles():
    sim = _sim()
    gas = sim.gas
    x = gas.x.numpy()
    rp = 0.5 * np.sqrt(gas.vol.numpy().mean())
    # a ring of particles whose centres sit 0.2 r_p inside the wall: overlap ≈ 0.8 r_p (chord sag adds a bit)
    ring = np.arange(0, len(x), max(1, len(x) // 24))[:24]
    ang = 2 * np.pi * np.arange(len(ring)) / len(ring) + 0.1
    x[ring] = (R_B - 0.2 * rp) * np.stack([np.cos(ang), np.sin(ang)], 1)
    keep = np.ones(len(x), bool)
    keep[ring] = False
    x[keep] *= 0.3                                           # the rest well away from the wall
    gas.x.assign(x)
    d0 = _wall_overlaps(sim, x[ring], rp)
    assert d0.min() > 0.6 * rp, "set-up: every ring particle must start deep in contact"
    m_p = gas.mass.numpy()[ring].max()
    v_full = d0.max() * np.sqrt(KC / m_p)                    # what the plain penalty law gives
    v_allow = NEW_CONTACT_SLACK_NP * rp * np.sqrt(KC / gas.mass.numpy()[ring].min())
    vmax = 0.0
    for _ in range(300):
        sim.step()
        vmax = max(vmax, float(np.linalg.norm(gas.v.numpy()[ring], axis=1).max()))
    ke = 0.5 * float((gas.mass.numpy() * (gas.v.numpy() ** 2).sum(1)).sum())
    ke_allow = len(ring) * 0.5 * KC * (NEW_CONTACT_SLACK_NP * rp) ** 2
    print(f"\n  overlap at start {d0.min() / rp:.2f}-{d0.max() / rp:.2f} r_p; max particle speed {vmax:.2f} m/s "
          f"(bound {v_allow:.2f}, full penalty would give {v_full:.1f}); gas KE {ke:.3g} J/m (bound {ke_allow:.3g})")
    assert v_full > 5 * v_allow                              # the test can tell the two laws apart
    assert vmax < 1.5 * v_allow
    assert ke < 1.2 * ke_allow
