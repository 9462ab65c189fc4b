"""Gas stays out of intact rock and flows into a crack once the crack is wider than a particle (METHOD §3.7).

A pressurised ideal gas fills a borehole in an unbreakable block; one radial crack of 8 mm is cut beforehand
(both springs of the interfaces on a mesh path marked broken). Expected: no particle ever inside an intact
element; particles found inside the crack, each where the local opening exceeds about one particle diameter;
and with no crack, no particle beyond the wall.
"""

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from blastfrac.coupling.seeding import inside_elements
from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

R_B, CRACK = 0.004, 0.008


def _scenario():
    return scenario_from_dict({
        "simulation": {"end_time": 25e-6, "progress": False},
        "output": {"paraview": False, "figures": False},
        "rock": {"density": 2600.0, "youngs_modulus": 5e9, "poisson_ratio": 0.2, "unbreakable": True},
        "geometry": {"domain": {"type": "rectangle", "width": 0.04, "height": 0.04}, "mesh_size": 0.002,
                     "mesh_size_near": 0.0004, "refinement_distance": 0.012,
                     "boreholes": [{"center": [0.0, 0.0], "radius": R_B}]},
        "explosive": {"constants": {"rho0": 1000.0, "D": 5000.0, "A": 0.0, "B": 0.0, "R1": 4.0, "R2": 1.0,
                                    "omega": 0.4, "E0": 300e6 / 0.4},
                      "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": R_B}],
                      "grid": {"cell_size": 0.0005, "points_per_cell": 2}, "burn": {"mode": "instant"}},
        "coupling": {"contact_stiffness": 60e9},
    })


def _cut_crack(sim):
    """Mark broken both springs of the interfaces on the mesh path from (R_B, 0) to (R_B + CRACK, 0)."""
    mesh, topo = sim.model.mesh, sim.model.topology
    V, T = mesh.vertices, mesh.triangles
    e = np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]])
    w = np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1)
    g = coo_matrix((w, (e[:, 0], e[:, 1])), shape=(len(V), len(V))).tocsr()
    a = int(np.argmin(np.linalg.norm(V - [R_B, 0.0], axis=1)))
    b = int(np.argmin(np.linalg.norm(V - [R_B + CRACK, 0.0], axis=1)))
    _, pred = dijkstra(g, directed=False, indices=a, return_predecessors=True)
    path = [b]
    while path[-1] != a:
        path.append(int(pred[path[-1]]))
    pn = topo.pair_nodes
    va, vb = topo.node_vertex[pn[0::2, 0]], topo.node_vertex[pn[1::2, 0]]
    key = {frozenset((int(p), int(q))): i for i, (p, q) in enumerate(zip(va, vb))}
    ifaces = [key[frozenset((path[k], path[k + 1]))] for k in range(len(path) - 1)]
    mode = sim.state.pair_mode.numpy()
    for q in ifaces:
        mode[2 * q], mode[2 * q + 1] = 1, 1
    sim.state.pair_mode.assign(mode)
    return np.array(ifaces)


def _run(cut: bool):
    sim = Simulation(_scenario(), out_dir=None)
    ifaces = _cut_crack(sim) if cut else np.zeros(0, int)
    inside_max = 0
    while sim.time < 25e-6:
        sim.step()
        if sim.steps % 200 == 0:
            inside_max = max(inside_max, int(inside_elements(sim.gas.x.numpy(), sim.state.x.numpy()).sum()))
    return sim, ifaces, inside_max


@pytest.mark.parametrize("cut", [False, True], ids=["intact", "cracked"])
def test_gas_leak_and_crack_entry(cut):
    sim, ifaces, inside_max = _run(cut)
    xp = sim.gas.x.numpy()
    r_p = np.minimum(0.5 * np.sqrt(sim.gas.vol.numpy()), sim.coupler.r_max)    # contact radius, capped
    r = np.linalg.norm(xp, axis=1)
    beyond = r > R_B + 2 * r_p.max()                       # clearly past the (deformed) wall
    x = sim.state.x.numpy()
    wall_growth = np.linalg.norm(x, axis=1)[np.linalg.norm(sim.model.host["node_X"], axis=1) < R_B * 1.01].max() - R_B
    print(f"{'cracked' if cut else 'intact'}: {sim.gas.n} particles, {int(beyond.sum())} beyond the wall, "
          f"max inside intact elements {inside_max}, wall moved {wall_growth * 1e6:.1f} µm, "
          f"deactivated {sim.gas.deactivated_count}")
    assert inside_max == 0, "no particle inside an intact element"
    assert sim.gas.deactivated_count == 0
    if not cut:
        assert not np.any(r > R_B + wall_growth + r_p.max()), "no particle beyond the wall of an intact hole"
        return
    assert beyond.sum() >= 5, "gas flows into the open crack"
    # every particle in the crack sits where the crack is open by about a particle diameter or more
    pn = sim.model.topology.pair_nodes
    pairs = np.concatenate([2 * ifaces, 2 * ifaces + 1])
    mid = 0.5 * (x[pn[pairs, 0]] + x[pn[pairs, 1]])
    opening = np.linalg.norm(x[pn[pairs, 0]] - x[pn[pairs, 1]], axis=1)
    for p in np.flatnonzero(beyond):
        near = np.argsort(np.linalg.norm(mid - xp[p], axis=1))[:2]
        assert opening[near].max() > 1.5 * r_p[p], f"particle {p} in a crack narrower than itself"
    assert np.all(np.abs(xp[beyond, 1]) < 0.003) and np.all(xp[beyond, 0] > 0), "only inside the cut crack"
