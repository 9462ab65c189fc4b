"""Pre-existing joints (geometry.joints, docs/joints.md): validation, DFN statistics and reproducibility, meshes whose
edges follow the joints, joint properties per spring, and joints kept apart from blast cracks in the outputs."""

import math

import numpy as np
import pytest

from blastfrac.geometry.joints import Shape, joint_network, joint_traces, mean_length
from blastfrac.geometry.mesh import generate_mesh
from blastfrac.model.builder import ModelBuilder
from blastfrac.scenario import ScenarioError, scenario_from_dict
from blastfrac.scenario.load import resolved_dict
from blastfrac.scenario.schema import GeometryConfig

QUIET = {"simulation": {"progress": False}, "output": {"paraview": False, "figures": False}}
SQUARE = {"type": "rectangle", "width": 0.2, "height": 0.2}
HOLE = [{"center": [0.05, 0.05], "radius": 0.01}]


def _scenario(joints, domain=SQUARE, boreholes=(), h=0.02, **extra):
    return scenario_from_dict({**QUIET, **extra, "geometry": {"domain": domain, "boreholes": list(boreholes),
                                                              "mesh_size": h, "joints": joints}})


def _error(joints, **kw) -> str:
    with pytest.raises(ScenarioError) as e:
        _scenario(joints, **kw)
    return str(e.value)


# ----------------------------------------------------------------------------- validation
@pytest.mark.parametrize("joints, kw, key, words", [
    ([{"segments": [[[0.0, 0.0], [0.0, 0.0]]]}], {}, "geometry.joints[0].segments[0]", "zero length"),
    ([{"segments": [[[0.0, 0.0], [0.05, 0.0]], [[0.3, 0.3], [0.5, 0.4]]]}], {}, "geometry.joints[0].segments[1]",
     "outside the domain"),
    ([{"segments": [[[-0.1, -0.1], [0.1, -0.1]]]}], {}, "geometry.joints[0].segments[0]", "along the domain boundary"),
    ([{"segments": [[[-0.1, 0.05], [0.1, 0.05]]]}], {"boreholes": HOLE}, "geometry.joints[0].segments[0]",
     "passes through borehole geometry.boreholes[0]"),
    ([{"segments": [[[-0.1, 0.07], [0.1, 0.07]]], "borehole_clearance": 0.015}], {"boreholes": HOLE},
     "geometry.joints[0].segments[0]", "closer than borehole_clearance"),
    ([{"segments": [[[0, 0], [0.1, 0]]], "dfn": {"angle": 0, "spacing": 0.05}}], {}, "geometry.joints[0].segments",
     "exactly one of segments"),
    ([{}], {}, "geometry.joints[0].segments", "exactly one of segments"),
    ([{"segments": []}], {}, "geometry.joints[0].segments", "empty list"),
    ([{"dfn": {"angle": 0, "spacing": 0.05, "density": 10, "length": {"mean": 0.05}}}], {},
     "geometry.joints[0].dfn.spacing", "exactly one of spacing"),
    ([{"dfn": {"angle": 0, "density": 10}}], {}, "geometry.joints[0].dfn.density", "needs a trace-length"),
    ([{"dfn": {"angle": 200, "spacing": 0.05}}], {}, "geometry.joints[0].dfn.angle", "less than or equal to 180"),
    ([{"dfn": {"angle": 0, "angle_spread": 95, "spacing": 0.05}}], {}, "geometry.joints[0].dfn.angle_spread", "90"),
    ([{"dfn": {"angle": 0, "spacing": -1}}], {}, "geometry.joints[0].dfn.spacing", "greater than 0"),
    ([{"dfn": {"angle": 0, "spacing": 0.01}}], {}, "geometry.joints[0].dfn.spacing", "below min_gap"),
    ([{"dfn": {"angle": 0, "spacing": 0.05, "length": {"distribution": "uniform", "min": 0.1}}}], {},
     "geometry.joints[0].dfn.length.max", "needs min, max"),
    ([{"dfn": {"angle": 0, "spacing": 0.05, "length": {"distribution": "fixed", "mean": 0.1, "std": 0.1}}}], {},
     "geometry.joints[0].dfn.length.std", "not a parameter"),
    ([{"dfn": {"angle": 0, "spacing": 0.05, "length": {"distribution": "power_law", "min": 0.05, "max": 0.2,
                                                        "exponent": 0.5}}}], {},
     "geometry.joints[0].dfn.length.exponent", "greater than 1"),
    ([{"dfn": {"angle": 0, "spacing": 0.05, "region": {"type": "rectangle", "width": 0.1, "height": 0.1,
                                                       "center": [1.0, 1.0]}}}], {},
     "geometry.joints[0].dfn.region", "does not overlap"),
    ([{"dfn": {"angle": 0, "density": 5000, "length": {"mean": 0.1}}}], {}, "geometry.joints[0].dfn",
     "placed only"),
    ([{"segments": [[[0, 0], [0.1, 0]]], "mesh_size": 0.05}], {}, "geometry.joints[0].mesh_size", "must not exceed"),
    ([{"segments": [[[0, 0], [0.1, 0]]], "friction_angle": 90}], {}, "geometry.joints[0].friction_angle", "90"),
    ([{"segments": [[[0, 0], [0.1, 0]]], "cohesion": -1}], {}, "geometry.joints[0].cohesion", "greater than or equal"),
    ([{"segments": [[[0, 0], [0.1, 0]]], "name": "a"}, {"segments": [[[0, 0.05], [0.1, 0.05]]], "name": "a"}], {},
     "geometry.joints[1].name", "already used"),
    ([{"segments": [[[-0.05, 0], [0.05, 0]]]}, {"segments": [[[0.0, 0], [0.08, 0]]]}], {},
     "geometry.joints[1].segments[0]", "overlaps joints[0].segments[0]"),
    ([{"segments": [[[-0.05, 0], [0.05, 0]], [[0.05, 0], [0.08, 0]]]}], {}, None, None),      # end to end: fine
])
def test_joint_options_are_validated_with_the_key_named(joints, kw, key, words):
    if key is None:
        _scenario(joints, **kw)
        return
    msg = _error(joints, **kw)
    assert key in msg and words in msg, msg


def test_the_example_in_docs_joints_md_is_valid_and_meshes():
    import tomllib
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "joints.md").read_text()
    block = text.split("```toml\n", 1)[1].split("```", 1)[0]
    sc = scenario_from_dict({**QUIET, **tomllib.loads(block)})
    mesh = generate_mesh(sc.geometry, sc.simulation.seed)
    assert set(np.unique(mesh.joint_sets)) == {0, 1}
    ts = joint_traces(sc.geometry, sc.simulation.seed)
    assert ts[1].asked == round(0.48 / (0.15 * mean_length(sc.geometry.joints[1].dfn.length)))


def test_joints_need_gmsh_meshing():
    with pytest.raises(ScenarioError, match=r"geometry.joints: .*mesh_file"):
        scenario_from_dict({**QUIET, "geometry": {"domain": SQUARE, "mesh_size": 0.02, "mesh_file": "m.msh",
                                                  "joints": [{"segments": [[[0, 0], [0.1, 0]]]}]}})


def test_resolved_scenario_lists_the_joints_with_their_defaults():
    sc = _scenario([{"segments": [[[-0.2, 0.0], [0.2, 0.0]]], "cohesion": 1e6},
                    {"dfn": {"angle": 30, "spacing": 0.05, "length": {"distribution": "exponential", "mean": 0.05}}}])
    j = resolved_dict(sc)["geometry"]["joints"]
    assert j[0]["cohesion"] == 1e6 and j[0]["tensile_strength"] == 0.0 and j[0]["friction_angle"] == 30.0
    assert j[0]["open"] is False and j[0]["segments"] == [[[-0.2, 0.0], [0.2, 0.0]]]
    assert j[1]["dfn"]["angle_spread"] == 0.0 and j[1]["dfn"]["min_angle"] == 20.0
    assert j[1]["dfn"]["length"]["distribution"] == "exponential"
    assert "joints" not in resolved_dict(_scenario([]))["geometry"] or resolved_dict(_scenario([]))["geometry"]["joints"] == []


# ----------------------------------------------------------------------------- DFN
def _dfn_geometry(dfn: dict, size: float = 2.0, **geom) -> GeometryConfig:
    return GeometryConfig.model_validate({"domain": {"type": "rectangle", "width": size, "height": size},
                                          "mesh_size": 0.01, "joints": [{"dfn": dfn}], **geom})


def test_dfn_is_reproducible_and_seeded():
    g = _dfn_geometry({"angle": 60, "angle_spread": 10, "spacing": 0.2,
                       "length": {"distribution": "lognormal", "mean": 0.15, "std": 0.08}}, size=1.0)
    a, b, c = joint_network(g, 3), joint_network(g, 3), joint_network(g, 4)
    assert np.array_equal(a.points, b.points) and np.array_equal(a.edges, b.edges)
    assert a.points.shape != c.points.shape or not np.array_equal(a.points, c.points)
    g2 = _dfn_geometry({"angle": 60, "angle_spread": 10, "spacing": 0.2, "seed": 3,
                        "length": {"distribution": "lognormal", "mean": 0.15, "std": 0.08}}, size=1.0)
    assert np.array_equal(joint_network(g2, 99).points, a.points)      # dfn.seed overrides simulation.seed


def test_dfn_count_orientation_and_length_statistics_match_the_asked_values():
    """N = A/(s·E[l]) traces (P21 = 1/s), orientations N(30°, 8°), truncated exponential lengths: mean angle,
    angle spread and mean length within 4 standard errors, P21 of the drawn traces within 4 standard errors."""
    s, spread = 0.2, 8.0
    length = {"distribution": "exponential", "mean": 0.1, "min": 0.03, "max": 0.4}
    g = _dfn_geometry({"angle": 30, "angle_spread": spread, "spacing": s, "length": length})
    ts = joint_traces(g, 0)[0]
    area = 4.0
    El = mean_length(g.joints[0].dfn.length)
    n = ts.asked
    assert n == round(area / (s * El)) == len(ts.angles) == len(ts.lengths)
    a = np.radians(ts.angles)
    mean = math.degrees(np.angle(np.exp(2j * a).mean()) / 2)
    assert abs(mean - 30.0) < 4 * spread / math.sqrt(n)
    assert ts.angles.std() == pytest.approx(spread, rel=4 / math.sqrt(2 * n))
    se_l = ts.lengths.std() / math.sqrt(n)
    assert abs(ts.lengths.mean() - El) < 4 * se_l
    assert ts.lengths.sum() / area == pytest.approx(1 / s, abs=4 * n * se_l / area)
    assert ts.remarked == 0                                       # marks drawn once: no redraw bias
    # the clipped traces: inside the domain, lengths never longer than drawn
    assert np.all(np.abs(ts.pieces) <= 1.0 + 1e-12)
    assert ts.total_length <= ts.lengths.sum() + 1e-12
    print(f"N {n}, mean angle {mean:.2f}°, spread {ts.angles.std():.2f}°, mean length {ts.lengths.mean():.4f} m "
          f"(asked {El:.4f}), P21 {ts.lengths.sum() / area:.3f} 1/m (1/s = {1 / s:.3f}), redrawn {ts.redrawn}")


def test_dfn_density_and_persistent_sets():
    g = _dfn_geometry({"angle": -45, "density": 20.0, "length": {"distribution": "fixed", "mean": 0.2}}, size=1.0)
    ts = joint_traces(g, 1)[0]
    assert ts.asked == 20 and len(ts.angles) == 20 and np.all(ts.angles == -45.0)
    # persistent, parallel: lines across the region s apart (a line that would meet the boundary within min_gap
    # of a corner is shifted by up to s/4)
    g = _dfn_geometry({"angle": 20, "spacing": 0.1}, size=1.0)
    ts = joint_traces(g, 0)[0]
    nrm = np.array([-math.sin(math.radians(20)), math.cos(math.radians(20))])
    off = np.sort(ts.pieces[:, 0] @ nrm)
    exact = np.isclose(np.diff(off), 0.1, rtol=0, atol=1e-12)
    assert exact.sum() >= len(exact) - 4 and np.all(np.abs(np.diff(off) - 0.1) <= 0.05 + 1e-12)
    proj = np.array([[x, y] for x in (-0.5, 0.5) for y in (-0.5, 0.5)]) @ nrm
    assert ts.asked == len(ts.pieces) in (int(np.ptp(proj) / 0.1), int(np.ptp(proj) / 0.1) + 1)
    # every line runs from boundary to boundary
    shape = Shape(g.domain)
    assert np.all(shape.boundary_distance(ts.pieces.reshape(-1, 2)) < 1e-9)


def test_dfn_network_keeps_its_gaps_angles_and_borehole_clearance():
    g = GeometryConfig.model_validate({
        "domain": {"type": "disc", "radius": 0.5}, "mesh_size": 0.02, "boreholes": [{"radius": 0.02}],
        "joints": [{"dfn": {"angle": 0, "angle_spread": 30, "density": 60, "min_angle": 25,
                            "length": {"distribution": "power_law", "min": 0.05, "max": 0.4, "exponent": 2.5}}},
                   {"dfn": {"angle": 80, "spacing": 0.15}, "borehole_clearance": 0.05}]})
    net = joint_network(g, 0)
    P = net.points
    gap = 0.02
    A, B = P[net.edges[:, 0]], P[net.edges[:, 1]]
    d = np.linalg.norm(B - A, axis=1)
    assert d.min() > 1e-6
    # clear of the hole by the clearance of each set (0.02 default = mesh size, 0.05 given)
    from blastfrac.geometry.joints import _point_seg_dist
    dist = _point_seg_dist(np.zeros((1, 2)), A, B)
    clear = np.where(net.edge_set == 0, 0.02, 0.05) + 0.02
    assert np.all(dist >= clear - 1e-9)
    # edges meeting at a point do so at min_angle or more; points of degree 1 are ends: on the boundary or gap away
    u = (B - A) / d[:, None]
    for k in range(len(P)):
        at = np.flatnonzero((net.edges[:, 0] == k) | (net.edges[:, 1] == k))
        for i in at:
            for j in at:
                if i < j:
                    c = abs(float(u[i] @ u[j]))
                    if c < 1 - 1e-9:                                    # not collinear pieces of one trace
                        assert math.degrees(math.acos(min(1.0, c))) >= 25 - 1e-6
    shape = Shape(g.domain)
    deg = np.bincount(net.edges.ravel(), minlength=len(P))
    ends = np.flatnonzero(deg == 1)
    db = shape.boundary_distance(P[ends])
    near_hole = np.linalg.norm(P[ends], axis=1) < 0.1
    assert np.all((db < 1e-9) | (db >= gap - 1e-9) | near_hole)


# ----------------------------------------------------------------------------- meshes follow the joints
def _covered(mesh, net, tol=1e-9):
    """Each network edge is the union of mesh joint edges along it (lengths add up) and every joint edge lies on one."""
    V = mesh.vertices
    ja, jb = V[mesh.joint_edges[:, 0]], V[mesh.joint_edges[:, 1]]
    used = np.zeros(len(ja), bool)
    from blastfrac.geometry.joints import _point_seg_dist
    for (a, b), s in zip(net.edges, net.edge_set):
        A, B = net.points[a], net.points[b]
        on = (_point_seg_dist(ja, A[None], B[None]) < tol) & (_point_seg_dist(jb, A[None], B[None]) < tol)
        assert np.all(mesh.joint_sets[on] == s)
        assert np.linalg.norm(jb[on] - ja[on], axis=1).sum() == pytest.approx(np.linalg.norm(B - A), rel=1e-9)
        used |= on
    assert used.all()


@pytest.mark.parametrize("domain", [SQUARE, {"type": "disc", "radius": 0.1},
                                    {"type": "polygon", "vertices": [[-0.1, -0.1], [0.1, -0.1], [0.12, 0.1], [-0.05, 0.08]]}])
def test_mesh_edges_follow_given_and_generated_joints(domain):
    """Crossing joints, a T-junction, joints ending on the boundary, at a corner and inside the rock, and a DFN:
    element edges run along every joint (the interfaces cover each joint piece exactly), and the topology
    marks them."""
    joints = [{"segments": [[[-0.3, 0.0], [0.3, 0.0]], [[-0.05, -0.3], [0.05, 0.3]], [[0.03, 0.0], [0.06, 0.05]]],
               "mesh_size": 0.01},
              {"dfn": {"angle": 70, "angle_spread": 10, "density": 150, "length": {"distribution": "fixed", "mean": 0.05}}}]
    if domain is SQUARE:
        joints[0]["segments"].append([[-0.1, -0.1], [-0.02, -0.05]])        # from a corner
    sc = _scenario(joints, domain=domain)
    mesh = generate_mesh(sc.geometry, sc.simulation.seed)
    net = joint_network(sc.geometry, sc.simulation.seed)
    assert len(mesh.joint_edges) > 0 and set(np.unique(mesh.joint_sets)) == {0, 1}
    _covered(mesh, net)
    b = ModelBuilder(sc, mesh)
    jq = b.topology.iface_joint
    assert (jq >= 0).sum() == len(mesh.joint_edges)
    # the joint edges are interfaces of two blocks on opposite sides of the joint; boundary tags are unchanged
    assert set(b.topology.boundary_slot_tags) == set(sc.geometry.domain.sides)
    again = generate_mesh(sc.geometry, sc.simulation.seed)
    assert np.array_equal(again.vertices, mesh.vertices) and np.array_equal(again.joint_edges, mesh.joint_edges)


def test_joint_mesh_size_refines_along_the_joint():
    sc = _scenario([{"segments": [[[-0.2, 0.0], [0.2, 0.0]]], "mesh_size": 0.005}], boreholes=HOLE, h=0.02)
    mesh = generate_mesh(sc.geometry, 0)
    L = np.linalg.norm(mesh.vertices[mesh.joint_edges[:, 0]] - mesh.vertices[mesh.joint_edges[:, 1]], axis=1)
    assert np.median(L) == pytest.approx(0.005, rel=0.3) and L.sum() == pytest.approx(0.2, rel=1e-9)


# ----------------------------------------------------------------------------- properties
def test_joint_springs_get_the_joint_properties_and_open_joints_start_broken():
    rock = {"stiffness_mode": "per_area", "kn": 1e13, "ks": 5e12, "friction_angle": 40.0,
            "residual_friction_angle": 35.0, "tensile_fracture_energy": 100.0}
    sc = _scenario([{"segments": [[[-0.2, 0.0], [0.2, 0.0]]], "tensile_strength": 1e6, "cohesion": 2e6,
                     "friction_angle": 25.0, "residual_friction_angle": 15.0, "kn": 1e11},
                    {"segments": [[[0.05, 0.01], [0.05, 0.2]]], "open": True, "friction_angle": 10.0}], rock=rock)
    b = ModelBuilder(sc)
    h, pj = b.host, b.host["pair_joint"]
    j0, j1, r = pj == 0, pj == 1, pj < 0
    assert j0.sum() > 0 and j1.sum() > 0
    assert np.all(h["pair_t0"][j0] == 1e6) and np.all(h["pair_c0"][j0] == 2e6)
    assert np.all(h["pair_kn_area"][j0] == 1e11) and np.allclose(h["pair_ks"][j0], 5e12 * h["pair_ac"][j0])
    assert np.all(h["pair_t0"][r] == sc.rock.tensile_strength) and np.all(h["pair_kn_area"][r] == 1e13)
    law = h["pair_law"]
    assert np.allclose(law[j0], [math.tan(math.radians(25)), math.tan(math.radians(15)), 0, 0])
    assert np.allclose(law[j1][:, :2], math.tan(math.radians(10)))
    assert np.allclose(law[r], [math.tan(math.radians(40)), math.tan(math.radians(35)), b.slope_t, b.slope_c])
    assert b.slope_t > 0
    m = b.finalize("cpu")
    assert m.per_pair_law == 1
    st = m.state()
    mode, tb = st.pair_mode.numpy(), st.pair_tbreak.numpy()
    assert np.all(mode[j1] == 1) and np.all(tb[j1] == 0.0) and np.all(mode[~j1] == 0) and np.all(tb[~j1] == -1.0)
    # without joints: no per-spring law, the scalars apply
    m0 = ModelBuilder(_scenario([])).finalize("cpu")
    assert m0.per_pair_law == 0 and "pair_law" not in m0.host and "pair_mode0" not in m0.host


def test_per_spring_law_is_bit_identical_to_the_scalar_law():
    """The same mesh run with a joint whose properties are the rock's (per-spring law) and without (scalars): the
    same states bit for bit after a blast that breaks springs."""
    from blastfrac.cdem.solver import CDEMSolver

    rock = {"tensile_strength": 2e6, "cohesion": 8e6, "friction_angle": 40.0, "residual_friction_angle": 30.0}
    bc = {"left": {"type": "pressure", "pulse": {"type": "triangle", "peak": 60e6, "rise_time": 2e-6, "duration": 8e-6}}}
    joint = {"segments": [[[0.0, -0.2], [0.0, 0.2]]], "tensile_strength": 2e6, "cohesion": 8e6, "friction_angle": 40.0,
             "residual_friction_angle": 30.0}
    sc_j = _scenario([joint], h=0.01, rock=rock, boundaries=bc)
    sc_0 = _scenario([], h=0.01, rock=rock, boundaries=bc)
    mesh = generate_mesh(sc_j.geometry, 0)
    bare = type(mesh)(mesh.vertices, mesh.triangles, mesh.boundary_edges, mesh.boundary_tags)
    out = []
    for sc, me in ((sc_j, mesh), (sc_0, bare)):
        m = ModelBuilder(sc, me).finalize("cpu")
        st, solver = m.state(), CDEMSolver(m)
        dt = 0.8 * m.stable_dt
        for k in range(400):
            solver.forces(st, dt, k * dt)
            solver.integrate(st, dt)
        out.append((m.per_pair_law, st.x.numpy().copy(), st.pair_F.numpy().copy(), st.pair_mode.numpy().copy()))
    assert out[0][0] == 1 and out[1][0] == 0
    assert (out[0][3] > 0).sum() > 0                       # springs broke
    for a, b in zip(out[0][1:], out[1][1:]):
        assert np.array_equal(a, b)


# ----------------------------------------------------------------------------- outputs
def test_joints_are_not_counted_as_blast_cracks(tmp_path):
    """An open joint (broken from t = 0) near a hole: not in the fracture degree (with the joint springs excluded),
    not cracked for crack_statistics, a `joint` cell field in ParaView, drawn apart in fracture_pattern.png."""
    import meshio

    from blastfrac.analysis.cracks import crack_statistics
    from blastfrac.analysis.fracture import FractureDegree, joint_spring_mask
    from blastfrac.io.paraview import ParaviewSeries, crack_joint_field, crack_segments, joint_segments
    from blastfrac.plot.figures import fracture_pattern
    from blastfrac.scenario.schema import AnnulusZone

    sc = _scenario([{"segments": [[[-0.2, -0.03], [0.2, -0.03]]], "open": True},
                    {"segments": [[[0.03, 0.0], [0.03, 0.2]]]}], boreholes=[{"radius": 0.01}], h=0.01)
    m = ModelBuilder(sc).finalize("cpu")
    st = m.state()
    mode = st.pair_mode.numpy()
    assert (mode > 0).sum() == 2 * (m.host["iface_joint"] == 0).sum()
    X = m.host["node_X"][m.topology.pair_nodes[:, 0]]
    zone = AnnulusZone(name="z", r_inner=0.01, r_outer=0.1)
    plain = FractureDegree(X, [zone])
    assert plain.sample(mode)["D"] > 0                                    # counted without the exclusion
    fd = FractureDegree(X, [zone], exclude=joint_spring_mask(m))
    assert fd.total == (m.host["pair_joint"] < 0).sum()
    assert fd.sample(mode) == {k: 0.0 for k in fd.sample(mode)} and fd.counts(mode)["tensile"] == 0
    # a blast crack beside it counts
    q = int(np.flatnonzero(m.host["iface_joint"] < 0)[0])
    mode2 = mode.copy()
    mode2[2 * q] = 1
    assert fd.sample(mode2)["D"] == pytest.approx(1 / fd.total)
    cs = crack_statistics(m, mode, np.zeros(2), 0.01)
    assert cs["cracked_interfaces"] == 0 and cs["crushed_zone_radius"] == 0.01
    # ParaView: the open joint is on the crack lines with joint = 1; triangles 0
    series = ParaviewSeries(tmp_path)
    series.write(m, st, 0.0)
    vtu = meshio.read(tmp_path / "rock_0000.vtu")
    joint_field = dict(zip([c.type for c in vtu.cells], vtu.cell_data["joint"]))
    assert np.all(joint_field["triangle"] == 0) and np.all(joint_field["line"] == 1)
    seg, cmode = crack_segments(m, mode2, st.pair_tbreak.numpy())
    jf = crack_joint_field(m, mode2)
    assert len(jf) == len(seg) and (jf == 0).sum() == 1 and (jf == 1).sum() == len(seg) - 1
    js = joint_segments(m)
    assert len(js) == (m.host["iface_joint"] >= 0).sum()
    fracture_pattern(tmp_path / "pattern.png", st.x.numpy(), seg, cmode, joints=js, circles=[((0, 0), 0.01)])
    assert (tmp_path / "pattern.png").stat().st_size > 10_000
    # a model without joints: no joint field, no joint segments
    m0 = ModelBuilder(_scenario([])).finalize("cpu")
    assert crack_joint_field(m0, m0.state().pair_mode.numpy()) is None and len(joint_segments(m0)) == 0
