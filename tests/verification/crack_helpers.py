"""Meshes with a straight pre-cut crack along mesh edges, for the crack-gas verification cases."""

import numpy as np

from blastfrac.explosives.library import get_explosive
from blastfrac.geometry.mesh import TriMesh, _compact


def plate_with_crack(width: float, a: float, h_crack: float, h_far: float, x0: float | None = None,
                     x1: float | None = None) -> TriMesh:
    """A square plate [−W/2, W/2]² meshed by gmsh with the segment y = 0, x0 ≤ x ≤ x1 (default −a … a) embedded,
    so that mesh edges run along it; size h_crack [m] within a of the segment, growing to h_far [m]."""
    import gmsh

    x0 = -a if x0 is None else x0
    x1 = a if x1 is None else x1
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("crack")
        g = gmsh.model.geo
        w = width / 2
        pts = [g.addPoint(x, y, 0, h_far) for x, y in ((-w, -w), (w, -w), (w, w), (-w, w))]
        loop = g.addCurveLoop([g.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)])
        surf = g.addPlaneSurface([loop])
        c0, c1 = g.addPoint(x0, 0, 0, h_crack), g.addPoint(x1, 0, 0, h_crack)
        crack = g.addLine(c0, c1)
        g.synchronize()
        gmsh.model.mesh.embed(1, [crack], 2, surf)
        f = gmsh.model.mesh.field
        dist = f.add("Distance")
        f.setNumbers(dist, "CurvesList", [crack])
        f.setNumber(dist, "Sampling", 400)
        thr = f.add("Threshold")
        f.setNumber(thr, "InField", dist)
        f.setNumber(thr, "SizeMin", h_crack)
        f.setNumber(thr, "SizeMax", h_far)
        f.setNumber(thr, "DistMin", a)
        f.setNumber(thr, "DistMax", 6 * a)
        f.setAsBackgroundMesh(thr)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.option.setNumber("Mesh.RandomSeed", 1.0)
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        xy = coords.reshape(-1, 3)[:, :2]
        row = np.full(int(tags.max()) + 1, -1, np.int64)
        row[tags.astype(np.int64)] = np.arange(len(tags))
        _, en = gmsh.model.mesh.getElementsByType(2)
        tri = row[en.astype(np.int64)].reshape(-1, 3)
    finally:
        gmsh.finalize()
    return _compact(xy, tri, np.zeros((0, 2), np.int64), [])


def interfaces_on_segment(model, x0: float, x1: float, tol: float = 1e-9) -> np.ndarray:
    """Interfaces whose both vertices lie on y = 0 with x0 ≤ x ≤ x1, ordered by x."""
    X = model.host["node_X"]
    pn = model.topology.pair_nodes
    A, B = X[pn[0::2, 0]], X[pn[1::2, 0]]
    on = (np.abs(A[:, 1]) < tol) & (np.abs(B[:, 1]) < tol)
    on &= (np.minimum(A[:, 0], B[:, 0]) >= x0 - tol) & (np.maximum(A[:, 0], B[:, 0]) <= x1 + tol)
    q = np.flatnonzero(on)
    return q[np.argsort(0.5 * (A[q, 0] + B[q, 0]))]


def break_interfaces(state, q: np.ndarray) -> None:
    """Mark both springs of the interfaces q broken in tension."""
    mode = state.pair_mode.numpy().copy()
    mode[2 * q] = 1
    mode[2 * q + 1] = 1
    state.pair_mode.assign(mode)


def emulsion():
    """The paper's emulsion JWL set (the crack gas needs a products EOS even where its pressure is prescribed)."""
    return get_explosive("emulsion")
