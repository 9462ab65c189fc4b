"""Node-to-edge block contact (METHOD §1.5): frictionless collision and rebound, Coulomb sliding friction."""

import numpy as np
import pytest

from blastfrac.analysis.energy import rock_energies
from blastfrac.cdem.solver import CDEMSolver
from blastfrac.geometry.mesh import TriMesh
from blastfrac.model.builder import ModelBuilder
from blastfrac.model.model import CONTACT_DISSIPATED
from conftest import scenario

KN = 1e14          # interface stiffness per area [Pa/m]


def _rock(phi_r: float) -> dict:
    return {"unbreakable": False, "stiffness_mode": "per_area", "kn": KN, "ks": KN,
            "tensile_strength": 1e9, "cohesion": 1e9, "residual_friction_angle": phi_r}


def _depth(p: np.ndarray, poly: np.ndarray) -> float:
    """Penetration depth [m] of point p into the convex counter-clockwise polygon poly (0 outside)."""
    d = np.roll(poly, -1, axis=0) - poly
    nrm = np.stack([d[:, 1], -d[:, 0]], 1) / np.linalg.norm(d, axis=1)[:, None]
    g = np.einsum("ij,ij->i", p - poly, nrm)            # outward signed distance to each face line
    return float(-g.max()) if g.max() < 0 else 0.0


@pytest.mark.parametrize("offset", [0.2, 0.0], ids=["offset", "flush"])
def test_two_blocks_collide_and_rebound(offset):
    """Two 1 cm squares (2 triangles each) meet at ±2 m/s, μ = 0; 'flush' has collinear top and bottom faces."""
    a, gap = 0.01, 1e-5
    sq = np.array([[0, 0], [a, 0], [a, a], [0, a]], float)
    verts = np.vstack([sq, sq + [a + gap, offset * a]])
    tris = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    sc = scenario(rock=_rock(0.0),
                  geometry={"domain": {"type": "rectangle", "width": 1.0, "height": 1.0}, "mesh_size": a})
    m = ModelBuilder(sc, mesh=TriMesh(verts, tris)).finalize("cpu")
    st, solver = m.state(), CDEMSolver(m)
    solver.contact.active = True
    X = m.host["node_X"]
    left = X[:, 0] < a + gap / 2
    corner = [int(np.flatnonzero(m.topology.node_vertex == i)[0]) for i in range(8)]   # a node at each vertex
    v0 = np.where(left[:, None], [2.0, 0.0], [-2.0, 0.0])
    st.v.assign(v0)
    mass = m.host["node_mass"]
    p0 = (mass[:, None] * v0).sum(axis=0)
    e0 = rock_energies(m, st)["kinetic"]
    dt = 0.5 * m.stable_dt
    depth, in_contact = 0.0, 0
    for k in range(4000):
        solver.forces(st, dt, k * dt)
        solver.integrate(st, dt)
        c = st.x.numpy()[corner]
        depth = max(depth, *(_depth(c[i], c[4:]) for i in range(4)), *(_depth(c[i], c[:4]) for i in range(4, 8)))
        in_contact += bool(np.any(solver.contact.contact_slot.numpy() >= 0))
    v = st.v.numpy()
    p = (mass[:, None] * v).sum(axis=0)
    e = rock_energies(m, st)
    total = e["kinetic"] + e["strain"] + e["springs"]
    restitution = (v[~left, 0].mean() - v[left, 0].mean()) / 4.0
    # penalty estimate of the depth: v_rel·√(m_node/Kc), Kc = kn·a for a corner node (two half faces)
    scale = 4.0 * np.sqrt(mass.min() / (KN * a))
    print(f"contact ({offset}): {in_contact} steps in contact, max depth {depth * 1e6:.3f} µm "
          f"(penalty scale {scale * 1e6:.3f} µm), restitution {restitution:.3f}, KE {e['kinetic'] / e0:.3f} "
          f"of initial, total {total / e0:.3f}, friction loss {e['friction']:.1e} J/m")
    np.testing.assert_allclose(p, p0, atol=1e-12 * np.abs(mass[:, None] * v0).sum())   # momentum conserved
    assert 0 < in_contact < 200, "one short impact"
    assert v[left, 0].mean() < 0 < v[~left, 0].mean(), "the blocks rebound"
    assert restitution > 0.6, "μ = 0: near-elastic rebound (the rest goes into block vibration)"
    assert depth < 2.0 * scale, "no interpenetration beyond the contact penalty"
    assert total < 1.02 * e0, "contact creates no energy"
    # frictionless: little loss. Flush corners lie at each other's edge ends, both passes hold the same overlap,
    # and the pass whose node leaves its edge's range drops its penalty energy ½Kc·g² (about 15 % here).
    assert total > (0.9 if offset else 0.8) * e0, "frictionless contact dissipates little"
    assert st.energy_acc.numpy()[CONTACT_DISSIPATED] == 0.0


def test_block_slides_with_coulomb_friction():
    """A 1 cm square slides at v0 on a fixed base under a body load g_b; φ_r = 30°.

    Coulomb: N = M·g_b, so the block decelerates at μ·g_b (μ = tan φ_r), stops after
    s = v0²/(2μ·g_b) and then sticks; the slip dissipates ½M·v0².
    """
    a, phi, v0, gb = 0.01, 30.0, 0.5, 3000.0
    mu = np.tan(np.radians(phi))
    base = np.array([[-1.5 * a, -0.5 * a], [2.5 * a, -0.5 * a], [2.5 * a, 0], [-1.5 * a, 0]])
    top = np.array([[0, 0], [a, 0], [a, a], [0, a]], float)
    mesh = TriMesh(np.vstack([base, top]), np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]),
                   boundary_edges=np.array([[0, 1]]), boundary_tags=["bottom"])
    sc = scenario(rock=_rock(phi), boundaries={"bottom": {"type": "fixed"}},
                  geometry={"domain": {"type": "rectangle", "width": 1.0, "height": 1.0}, "mesh_size": a})
    m = ModelBuilder(sc, mesh=mesh).finalize("cpu")
    st, solver = m.state(), CDEMSolver(m)
    solver.contact.active = True
    X, mass = m.host["node_X"], m.host["node_mass"]
    blk = np.arange(len(X)) >= 6                           # nodes of the sliding block
    M = mass[blk].sum()
    f_body = np.zeros_like(X)
    f_body[blk, 1] = -mass[blk] * gb
    v = np.zeros_like(X)
    v[blk, 0] = v0
    st.v.assign(v)
    dt = 0.5 * m.stable_dt
    t_stop = v0 / (mu * gb)
    n = int(1.3 * t_stop / dt)
    t = (np.arange(n) + 0.5) * dt                           # times of the half-step velocities
    vx = np.empty(n)
    for k in range(n):
        solver.forces(st, dt, k * dt)
        st.f.assign(st.f.numpy() + f_body)
        solver.integrate(st, dt)
        vx[k] = mass[blk] @ st.v.numpy()[blk, 0] / M
    w = (t > 0.1 * t_stop) & (t < 0.9 * t_stop)
    decel = -np.polyfit(t[w], vx[w], 1)[0]
    slide = st.x.numpy()[blk, 0].mean() - X[blk, 0].mean()
    loss = st.energy_acc.numpy()[CONTACT_DISSIPATED]
    print(f"friction: deceleration {decel:.1f} m/s² (μ·g_b = {mu * gb:.1f}), slide {slide * 1e6:.2f} µm "
          f"(v0²/2μg_b = {v0**2 / (2 * mu * gb) * 1e6:.2f}), slip loss {loss:.4e} J/m (½Mv0² = {0.5 * M * v0**2:.4e}), "
          f"final v {vx[-1]:.1e} m/s, {n} steps")
    assert decel == pytest.approx(mu * gb, rel=0.01)
    assert slide == pytest.approx(v0**2 / (2 * mu * gb), rel=0.01)
    assert loss == pytest.approx(0.5 * M * v0**2, rel=0.01)
    assert np.abs(vx[t > 1.1 * t_stop]).max() < 0.02 * v0, "static friction holds the block once it stops"
