"""The crack gas's face loads reach the rock whole, once, and only for the step that made them.

The stage lists the nodes it loads (kernels_crack_gas.FaceLoads) and adds and clears the loads at those nodes only,
instead of passes over every node of the rock. The reference here is the definition: each pressurised cell pushes
its four nodes with the forces it stored (gas.force), so the rock's nodal force grows by their sum per node
(np.add.at over the cells), whichever nodes two cells share; a step that the rock does not take up leaves nothing
behind for the next.
"""

from __future__ import annotations

import numpy as np

from blastfrac.coupling.crack_gas import CrackGas
from blastfrac.model.builder import ModelBuilder
from conftest import scenario
from verification.crack_helpers import break_interfaces, emulsion, interfaces_on_segment, plate_with_crack


def _setup(p_cells):
    width, a = 0.1, 0.02
    sc = scenario(geometry={"domain": {"type": "rectangle", "width": width, "height": width}, "mesh_size": width / 10})
    m = ModelBuilder(sc, plate_with_crack(width, a, a / 4, width / 10)).finalize("cpu")
    st = m.state()
    q = interfaces_on_segment(m, -a, a)
    # and every interface at the crack's middle vertex (a crushed star): there each node has both of its
    # element's edges broken, so it belongs to two pressurised cells
    pn = m.topology.pair_nodes
    vA, vB = m.topology.node_vertex[pn[0::2, 0]], m.topology.node_vertex[pn[1::2, 0]]
    X = m.host["node_X"]
    v0 = m.topology.node_vertex[np.argmin(np.hypot(X[:, 0], X[:, 1]))]
    q = np.union1d(q, np.flatnonzero((vA == v0) | (vB == v0)))
    break_interfaces(st, q)
    cg = CrackGas(m, None, viscosity=1e-4, min_aperture=1e-12, mouth_radius=0.0, material=emulsion(), p_max=1e15)
    for cells, p in p_cells(q):
        cg.set_fixed_pressure(cells, p)
    return m, st, cg, q


def _expected(cg) -> np.ndarray:
    """Σ over the pressurised cells of their stored face forces, at their nodes."""
    nodes = cg.cells.nodes.numpy()[: cg.Q]
    force = cg.gas.force.numpy()[: 4 * cg.Q].reshape(-1, 4, 2)
    loaded = cg.gas.pres.numpy()[: cg.Q] > 0
    out = np.zeros((cg.model.node_count, 2))
    np.add.at(out, nodes[loaded].ravel(), force[loaded].reshape(-1, 2))
    return out


def test_each_node_gets_the_sum_of_its_cells_loads_once():
    _, st, cg, q = _setup(lambda q: [(q, 5e6)])
    st.f.zero_()
    cg.apply(st, 0.0)
    cg.add_loads(st)
    want = _expected(cg)
    got = st.f.numpy()
    shared = np.bincount(cg.cells.nodes.numpy()[q].ravel())
    assert shared.max() == 2                          # nodes in two loaded cells: listed once, loaded by both
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    # a second step whose cells are loaded differently: the first step's loads are gone, the new ones are whole
    cg.set_fixed_pressure(q, -1.0)                    # back to the gas's own (empty: no load)
    cg.set_fixed_pressure(q[::2], 2e6)
    st.f.zero_()
    cg.apply(st, 0.0)
    cg.add_loads(st)
    want2 = _expected(cg)
    np.testing.assert_allclose(st.f.numpy(), want2, rtol=0, atol=1e-12 * np.abs(want2).max())
    assert np.abs(want2 - want).max() > 0.1 * np.abs(want).max()


def test_a_step_the_rock_did_not_take_up_leaves_nothing_behind():
    """apply twice, add once (as the channel-flow check does): only the last step's loads arrive."""
    _, st, cg, q = _setup(lambda q: [(q, 5e6)])
    cg.apply(st, 0.0)
    cg.set_fixed_pressure(q, -1.0)
    cg.set_fixed_pressure(q[:2], 3e6)
    cg.apply(st, 0.0)
    st.f.zero_()
    cg.add_loads(st)
    want = _expected(cg)
    got = st.f.numpy()
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    assert (np.abs(got).sum(axis=1) > 0).sum() <= 8          # two cells' nodes, nothing of the first step
