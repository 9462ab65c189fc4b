"""Triangle meshes of rock domains: gmsh generation and .msh import.

A :class:`TriMesh` is the shared-vertex mesh as a mesher produces it (vertices, CCW
triangles, tagged boundary edges). The CDEM builder later splits it into blocks that
each own their nodes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..scenario.schema import DiscDomain, GeometryConfig, PolygonDomain, RectangleDomain


@dataclass
class TriMesh:
    """Shared-vertex triangle mesh.

    vertices: coordinates [m], shape [V, 2]
    triangles: vertex indices, counter-clockwise, shape [E, 3]
    boundary_edges: vertex index pairs of boundary segments, shape [B, 2]
    boundary_tags: side name of each boundary edge ('left', 'outer', 'hole0', ...), length B
    joint_edges: vertex index pairs of the interior edges that lie on a joint (geometry.joints), shape [J, 2]
    joint_sets: the joint set (index into geometry.joints) of each joint edge, shape [J]
    """

    vertices: np.ndarray
    triangles: np.ndarray
    boundary_edges: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    boundary_tags: list[str] = field(default_factory=list)
    joint_edges: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    joint_sets: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(self.vertices[:, :2], dtype=np.float64)
        tri = np.ascontiguousarray(self.triangles, dtype=np.int64)
        area = signed_areas(self.vertices, tri)
        if np.any(area == 0):
            raise ValueError(f"mesh has {int(np.sum(area == 0))} degenerate triangles")
        flip = area < 0
        tri[flip] = tri[flip][:, [0, 2, 1]]
        self.triangles = tri
        self.boundary_edges = np.asarray(self.boundary_edges, dtype=np.int64).reshape(-1, 2)
        self.joint_edges = np.asarray(self.joint_edges, dtype=np.int64).reshape(-1, 2)
        self.joint_sets = np.asarray(self.joint_sets, dtype=np.int64).reshape(-1)
        if len(self.joint_sets) != len(self.joint_edges):
            raise ValueError("joint_sets must give one set per joint edge")

    @property
    def element_count(self) -> int:
        return len(self.triangles)

    def edge_lengths(self) -> np.ndarray:
        """Lengths of the three edges of every triangle [m], shape [E, 3] (edge k joins k and k+1)."""
        p = self.vertices[self.triangles]
        return np.linalg.norm(p[:, [1, 2, 0]] - p, axis=2)


def signed_areas(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    p = vertices[triangles]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def generate_mesh(geom: GeometryConfig, seed: int = 0) -> TriMesh:
    """Mesh ``geom`` with gmsh (deterministic for a given seed), or read ``geom.mesh_file``."""
    if geom.mesh_file is not None:
        return read_msh(geom.mesh_file)
    import gmsh

    initialised_here = not gmsh.isInitialized()
    if initialised_here:
        gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("blastfrac")
        try:
            return _mesh_with_gmsh(gmsh, geom, seed)
        except Exception as e:  # gmsh reports a geometry it cannot mesh as a bare Exception
            raise ValueError(f"geometry: gmsh could not mesh this geometry ({e})") from None
    finally:
        gmsh.model.remove()
        if initialised_here:
            gmsh.finalize()


def _mesh_with_gmsh(gmsh, geom: GeometryConfig, seed: int) -> TriMesh:
    g = gmsh.model.geo
    h = geom.mesh_size
    h_near = geom.mesh_size_near or h
    side_curves: dict[str, list[int]] = {}
    net = None
    if geom.joints:
        from .joints import joint_network

        net = joint_network(geom, seed)
    # joint points on the outer boundary (the boundary curves are split there) and their gmsh tags
    on_boundary = net.points[net.boundary_points] if net is not None else np.zeros((0, 2))
    size_at = _joint_point_sizes(geom, net) if net is not None else np.zeros(0)
    joint_tag: dict[int, int] = {}

    def polyline(points: list[tuple[float, float]], names: list[str]) -> int:
        tags = [g.addPoint(x, y, 0.0, h) for x, y in points]
        for k in (net.boundary_points if net is not None else ()):
            # a joint that ends at a corner of the domain shares the corner's point
            dv = np.linalg.norm(np.asarray(points, float) - net.points[k], axis=1)
            if dv.min() <= 1e-8 * max(float(np.ptp(np.asarray(points, float), axis=0).max()), 1e-300):
                joint_tag[int(k)] = tags[int(np.argmin(dv))]
        lines = []
        for i, name in enumerate(names):
            a, b = np.asarray(points[i], float), np.asarray(points[(i + 1) % len(points)], float)
            chain = [tags[i]]
            for k, t in _points_on_side(a, b, net, on_boundary):
                x, y = a + t * (b - a)
                joint_tag[k] = g.addPoint(x, y, 0.0, min(h, size_at[k]))
                chain.append(joint_tag[k])
            chain.append(tags[(i + 1) % len(tags)])
            for p0, p1 in zip(chain[:-1], chain[1:]):
                ln = g.addLine(p0, p1)
                side_curves.setdefault(name, []).append(ln)
                lines.append(ln)
        return g.addCurveLoop(lines)

    def circle(center: tuple[float, float], r: float, name: str, size: float, reverse: bool,
               joint_points: bool = False) -> int:
        c = g.addPoint(center[0], center[1], 0.0, size)
        angles = [(a, -1) for a in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi)]
        if joint_points and net is not None and len(net.boundary_points):
            for k in net.boundary_points:
                d = net.points[k] - np.asarray(center, float)
                a = math.atan2(d[1], d[0]) % (2 * math.pi)
                # a joint end at one of the four default points replaces it
                angles = [(b, kb) for b, kb in angles
                          if not (kb < 0 and min(abs(a - b), 2 * math.pi - abs(a - b)) <= 1e-8)]
                angles.append((a, int(k)))
            angles.sort()
        pts = []
        for a, k in angles:
            if k < 0:
                pts.append(g.addPoint(center[0] + r * math.cos(a), center[1] + r * math.sin(a), 0.0, size))
            else:
                x, y = net.points[k]
                joint_tag[k] = g.addPoint(x, y, 0.0, min(size, size_at[k]))
                pts.append(joint_tag[k])
        n = len(pts)
        arcs = [g.addCircleArc(pts[i], c, pts[(i + 1) % n]) for i in range(n)]
        side_curves.setdefault(name, []).extend(arcs)
        loop = [-a for a in reversed(arcs)] if reverse else arcs
        return g.addCurveLoop(loop)

    def cut_loop(pieces) -> int:
        """Curve loop of a rectangle whose sides are cut by boreholes (symmetry lines): ``pieces`` from
        :func:`cut_boundary`, lines (split at joint points like ``polyline``) and arcs of at most π/2."""
        pts: dict[tuple[float, float], int] = {}
        centres: dict[tuple[float, float], int] = {}

        def point(p, size):
            key = (float(p[0]), float(p[1]))
            if key not in pts:
                pts[key] = g.addPoint(key[0], key[1], 0.0, size)
            return pts[key]

        curves = []
        for pc in pieces:
            if pc[0] == "line":
                _, a, b, name = pc
                chain = [point(a, pc_size(a))]
                for k, t in _points_on_side(np.asarray(a), np.asarray(b), net, on_boundary):
                    x, y = np.asarray(a) + t * (np.asarray(b) - np.asarray(a))
                    joint_tag[k] = g.addPoint(x, y, 0.0, min(h, size_at[k]))
                    chain.append(joint_tag[k])
                chain.append(point(b, pc_size(b)))
                for p0, p1 in zip(chain[:-1], chain[1:]):
                    ln = g.addLine(p0, p1)
                    side_curves.setdefault(name, []).append(ln)
                    curves.append(ln)
            else:
                _, a, b, c, name, size = pc
                if c not in centres:
                    centres[c] = g.addPoint(c[0], c[1], 0.0, size)
                arc = g.addCircleArc(point(a, size), centres[c], point(b, size))
                side_curves.setdefault(name, []).append(arc)
                curves.append(arc)
        if net is not None and len(pts):
            # a joint that ends at a corner of the domain shares the corner's point (as in polyline)
            keys = np.array(list(pts), float)
            tol = 1e-8 * float(np.ptp(keys, axis=0).max())
            for k in net.boundary_points:
                dv = np.linalg.norm(keys - net.points[k], axis=1)
                if int(k) not in joint_tag and dv.min() <= tol:
                    joint_tag[int(k)] = pts[tuple(keys[int(np.argmin(dv))])]
        return g.addCurveLoop(curves)

    hole_size = [b.mesh_size or h_near for b in geom.boreholes]

    def pc_size(p) -> float:
        """Size at a point of a cut rectangle's sides: the hole's where a hole meets the side, else h."""
        for b, hs in zip(geom.boreholes, hole_size):
            if abs(math.dist(p, b.center) - b.radius) <= 1e-9 * b.radius:
                return hs
        return h

    d = geom.domain
    cut = [i for i in range(len(geom.boreholes)) if geom.symmetry and geom.cut_sides(i)]
    if isinstance(d, RectangleDomain) and cut:
        outer = cut_loop(cut_boundary(d, [(geom.boreholes[i].center, geom.boreholes[i].radius, f"hole{i}",
                                           hole_size[i]) for i in cut]))
    elif isinstance(d, RectangleDomain):
        cx, cy, w2, h2 = d.center[0], d.center[1], d.width / 2, d.height / 2
        outer = polyline([(cx - w2, cy - h2), (cx + w2, cy - h2), (cx + w2, cy + h2), (cx - w2, cy + h2)],
                         ["bottom", "right", "top", "left"])
    elif isinstance(d, DiscDomain):
        outer = circle(d.center, d.radius, "outer", h, reverse=False, joint_points=True)
    elif isinstance(d, PolygonDomain):
        outer = polyline(list(d.vertices), [f"side{i}" for i in range(len(d.vertices))])
    else:  # pragma: no cover - the schema admits no other type
        raise TypeError(type(d))

    holes = [circle(b.center, b.radius, f"hole{i}", b.mesh_size or h_near, reverse=True)
             for i, b in enumerate(geom.boreholes) if i not in cut]
    joint_lines: list[tuple[int, int]] = []             # (gmsh curve tag, joint set)
    if net is not None:
        for k in range(len(net.points)):
            if k not in joint_tag:
                x, y = net.points[k]
                joint_tag[k] = g.addPoint(x, y, 0.0, min(h, size_at[k]))
        for (a, b), js in zip(net.edges, net.edge_set):
            joint_lines.append((g.addLine(joint_tag[int(a)], joint_tag[int(b)]), int(js)))
    surf = g.addPlaneSurface([outer, *holes])
    g.synchronize()
    if joint_lines:
        gmsh.model.mesh.embed(1, [c for c, _ in joint_lines], 2, surf)

    fields = []
    if geom.boreholes and h_near < h:
        hole_curves = [c for i in range(len(geom.boreholes)) for c in side_curves[f"hole{i}"]]
        dist = gmsh.model.mesh.field.add("Distance")
        gmsh.model.mesh.field.setNumbers(dist, "CurvesList", hole_curves)
        gmsh.model.mesh.field.setNumber(dist, "Sampling", 200)
        thr = gmsh.model.mesh.field.add("Threshold")
        rmax = max(b.radius for b in geom.boreholes)
        gmsh.model.mesh.field.setNumber(thr, "InField", dist)
        gmsh.model.mesh.field.setNumber(thr, "SizeMin", h_near)
        gmsh.model.mesh.field.setNumber(thr, "SizeMax", h)
        gmsh.model.mesh.field.setNumber(thr, "DistMin", 0.0)
        gmsh.model.mesh.field.setNumber(thr, "DistMax", geom.refinement_distance or 10.0 * rmax)
        fields.append(thr)
    for hj in sorted({geom.joint_mesh_size(i) for i in range(len(geom.joints))}):
        # joints meshed finer than the rock: size hj on the joint, growing to h over JOINT_GRADING·h
        curves = [c for c, js in joint_lines if geom.joint_mesh_size(js) == hj]
        if hj >= h or not curves:
            continue
        dist = gmsh.model.mesh.field.add("Distance")
        gmsh.model.mesh.field.setNumbers(dist, "CurvesList", curves)
        gmsh.model.mesh.field.setNumber(dist, "Sampling", 200)
        thr = gmsh.model.mesh.field.add("Threshold")
        gmsh.model.mesh.field.setNumber(thr, "InField", dist)
        gmsh.model.mesh.field.setNumber(thr, "SizeMin", hj)
        gmsh.model.mesh.field.setNumber(thr, "SizeMax", h)
        gmsh.model.mesh.field.setNumber(thr, "DistMin", 0.0)
        gmsh.model.mesh.field.setNumber(thr, "DistMax", JOINT_GRADING * h)
        fields.append(thr)
    if fields:
        if len(fields) == 1:
            gmsh.model.mesh.field.setAsBackgroundMesh(fields[0])
        else:
            fmin = gmsh.model.mesh.field.add("Min")
            gmsh.model.mesh.field.setNumbers(fmin, "FieldsList", fields)
            gmsh.model.mesh.field.setAsBackgroundMesh(fmin)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm", 5 if geom.mesh_algorithm == "delaunay" else 6)
    gmsh.option.setNumber("Mesh.RandomSeed", 1.0 + seed)
    gmsh.option.setNumber("Mesh.RandomFactor", 1e-9)
    gmsh.model.mesh.generate(2)

    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    xy = coords.reshape(-1, 3)[:, :2]
    tag_to_row = np.full(int(node_tags.max()) + 1, -1, np.int64)
    tag_to_row[node_tags.astype(np.int64)] = np.arange(len(node_tags))
    _, elem_nodes = gmsh.model.mesh.getElementsByType(2)
    tri = tag_to_row[elem_nodes.astype(np.int64)].reshape(-1, 3)
    bedges, btags = [], []
    for name, curves in side_curves.items():
        for c in curves:
            types, _, enodes = gmsh.model.mesh.getElements(1, c)
            for t, en in zip(types, enodes):
                if t == 1:
                    e = tag_to_row[en.astype(np.int64)].reshape(-1, 2)
                    bedges.append(e)
                    btags.extend([name] * len(e))
    jedges, jsets = [], []
    for c, js in joint_lines:
        types, _, enodes = gmsh.model.mesh.getElements(1, c)
        for t, en in zip(types, enodes):
            if t == 1:
                e = tag_to_row[en.astype(np.int64)].reshape(-1, 2)
                jedges.append(e)
                jsets.append(np.full(len(e), js, np.int64))
    joints = (np.concatenate(jedges), np.concatenate(jsets)) if jedges else None
    return _compact(xy, tri, np.concatenate(bedges) if bedges else np.zeros((0, 2), np.int64), btags, joints)


#: a joint meshed finer than geometry.mesh_size grades to mesh_size over this many mesh_size from the joint
JOINT_GRADING = 4.0


def cut_boundary(d: RectangleDomain, holes) -> list[tuple]:
    """The boundary of a rectangle minus discs that cross its sides (holes cut by symmetry lines), counter-clockwise.

    ``holes``: (centre, radius, tag, mesh size) of each cutting disc; each must meet the rectangle's perimeter in one
    stretch (it crosses one side, or two sides about their corner). Returns pieces ``("line", a, b, side)`` along the
    sides and ``("arc", a, b, centre, tag, size)`` along the discs inside the rectangle, clockwise about their centre
    and split at the multiples of π/2 about it (as a whole hole's four arcs), each at most π/2.
    """
    (x0, y0), (x1, y1) = d.bbox
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    names = ["bottom", "right", "top", "left"]
    lengths = [x1 - x0, y1 - y0, x1 - x0, y1 - y0]
    start = [0.0, lengths[0], lengths[0] + lengths[1], lengths[0] + lengths[1] + lengths[2]]
    per = float(sum(lengths))

    def covered(p) -> bool:
        return any(math.dist(p, c) < r * (1 - 1e-12) for c, r, _, _ in holes)

    # each disc's entry and exit on the perimeter: (perimeter coordinate s from (x0, y0), point)
    spans = []
    for c, r, tag, size in holes:
        cross = []
        for k in range(4):
            a, b = np.asarray(corners[k], float), np.asarray(corners[(k + 1) % 4], float)
            dv, f = b - a, a - np.asarray(c, float)
            qa, qb, qc = dv @ dv, 2 * f @ dv, f @ f - r * r
            disc = qb * qb - 4 * qa * qc
            if disc <= 0:
                continue
            sq = math.sqrt(disc)
            for t, entering in (((-qb - sq) / (2 * qa), True), ((-qb + sq) / (2 * qa), False)):
                if 0.0 < t < 1.0:
                    # exact coordinates on the side: the side's fixed coordinate is kept as given
                    p = tuple(float(a[i] + t * dv[i]) if dv[i] else float(a[i]) for i in (0, 1))
                    cross.append((start[k] + t * lengths[k], p, entering))
        ins = [(sv, p) for sv, p, e in cross if e]
        outs = [(sv, p) for sv, p, e in cross if not e]
        if len(ins) != 1 or len(outs) != 1:
            raise ValueError(f"geometry: {tag} must cut the rectangle's boundary in one stretch (one side, or two "
                             "sides about their corner)")
        spans.append((ins[0], outs[0], c, r, tag, size))
    free = [k for k in range(4) if not covered(corners[k])]
    s0 = start[free[0]]                                   # walk from a corner no disc covers
    events = [((start[k] - s0) % per, "corner", k) for k in free[1:]]
    events += [((sp[0][0] - s0) % per, "hole", j) for j, sp in enumerate(spans)]
    events.sort(key=lambda ev: ev[0])
    events.append((per, "end", free[0]))

    def side_of(sa: float, sb: float) -> str:
        m = (s0 + 0.5 * (sa + sb)) % per
        return names[max(k for k in range(4) if start[k] <= m)]

    pieces: list[tuple] = []
    pos_s, pos = 0.0, corners[free[0]]
    for s_ev, kind, j in events:
        if kind == "hole":
            (_, p_in), (s_out, p_out), c, r, tag, size = spans[j]
            if s_ev - pos_s > 1e-12 * per:
                pieces.append(("line", pos, p_in, side_of(pos_s, s_ev)))
            pieces += _cw_arcs(p_in, p_out, c, r, tag, size)
            pos_s, pos = (s_out - s0) % per, p_out
        else:
            q = corners[j]
            if s_ev - pos_s > 1e-12 * per:
                pieces.append(("line", pos, q, side_of(pos_s, s_ev)))
            pos_s, pos = s_ev, q
    return pieces


def _cw_arcs(a, b, c, r: float, tag: str, size: float) -> list[tuple]:
    """Arcs from a to b clockwise about c, split at the multiples of π/2 strictly between them."""
    q = 0.5 * math.pi
    ta = math.atan2(a[1] - c[1], a[0] - c[0])
    sweep = (ta - math.atan2(b[1] - c[1], b[0] - c[0])) % (2 * math.pi)
    eps = 1e-9
    ks = [k for k in range(math.floor((ta - sweep) / q) - 1, math.ceil(ta / q) + 2)
          if ta - sweep + eps < k * q < ta - eps]
    mid = [(c[0] + r * math.cos(k * q), c[1] + r * math.sin(k * q)) for k in sorted(ks, reverse=True)]
    pts = [a, *mid, b]
    return [("arc", p, e, (float(c[0]), float(c[1])), tag, size) for p, e in zip(pts[:-1], pts[1:])]


def _joint_point_sizes(geom: GeometryConfig, net) -> np.ndarray:
    """Element size at each network point [m]: the smallest joint mesh size of the edges that meet there."""
    size = np.full(len(net.points), geom.mesh_size)
    for (a, b), js in zip(net.edges, net.edge_set):
        hj = geom.joint_mesh_size(int(js))
        size[a] = min(size[a], hj)
        size[b] = min(size[b], hj)
    return size


def _points_on_side(a: np.ndarray, b: np.ndarray, net, on_boundary: np.ndarray) -> list[tuple[int, float]]:
    """(network point index, parameter along a→b) of the joint points strictly inside the side a→b, in order."""
    if net is None or not len(on_boundary):
        return []
    d = b - a
    L = float(np.linalg.norm(d))
    tol = 1e-8 * L
    t = (on_boundary - a) @ d / (L * L)
    off = np.abs((on_boundary[:, 0] - a[0]) * d[1] - (on_boundary[:, 1] - a[1]) * d[0]) / L
    sel = np.flatnonzero((off <= tol) & (t * L > tol) & ((1 - t) * L > tol))
    sel = sel[np.argsort(t[sel])]
    return [(int(net.boundary_points[k]), float(t[k])) for k in sel]


def morton_order(points: np.ndarray, bits: int = 16) -> np.ndarray:
    """Permutation sorting points along a Z-order (Morton) curve, for memory locality of the kernels."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    q = ((points - lo) / np.maximum(hi - lo, 1e-300) * (2**bits - 1)).astype(np.uint64)
    code = np.zeros(len(points), np.uint64)
    for b in range(bits):
        for d in range(2):
            code |= ((q[:, d] >> np.uint64(b)) & np.uint64(1)) << np.uint64(2 * b + d)
    return np.argsort(code, kind="stable")


def _compact(xy: np.ndarray, tri: np.ndarray, bedges: np.ndarray, btags: list[str], joints=None) -> TriMesh:
    tri = tri[morton_order(xy[tri].mean(axis=1))]     # neighbouring blocks close in memory
    used = np.zeros(len(xy), bool)
    used[tri.ravel()] = True
    new = np.cumsum(used) - 1
    kw = {}
    if joints is not None:
        kw = {"joint_edges": new[joints[0]], "joint_sets": joints[1]}
    return TriMesh(xy[used], new[tri], new[bedges] if len(bedges) else bedges, btags, **kw)


def read_msh(path: str) -> TriMesh:
    """Read a gmsh .msh file: triangles, plus line elements tagged by their physical-group names.

    Boundary lines without a named physical group are tagged 'outer'.
    """
    import meshio

    import meshio.gmsh

    try:
        # the format's reader itself: meshio.read() prints and calls sys.exit(1) on a file it cannot read
        m = meshio.gmsh.read(str(path))
    except Exception as e:  # meshio raises several kinds (ReadError, KeyError, ValueError...) on a bad file
        raise ValueError(f"geometry.mesh_file: cannot read {path} as a gmsh .msh mesh ({type(e).__name__}: {e})") from None
    tri = np.concatenate([c.data for c in m.cells if c.type == "triangle"]) if any(
        c.type == "triangle" for c in m.cells) else None
    if tri is None:
        raise ValueError(f"geometry.mesh_file: {path} has no triangle cells")
    names = {int(v[0]): k for k, v in m.field_data.items() if len(v) > 1 and int(v[1]) == 1}
    phys = m.cell_data.get("gmsh:physical")
    bedges, btags = [], []
    for i, c in enumerate(m.cells):
        if c.type == "line":
            ids = phys[i] if phys is not None else np.zeros(len(c.data), int)
            bedges.append(c.data)
            btags.extend(names.get(int(t), "outer") for t in ids)
    be = np.concatenate(bedges) if bedges else np.zeros((0, 2), np.int64)
    return _compact(m.points[:, :2], tri, be, btags)
