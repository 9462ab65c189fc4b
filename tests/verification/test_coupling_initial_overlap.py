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
import pytest

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


def test_switch_of_deepest_feature_keeps_the_force_continuous():
    """A particle deep inside a rock corner whose deepest edge changes must not be fired.

    One triangle, corner at (L, 0) between the bottom edge (outward normal −y) and the right edge (+x). The
    particle first meets the right edge 0.6 r_p deep (δ₀ = 0.5 r_p ignored, 0.1 r_p pushes), then sits
    where the bottom edge is the deeper one (1.9 r_p). Reusing the right edge's δ₀ against the bottom edge
    would push with k_c·1.4 r_p, fourteen times the slack (what made a single-hole blast go unstable);
    the ignored part is re-based on the switch, so the force stays at k_c·0.1 r_p.
    """
    from blastfrac.coupling import GasRockCoupler
    from blastfrac.materials.jwl import JWLParams
    from blastfrac.model.builder import ModelBuilder
    from blastfrac.mpm.grid import GridSpec
    from blastfrac.mpm.solver import MPMOptions, MPMSolver
    from conftest import scenario
    from coupling_helpers import structured_rectangle

    L, rp, kc = 0.01, 1e-3, 1e9
    model = ModelBuilder(scenario(geometry={"domain": {"type": "rectangle", "width": 1.0, "height": 1.0},
                                            "mesh_size": 0.01}),
                         mesh=structured_rectangle(0.0, 0.0, L, L, 1, 1)).finalize("cpu")
    st = model.state()
    gas = JWLParams(rho0=1000.0, D=1000.0, A=0.0, B=0.0, R1=4.0, R2=1.0, omega=0.4, E0=1e3)
    spec = GridSpec.from_bounds((-0.01, -0.01), (0.02, 0.02), 2.5e-3)
    x1 = np.array([[L + 0.4 * rp, 0.5 * rp]])             # right of the corner: 0.6 r_p into the right edge
    mpm = MPMSolver.from_arrays(x1, np.array([4 * rp * rp]), spec, gas, MPMOptions(), burn=np.zeros(1))
    cp = GasRockCoupler(model, mpm, kc=kc, rebuild_interval=1)
    cp.apply(st, 1e-9)
    cp.add_reactions(st)
    f1 = np.linalg.norm(mpm.f_ext_p.numpy()[0])
    mpm.x.assign(np.array([[L - 0.3 * rp, 0.9 * rp]]))   # inside the corner: bottom edge 1.9 r_p deep, right 1.3
    st.f.zero_()
    cp.apply(st, 1e-9)
    cp.add_reactions(st)
    f2 = mpm.f_ext_p.numpy()[0]
    slack = NEW_CONTACT_SLACK_NP * rp
    print(f"\n  first contact {f1 / (kc * slack):.2f}, after the switch {np.linalg.norm(f2) / (kc * slack):.2f} k_c·slack; "
          f"direction {f2 / np.linalg.norm(f2)}")
    assert f1 == pytest.approx(kc * slack, rel=1e-6)
    assert f2[1] < 0 and abs(f2[0]) < 1e-9 * abs(f2[1]), "the bottom edge pushes now"
    assert np.linalg.norm(f2) < 1.01 * kc * slack
