"""Gas-filled borehole: the wall feels the gas pressure, no more (METHOD §3 coupling check).

Set-up: a 5 mm hole in unbreakable elastic rock, filled with an ideal gas (JWL with A = B = 0, p = ωE/V,
γ = 1 + ω) burnt at t = 0 to p0 = ωE0 = 200 MPa, on a 1 mm grid with 2 points per cell.

Closed forms used:

* Wall load. A uniform pressure p on the meshed wall (a polygon, nodes on the circle) gives the wall nodes
  radial forces summing to p·G, G = Σ_edges L_e·½(n̂_e·r̂_a + n̂_e·r̂_b) (each edge's force p·L_e·n̂_e shared
  equally by its two nodes). The wall pressure is p_w = Σ(contact reactions·r̂)/G.
* Gas pressure. The hole grows by ~1 % of its area, slowly compared with the gas's sound speed
  (wall speed ~ p0/(ρ_r c_p) ≈ 17 m/s against c ≈ 460 m/s), so the gas expands quasi-statically along its
  isentrope: p_isen(t) = p0·(A(0)/A(t))^γ with A the hole's area from the wall nodes.
* Rock response. A step pressure p0 on a cylindrical cavity sends a front whose radial stress falls off as
  p0·(r_b/r)^½ (cylindrical spreading); at 2 r_b that is 0.71 p0. The same rock loaded by a prescribed
  pressure step on the wall (borehole_pressure) is the reference for the coupled run.

Before the fix (lattice seeding, contact force applied at the particle centre, plain penalty) the wall load
peaked at 1.6–2 p0 after the gas crossed the seeding void, its 2–8 µs mean exceeded the gas pressure by
~15–30 %, and the outer gas layer was stretched to 0.7 p0: the last test below checks that this test
would have caught it.
"""

import numpy as np

from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

R_B = 0.005
P0, OMEGA, RHO_G = 200e6, 0.4, 1300.0
T_END = 8e-6
R_MON = 2 * R_B
ANGLES = np.arange(8) * np.pi / 4


def _scenario(coupled: bool, seeding: str = "conformal") -> dict:
    d = {
        "title": "gas-filled hole", "simulation": {"end_time": T_END, "progress": False},
        "output": {"paraview": False, "figures": False, "monitor_interval": 2e-8},
        "rock": {"density": 2600.0, "youngs_modulus": 50e9, "poisson_ratio": 0.2, "tensile_strength": 10e6,
                 "cohesion": 40e6, "friction_angle": 40.0, "residual_friction_angle": 30.0, "unbreakable": True},
        "geometry": {"domain": {"type": "rectangle", "width": 0.08, "height": 0.08}, "mesh_size": 0.004,
                     "mesh_size_near": 0.0008, "refinement_distance": 0.02,
                     "boreholes": [{"center": [0.0, 0.0], "radius": R_B}]},
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
        "monitors": [{"name": f"m{k}", "position": [R_MON * np.cos(a), R_MON * np.sin(a)],
                      "quantities": ["sxx", "syy", "sxy"]} for k, a in enumerate(ANGLES)],   # located, not run
        "coupling": {"damping_ratio": 0.7},
    }
    if coupled:
        d["explosive"] = {"constants": {"rho0": RHO_G, "D": 4000.0, "A": 0.0, "B": 0.0, "R1": 4.2, "R2": 0.9,
                                        "omega": OMEGA, "E0": P0 / OMEGA},
                          "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": R_B}],
                          "grid": {"cell_size": 0.001, "points_per_cell": 2}, "burn": {"mode": "instant"},
                          "seeding": seeding}
    else:   # the same step on the wall, prescribed (0.1 µs rise)
        d["borehole_pressure"] = [{"borehole": 0, "pulse": {"type": "table", "times": [0.0, 1e-7, 1.0],
                                                            "values": [0.0, P0, P0]}}]
    return d


def _run(coupled: bool, tmp_path, seeding: str = "conformal", former: bool = False) -> dict:
    sim = Simulation(scenario_from_dict(_scenario(coupled, seeding)), out_dir=tmp_path)
    X = sim.model.host["node_X"]
    wall = np.abs(np.linalg.norm(X, axis=1) - R_B) < 1e-3 * R_B
    slots = sim.model.topology.boundary_slots
    a, b = slots, 3 * (slots // 3) + (slots % 3 + 1) % 3
    on = wall[a] & wall[b]
    a, b = a[on], b[on]
    mon = sim.monitors.elems                                          # elements at r = 2 r_b
    c, s = np.cos(ANGLES), np.sin(ANGLES)
    peaks = np.zeros(len(ANGLES))                                     # largest −σ_rr seen there [Pa]
    rec = {"t": [], "p_wall": [], "p_gas": [], "p_isen": []}
    if coupled and former:
        sim.coupler.surface_forces = False
        sim.coupler.pressure_preload = False
    A0 = None
    reset = False
    while sim.time < T_END:
        sim.step()
        if coupled and not reset and sim.time >= 2e-6:
            sim.wall_load.sample(sim.time)          # borehole_pressure.csv's time mean, from 2 µs on
            reset = True
        x = sim.state.x.numpy()
        sig = sim.state.sigma.numpy()[mon]
        peaks = np.maximum(peaks, -(sig[:, 0] * c * c + sig[:, 1] * s * s + 2 * sig[:, 2] * c * s))
        xa, xb = x[a], x[b]
        area = 0.5 * abs(np.sum(xa[:, 0] * xb[:, 1] - xb[:, 0] * xa[:, 1]))
        A0 = area if A0 is None else A0
        if not coupled or sim.steps % 5:
            continue
        t_e = xb - xa
        L = np.linalg.norm(t_e, axis=1)
        n_e = np.stack([-t_e[:, 1], t_e[:, 0]], 1) / L[:, None]
        rhat = lambda p: p / np.linalg.norm(p, axis=1)[:, None]  # noqa: E731
        n_e *= np.sign(np.einsum("ij,ij->i", n_e, rhat(0.5 * (xa + xb))))[:, None]   # radial outward
        G = float(np.sum(L * 0.5 * (np.einsum("ij,ij->i", n_e, rhat(xa)) + np.einsum("ij,ij->i", n_e, rhat(xb)))))
        f = sim.coupler.f_react.numpy()
        nodes = np.flatnonzero(wall)
        p_wall = float(np.einsum("ij,ij->i", f[nodes], rhat(x[nodes])).sum()) / G
        g = sim.gas.particle_fields()
        r = np.linalg.norm(g["position"], axis=1)
        outer = r > R_B - sim.gas.spec.h / sim.gas.opts.ppc          # the particles next to the wall
        rec["t"].append(sim.time)
        rec["p_wall"].append(p_wall)
        rec["p_gas"].append(float(np.average(g["pressure"][outer], weights=g["volume"][outer])))
        rec["p_isen"].append(P0 * (A0 / area) ** (1.0 + OMEGA))
    out = {k: np.asarray(v) for k, v in rec.items()}
    out["peaks"] = peaks
    if coupled:
        out["p_wall_mean_csv"] = sim.wall_load.sample(sim.time)[0]
    out["removed"] = sim.gas_report.get("removed_at_seeding", 0) if coupled else 0
    return out


def test_wall_load_equals_gas_pressure(tmp_path):
    gas = _run(True, tmp_path / "gas")
    ref = _run(False, tmp_path / "pulse")
    t = gas["t"]
    late = t > 2e-6
    pw, pg, pi = (gas[k][late].mean() for k in ("p_wall", "p_gas", "p_isen"))
    front = P0 * np.sqrt(R_B / R_MON)
    print(f"\n  2-8 µs means: wall {pw / 1e6:.1f} MPa, gas at the wall {pg / 1e6:.1f}, isentrope {pi / 1e6:.1f}; "
          f"wall max {gas['p_wall'].max() / 1e6:.1f} MPa (p0 {P0 / 1e6:.0f})")
    print(f"  peak -σrr at 2 r_b: coupled mean {gas['peaks'].mean() / 1e6:.1f} (max {gas['peaks'].max() / 1e6:.1f}), "
          f"prescribed mean {ref['peaks'].mean() / 1e6:.1f} (max {ref['peaks'].max() / 1e6:.1f}), "
          f"p0·(r_b/r)^½ = {front / 1e6:.1f} MPa")
    assert gas["removed"] == 0, "conformal seeding: the outer ring is moved onto the meshed wall, not deleted"
    # the gas follows its isentrope, right up to the wall (no stretched outer layer)
    assert abs(pg / pi - 1) < 0.03
    # the wall feels the gas pressure: ∮p ds, within a few %
    assert abs(pw / pg - 1) < 0.03
    assert abs(pw / pi - 1) < 0.03
    # the borehole_pressure.csv history (impulse / time / G, analysis/wall_load.py) tells the same mean
    print(f"  borehole_pressure.csv 2-8 µs mean {gas['p_wall_mean_csv'] / 1e6:.1f} MPa")
    assert abs(gas["p_wall_mean_csv"] / pi - 1) < 0.03
    # no impact on the wall: the gas only expands, so its pressure never exceeds p0
    assert gas["p_wall"].max() < 1.12 * P0
    # the rock sees what a prescribed wall pressure gives it
    assert 0.6 < ref["peaks"].mean() / front < 1.2, "reference run: cylindrical spreading of the front"
    assert 0.75 < gas["peaks"].mean() / ref["peaks"].mean() < 1.1
    assert gas["peaks"].max() < 1.1 * ref["peaks"].max()


def test_former_scheme_is_caught(tmp_path):
    """Lattice seeding, forces at the particle centre, plain penalty: the checks above fail."""
    old = _run(True, tmp_path / "old", seeding="lattice", former=True)
    late = old["t"] > 2e-6
    pw, pg = old["p_wall"][late].mean(), old["p_gas"][late].mean()
    print(f"\n  former scheme: wall {pw / 1e6:.1f} MPa vs gas at the wall {pg / 1e6:.1f}, max {old['p_wall'].max() / 1e6:.1f}")
    # each fails its check in test_wall_load_equals_gas_pressure (measured with the 0.2 gas defaults: max 1.28 p0;
    # with pure FLIP and q2 = 0.06 it was 1.6-2 p0)
    assert old["p_wall"].max() > 1.12 * P0
    assert pw / pg > 1.1
