"""Crack statistics around a borehole: crushed-zone and dense-cracking radii, radial crack count and lengths,
detached cracks.

Definitions (documented in docs/results.md). Positions are those of the reference configuration; an
interface is *cracked* when at least one of its two springs has broken, and r is the distance of a point
from the hole centre.

* **Crack network**: the graph whose nodes are the cracked interfaces, two of them being joined when they
  share a mesh vertex (the vertex of the shared-vertex mesh, before the blocks were split). Its connected
  components are the *crack sets*.
* **Borehole wall**: the mesh-boundary vertices at distance ≤ r_b·(1 + ``WALL_TOL``) from the centre (the
  vertices of the hole's polygon). Where there is none (a charge without a borehole, whose r_b is half the
  charge's width), the boundary vertices within r_b + w.
* **Ring width w**: the median length of the interfaces within 2 r_b of the centre (the mesh size at the wall).
* **Orientation classes**: an interface is *radial* when it makes less than 45° with the radius through its
  midpoint (a crack along it runs away from the hole), *circumferential* otherwise (a crack along it runs
  round the hole).
* **Crushed-zone radius r_c**: the outer radius of the run of consecutive rings [r_b + k·w, r_b + (k+1)·w),
  starting at the wall, in which at least half of the radial interfaces *and* at least half of the
  circumferential ones are cracked (r_c = r_b when the first ring fails; a ring without interfaces of a
  class ends the run). Crushed rock is broken in every direction: a ring in which only the radial
  interfaces are cracked is densely cracked by radial cracks, not crushed. (Until 2026-12-06 r_c thresholded
  all interfaces together at one half. Around a blasthole nearly every radial interface cracks and few
  circumferential ones do, so that fraction is the share of radial interfaces in the ring, about one half
  in a random mesh: the rule read the mesh's orientation statistics, which is why two meshes of one size gave
  values 17–51 % apart. That rule is kept as the dense-cracking radius r_k.)
* **Dense-cracking radius r_k** (``dense_cracking_radius``): the same run of rings with at least half of all
  interfaces cracked, whatever their orientation (r_k = r_b when the first ring is below one half): the zone
  where radial cracks lie about one element apart, inside which single cracks are not counted (N(R) below
  starts beyond it). It is noise-dominated (see r_c) and locates the start of the crack count only.
* **Damaged-zone radius r_d**: the radius at which the cracked fraction of the interfaces, averaged over a
  ring one borehole radius wide (midpoint radii in [x − r_b/2, x + r_b/2)), has fallen to half its value in
  the first ring [r_b, 2 r_b). The ring centre x steps by ``DAMAGE_STEP``·r_b from 1.5 r_b and the crossing is
  interpolated linearly. It measures the extent of the dense damage about the hole, all cracked interfaces
  counted, and unlike r_k it is well conditioned: r_k thresholds the fraction at one half in rings one mesh
  size wide, and the fraction sits near one half over the first two borehole radii, so two meshes of the same
  size gave r_k 17–51 % apart, r_d 1–9 % (examples/confined_blast/mesh_study.md, "The crushed zone").
  r_d = r_b when the first ring has no crack; when the fraction never falls to half within the mesh, r_d is
  the centre of the last ring that holds interfaces, a lower bound (``damaged_zone_radius_censored``).
* **Connected network** (of this hole): the crack sets that have a vertex on the wall, or, when r_k > r_b,
  a vertex at r ≤ r_k (the densely cracked zone touches the wall by construction). All other crack sets are
  **detached**: they are reported apart (number, total length, number of those of more than ``MIN_EXTENT``
  interfaces) and count in no N(R). A crack set joined only to *another* borehole is detached for this one.
* **Crack crossings of a circle** of radius R about the centre: the points where cracked interfaces of the
  connected network cross the circle, grouped by angle; two neighbouring crossings less than ``MERGE_GAP``·h
  apart along the circle belong to the same crack (a crack zig-zags along element edges and can cross a
  circle several times), h being the mesh size along that circle (median length of the interfaces it
  crosses). A group whose arc is at most ``NARROW_ARC``·h long is one *crack crossing*; wider groups are
  shattered or tangential (spalling) zones, not single cracks. The shattered arc (``shattered_arc``) is
  measured on all cracked interfaces, connected or not, since a detached fragmented zone is damage too.
* **N(R)**: the number of crack crossings of the circle R, sampled every w from r_k + 2w outward, for the
  connected network and for its tensile interfaces (an interface counts as tensile when a spring broke in
  tension). Crossings of neighbouring circles are linked into radial chains, and only crossings on chains at
  least ``MIN_EXTENT``·h long count (a crack is at least three elements long; this drops the ragged fringe
  of crushed and spalled zones). ``count_all`` is the same count over all cracked interfaces, detached sets
  included (for comparison only).
* **Radial crack count** N_rad = max over R of N(R): every radial crack crosses each circle between its
  start and its tip, so the circle crossed by most cracks counts all the cracks that coexist at one radius.
  Unlike a count of connected crack sets, this does not collapse a network whose cracks meet in the
  crushed zone into one crack.
* **Radial crack lengths**: the k-th longest crack reaches R_k = max{R : N(R) ≥ k}; its length is
  R_k − r_k (measured from the edge of the densely cracked zone), for k = 1 … N_rad.

Pre-existing joints (geometry.joints, docs/joints.md) are not blast cracks: their interfaces are never
*cracked* here, whether open from t = 0 or broken during the run, and they count in no ring of r_c or r_k
(:func:`blast_cracked`).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

#: crossings closer than this many ring widths along the circle belong to one crack [-]
MERGE_GAP = 1.0
#: a group of crossings longer than this many ring widths along the circle is not a single crack [-]
NARROW_ARC = 3.0
#: a chain of crossings shorter than this many local mesh sizes is the ragged edge of a zone, not a crack [-]
MIN_EXTENT = 3.0
#: relative tolerance on r_b for a boundary vertex to lie on the borehole wall [-]
WALL_TOL = 1e-6
#: step of the ring centre of the damaged-zone radius, in borehole radii [-]
DAMAGE_STEP = 0.1


def circle_crossings(a: np.ndarray, b: np.ndarray, center: np.ndarray, R: float) -> np.ndarray:
    """Polar angles [rad] at which the segments a→b [n,2] (m) cross the circle of radius R [m] about ``center``."""
    ra = np.linalg.norm(a - center, axis=1)
    rb = np.linalg.norm(b - center, axis=1)
    hit = ((ra - R) * (rb - R) <= 0.0) & (ra != rb)
    if not hit.any():
        return np.zeros(0)
    a, b, ra, rb = a[hit], b[hit], ra[hit], rb[hit]
    # the crossing point: solve |a + t(b − a) − c| = R for t in [0, 1]
    d, p = b - a, a - center
    qa = np.einsum("ij,ij->i", d, d)
    qb = 2.0 * np.einsum("ij,ij->i", p, d)
    qc = ra**2 - R**2
    disc = np.sqrt(np.maximum(qb**2 - 4 * qa * qc, 0.0))
    t1, t2 = (-qb - disc) / (2 * qa), (-qb + disc) / (2 * qa)
    t = np.where((t1 >= -1e-12) & (t1 <= 1 + 1e-12), t1, t2)
    q = p + np.clip(t, 0.0, 1.0)[:, None] * d
    return np.arctan2(q[:, 1], q[:, 0])


def group_crossings(theta: np.ndarray, R: float, w: float) -> list[tuple[float, float, int]]:
    """Groups of crossing angles on the circle R: (mid angle [rad], arc length [m], crossings) per group."""
    if len(theta) == 0:
        return []
    th = np.sort(np.mod(theta, 2 * np.pi))
    gaps = np.diff(np.concatenate([th, th[:1] + 2 * np.pi])) * R      # gap after each crossing, circular
    cut = np.flatnonzero(gaps > MERGE_GAP * w)
    if len(cut) == 0:                                                  # one group all round
        return [(0.0, 2 * np.pi * R, len(th))]
    groups = []
    start = (cut[-1] + 1) % len(th)                                    # a group starts after each large gap
    for c in cut:
        idx = np.arange(start, c + 1) if c >= start else np.concatenate([np.arange(start, len(th)), np.arange(c + 1)])
        t0, t1 = th[idx[0]], th[idx[-1]]
        span = (t1 - t0) % (2 * np.pi)
        groups.append((float(np.mod(t0 + 0.5 * span, 2 * np.pi)), float(span * R), len(idx)))
        start = (c + 1) % len(th)
    return groups


def local_mesh_size(ra: np.ndarray, rb: np.ndarray, length: np.ndarray, R: float) -> float:
    """Median length [m] of the interfaces that cross the circle R (the mesh size along that circle); ra, rb: the
    distances [m] of each interface's two ends from the centre, length: its length [m]."""
    hit = (ra - R) * (rb - R) <= 0.0
    return float(np.median(length[hit])) if hit.any() else 0.0


def crossing_profile(a, b, cracked, tensile, center, radii, connected=None) -> dict:
    """N(R) of the connected cracked interfaces a→b and of their tensile ones, and the shattered arc [m], per radius.

    ``cracked``, ``tensile``, ``connected``: masks over all interfaces (``connected`` None: all of them). N(R)
    (``count``, ``count_tensile``) counts the interfaces that are cracked and connected; ``count_all`` and
    ``shattered_arc`` use every cracked interface. The merge gap and the narrow-arc limit scale with the mesh
    size along each circle, so that a crack through coarse elements is not split into several. Narrow
    crossings are linked into radial chains (:func:`persistent_counts`); only chains at least
    ``MIN_EXTENT`` local mesh sizes long count, which drops the ragged fringe of shattered zones.
    """
    connected = np.ones(len(a), bool) if connected is None else connected
    masks = {"count": cracked & connected, "count_tensile": tensile & connected, "count_all": cracked}
    narrow = {k: [] for k in masks}
    shattered, sizes = [], []
    ra, rb, length = np.linalg.norm(a - center, axis=1), np.linalg.norm(b - center, axis=1), np.linalg.norm(b - a, axis=1)
    for R in radii:
        w = local_mesh_size(ra, rb, length, R)
        for k, m in masks.items():
            g = group_crossings(circle_crossings(a[m], b[m], center, R), R, w)
            narrow[k].append([t for t, arc, _ in g if arc <= NARROW_ARC * w])
            if k == "count_all":
                shattered.append(sum(arc for _, arc, _ in g if arc > NARROW_ARC * w))
        sizes.append(w)
    out = {"radius": [float(r) for r in radii]}
    out.update({k: persistent_counts(radii, narrow[k], sizes) for k in masks})
    out.update({"shattered_arc": [float(s) for s in shattered], "mesh_size": sizes})
    return out


def persistent_counts(radii, angles: list[list[float]], sizes: list[float]) -> list[int]:
    """Crack crossings per circle that belong to a radial chain at least ``MIN_EXTENT``·h long.

    A crossing on circle i+1 continues the nearest crossing of circle i within ``MERGE_GAP``·h along the
    circle (h: the local mesh size); a crossing with no predecessor starts a chain, and a branch (a second
    crossing continuing the same predecessor) starts a chain at its parent's start radius.
    """
    chain_of: list[np.ndarray] = []           # chain id of each crossing, per circle
    start, end = [], []                       # per chain: first and last radius
    for i, (R, th) in enumerate(zip(radii, angles)):
        th = np.asarray(th, float)
        ids = np.full(len(th), -1, int)
        if i > 0 and len(th) and len(angles[i - 1]):
            prev = np.asarray(angles[i - 1], float)
            tol = MERGE_GAP * max(sizes[i], sizes[i - 1]) / R
            d = np.abs((th[:, None] - prev[None, :] + np.pi) % (2 * np.pi) - np.pi)
            used = set()
            for j in np.argsort(d.min(axis=1)):
                k = int(np.argmin(d[j]))
                if d[j, k] > tol:
                    continue
                parent = int(chain_of[i - 1][k])
                if k in used:                             # a branch: a new chain from the parent's start
                    start.append(start[parent])
                    end.append(R)
                    ids[j] = len(start) - 1
                else:
                    used.add(k)
                    ids[j] = parent
                    end[parent] = R
        for j in np.flatnonzero(ids < 0):
            start.append(R)
            end.append(R)
            ids[j] = len(start) - 1
        chain_of.append(ids)
    extent = np.asarray(end) - np.asarray(start) if start else np.zeros(0)
    counts = []
    for i, ids in enumerate(chain_of):
        counts.append(int(np.sum(extent[ids] >= MIN_EXTENT * sizes[i])) if len(ids) else 0)
    return counts


def lengths_from_profile(radii: np.ndarray, counts: np.ndarray, r_k: float) -> list[float]:
    """Crack lengths R_k − r_k [m], longest first, with R_k = max{R : N(R) ≥ k}, k = 1 … max N (r_k: the
    dense-cracking radius, where the count starts)."""
    radii, counts = np.asarray(radii, float), np.asarray(counts, int)
    out = []
    for k in range(1, int(counts.max(initial=0)) + 1):
        out.append(float(radii[counts >= k].max() - r_k))
    return out


def interface_vertices(model) -> np.ndarray:
    """Mesh vertex ids of the two ends of each interface, shape [Q, 2] (node n is corner n % 3 of element n // 3)."""
    topo = model.topology
    pn = topo.pair_nodes
    return np.stack([topo.node_vertex[pn[0::2, 0]], topo.node_vertex[pn[1::2, 0]]], axis=1)


def vertex_components(ends: np.ndarray, cracked: np.ndarray, n_vertex: int) -> np.ndarray:
    """Component label of each mesh vertex in the graph whose edges are the cracked interfaces, shape [V].

    Two cracked interfaces share a label when a chain of cracked interfaces, each sharing a vertex with the
    next, joins them; the label of an interface is that of either of its ends ``ends`` [Q, 2].
    """
    e = ends[cracked]
    g = coo_matrix((np.ones(len(e), np.int8), (e[:, 0], e[:, 1])), shape=(n_vertex, n_vertex))
    return connected_components(g, directed=False)[1]


def wall_vertices(model, center: np.ndarray, r_b: float, w: float) -> np.ndarray:
    """Mesh vertex ids on the wall of the hole of radius ``r_b`` [m] about ``center`` [m].

    The wall is the mesh-boundary vertices at distance ≤ r_b·(1 + WALL_TOL); if there is none (a charge
    without a borehole), the boundary vertices within r_b + w, w [m] being the ring width.
    """
    topo = model.topology
    s = topo.boundary_slots                                   # slot 3e+k joins corners k and (k+1) % 3 of e
    nodes = np.concatenate([s, 3 * (s // 3) + (s % 3 + 1) % 3])
    d = np.linalg.norm(model.host["node_X"][nodes] - center, axis=1)
    on = d <= r_b * (1.0 + WALL_TOL)
    if not on.any():
        on = d <= r_b + w
    return np.unique(topo.node_vertex[nodes[on]])


def ring_width(L: np.ndarray, r: np.ndarray, r_b: float) -> float:
    """Median length [m] of the interfaces (lengths L, midpoint radii r) within 2 r_b of the centre."""
    near = r < 2.0 * r_b
    return float(np.median(L[near])) if near.any() else float(np.median(L))


def joint_interface_mask(model) -> np.ndarray | None:
    """The interfaces on pre-existing joints, mask [Q], or None for a model without joints."""
    jq = model.host.get("iface_joint")
    return None if jq is None or not np.any(jq >= 0) else jq >= 0


def blast_cracked(model, mode: np.ndarray) -> np.ndarray:
    """Interfaces with a broken spring that are not on a joint, mask [Q]."""
    cracked = (mode.reshape(-1, 2) > 0).any(axis=1)
    joint = joint_interface_mask(model)
    return cracked if joint is None else cracked & ~joint


def radial_interfaces(a: np.ndarray, b: np.ndarray, center: np.ndarray) -> np.ndarray:
    """Interfaces a→b [m] (rows) within 45° of the radius from ``center`` [m] through their midpoint, mask [Q]: the
    *radial* orientation class; the others are *circumferential* (see the module doc)."""
    mid = 0.5 * (a + b) - center
    t = b - a
    # |cos| of the angle to the radius > 1/√2, without roots: 2 (t·m)² > |t|²|m|²
    return 2.0 * np.einsum("ij,ij->i", t, mid) ** 2 > np.einsum("ij,ij->i", t, t) * np.einsum("ij,ij->i", mid, mid)


def dense_cracking_radius(r: np.ndarray, cracked: np.ndarray, r_b: float, w: float) -> float:
    """Dense-cracking radius r_k [m]: outer radius of the rings of width w [m] from the wall, each ≥ half cracked.

    ``r``: midpoint radius of each interface [m]; ``cracked``: mask over the interfaces.
    """
    r_k, k = r_b, 0
    while True:
        ring = (r >= r_b + k * w) & (r < r_b + (k + 1) * w)
        if ring.sum() == 0 or cracked[ring].mean() < 0.5:
            return r_k
        k += 1
        r_k = r_b + k * w


def crushed_zone_radius(r: np.ndarray, cracked: np.ndarray, radial: np.ndarray, r_b: float, w: float) -> float:
    """Crushed-zone radius r_c [m]: outer radius of the rings of width w [m] from the wall in each of which at least
    half of the radial interfaces and at least half of the circumferential ones are cracked (module doc).

    ``r``: midpoint radius of each interface [m]; ``cracked``, ``radial`` (:func:`radial_interfaces`): masks over the
    interfaces.
    """
    r_c, k = r_b, 0
    while True:
        ring = (r >= r_b + k * w) & (r < r_b + (k + 1) * w)
        for cls in (ring & radial, ring & ~radial):
            if cls.sum() == 0 or cracked[cls].mean() < 0.5:
                return r_c
        k += 1
        r_c = r_b + k * w


def damaged_zone_radius(r: np.ndarray, cracked: np.ndarray, r_b: float) -> tuple[float, bool]:
    """Damaged-zone radius r_d [m]: where the cracked fraction in rings r_b wide falls to half its first ring's.

    ``r``: midpoint radius of each interface [m]; ``cracked``: mask over the interfaces; r_b: borehole radius [m].
    Returns (r_d, censored): censored is True when the fraction does not fall to half within the mesh, r_d then
    being the centre of the last ring that holds interfaces (a lower bound).
    """
    order = np.argsort(r)
    r, c = r[order], np.cumsum(cracked[order].astype(np.int64))
    c = np.concatenate([[0], c])

    def fraction(x: float) -> float:                    # cracked fraction of the ring [x - r_b/2, x + r_b/2)
        lo, hi = np.searchsorted(r, [x - 0.5 * r_b, x + 0.5 * r_b])
        return (c[hi] - c[lo]) / (hi - lo) if hi > lo else np.nan

    x0 = 1.5 * r_b
    f0 = fraction(x0)
    if not f0 > 0.0:
        return r_b, False
    x_prev, f_prev = x0, f0
    for k in range(1, int(np.ceil((r[-1] - x0) / (DAMAGE_STEP * r_b))) + 1):
        x = x0 + k * DAMAGE_STEP * r_b
        f = fraction(x)
        if np.isnan(f):
            break
        if f < 0.5 * f0:
            return float(x_prev + (x - x_prev) * (f_prev - 0.5 * f0) / (f_prev - f)), False
        x_prev, f_prev = x, f
    return float(x_prev), True


def connected_network(model, cracked: np.ndarray, center: np.ndarray, r_b: float) -> dict:
    """The crack network of one hole: ring width w, r_c and r_k [m], per interface its set label and connected mask.

    Returns ``w``, ``r_c`` (crushed zone), ``r_k`` (dense cracking), ``label`` (crack-set label of each interface,
    meaningful where cracked), ``connected`` (cracked and in a set with a vertex on the wall, or at r ≤ r_k when
    r_k > r_b), ``wall`` (the wall's mesh vertex ids) and ``length`` (interface lengths [m]).
    """
    X = model.host["node_X"]
    pn = model.topology.pair_nodes
    a, b = X[pn[0::2, 0]], X[pn[1::2, 0]]
    L = np.linalg.norm(b - a, axis=1)
    r = np.linalg.norm(0.5 * (a + b) - center, axis=1)
    w = ring_width(L, r, r_b)
    joint = joint_interface_mask(model)
    keep = np.ones(len(r), bool) if joint is None else ~joint
    r_k = dense_cracking_radius(r[keep], cracked[keep], r_b, w)
    r_c = crushed_zone_radius(r[keep], cracked[keep], radial_interfaces(a, b, center)[keep], r_b, w)
    ends = interface_vertices(model)
    label = vertex_components(ends, cracked, len(model.mesh.vertices))[ends[:, 0]]
    wall = wall_vertices(model, center, r_b, w)
    seed = cracked & np.isin(ends, wall).any(axis=1)
    if r_k > r_b:
        r_end = np.minimum(np.linalg.norm(a - center, axis=1), np.linalg.norm(b - center, axis=1))
        seed |= cracked & (r_end <= r_k)
    connected = cracked & np.isin(label, label[seed])
    return {"w": w, "r_c": r_c, "r_k": r_k, "label": label, "connected": connected, "wall": wall, "length": L}


def detached_sets(label: np.ndarray, length: np.ndarray, detached: np.ndarray) -> dict:
    """Number of detached crack sets, their total length [m] and the number of sets of more than MIN_EXTENT interfaces.

    A set of n interfaces is longer than MIN_EXTENT times its mean interface length (its local mesh size)
    exactly when n > MIN_EXTENT.
    """
    _, n = np.unique(label[detached], return_counts=True)
    return {"detached_crack_sets": int(len(n)), "detached_crack_length": float(length[detached].sum()),
            "detached_crack_sets_long": int(np.sum(n > MIN_EXTENT))}


def detached_interface_mask(model, mode: np.ndarray, holes) -> np.ndarray:
    """Cracked interfaces connected to none of the holes ``holes`` [(center [m], r_b [m]), ...], mask [Q].

    ``crack_segments`` (io.paraview) lists the cracked interfaces in index order, so
    ``mask[cracked]`` is the matching per-segment mask.
    """
    cracked = blast_cracked(model, mode)
    attached = np.zeros_like(cracked)
    for c, r_b in holes:
        attached |= connected_network(model, cracked, np.asarray(c, float), float(r_b))["connected"]
    return cracked & ~attached


def crack_statistics(model, mode: np.ndarray, center: np.ndarray, r_b: float) -> dict:
    """Statistics of the cracks around the hole at ``center`` [m] of radius ``r_b`` [m] (SI units).

    N(R), the radial crack count and lengths count only the crack network connected to this hole's wall
    (or to its densely cracked zone, r ≤ r_k); the other crack sets are reported as detached (``detached_*``).
    With several boreholes this is called once per hole, and a crack set joined only to another hole is detached
    here.
    """
    X = model.host["node_X"]
    pn = model.topology.pair_nodes
    a, b = X[pn[0::2, 0]], X[pn[1::2, 0]]       # the two ends of each interface (side e1)
    pair_mode = mode.reshape(-1, 2)
    cracked = blast_cracked(model, mode)
    tensile = (pair_mode == 1).any(axis=1) & cracked
    net = connected_network(model, cracked, center, r_b)
    w, r_c, r_k, connected = net["w"], net["r_c"], net["r_k"], net["connected"]
    mid_r = np.linalg.norm(0.5 * (a + b) - center, axis=1)
    joint = joint_interface_mask(model)
    r_d, r_d_censored = damaged_zone_radius(mid_r, cracked, r_b) if joint is None else \
        damaged_zone_radius(mid_r[~joint], cracked[~joint], r_b)
    # crack crossings of circles outside the densely cracked zone
    r_max = float(np.linalg.norm(np.concatenate([a, b]) - center, axis=1).max())
    radii = np.arange(r_k + 2 * w, r_max, w)
    if len(radii) > 400:                     # keep the profile short on big meshes
        radii = np.linspace(radii[0], radii[-1], 400)
    prof = crossing_profile(a, b, cracked, tensile, center, radii, connected)
    counts = np.asarray(prof["count"], int)
    lengths = lengths_from_profile(radii, counts, r_k)
    n_rad = int(counts.max(initial=0))
    r_at = float(radii[int(np.argmax(counts))]) if len(radii) else r_k
    return {
        "center": [float(center[0]), float(center[1])],
        "borehole_radius": r_b,
        "ring_width": w,
        "crushed_zone_radius": r_c,
        "crushed_zone_radius_over_rb": r_c / r_b,
        "dense_cracking_radius": r_k,
        "dense_cracking_radius_over_rb": r_k / r_b,
        "damaged_zone_radius": r_d,
        "damaged_zone_radius_over_rb": r_d / r_b,
        "damaged_zone_radius_censored": r_d_censored,
        "radial_crack_count": n_rad,
        "radial_crack_count_radius": r_at,
        "radial_crack_count_tensile": int(max(prof["count_tensile"], default=0)),
        "radial_crack_lengths": lengths,
        "longest_radial_crack": max(lengths) if lengths else 0.0,
        "mean_radial_crack_length": float(np.mean(lengths)) if lengths else 0.0,
        "wall_vertices": int(len(net["wall"])),
        "cracked_interfaces": int(cracked.sum()),
        "connected_interfaces": int(connected.sum()),
        "connected_crack_length": float(net["length"][connected].sum()),
        **detached_sets(net["label"], net["length"], cracked & ~connected),
        **crack_extent(0.5 * (a + b), net["length"], cracked, center),
        "crossings": prof,
    }


#: fractions of the cracked length for which crack_extent reports the enclosing radius
EXTENT_FRACTIONS = (0.5, 0.8, 0.9)


def crack_extent(mid: np.ndarray, length: np.ndarray, cracked: np.ndarray, center: np.ndarray) -> dict:
    """Radii about ``center`` [m] within which 50, 80 and 90 % of the cracked length lies, all cracks counted.

    mid: interface midpoints [Q, 2] [m]; length: interface lengths [Q] [m]; cracked: mask [Q]. Unlike the reach
    of the connected radial cracks, this does not depend on whether nucleated segments have linked up, which a
    finer mesh changes (examples/confined_blast/README.md, mesh study); it measures how far the rock cracked.
    Returns crack_length_total [m] and crack_extent_r50 / _r80 / _r90 [m] (0 when nothing cracked).
    """
    L = length[cracked]
    out = {"crack_length_total": float(L.sum())}
    r = np.linalg.norm(mid[cracked] - center, axis=1)
    order = np.argsort(r)
    cum = np.cumsum(L[order]) / L.sum() if len(L) else np.zeros(0)
    for f in EXTENT_FRACTIONS:
        out[f"crack_extent_r{int(round(100 * f))}"] = float(r[order][np.searchsorted(cum, f * (1 - 1e-12))]) if len(L) else 0.0
    return out


def zone_radii(c: dict) -> dict:
    """r_c and r_k [m] (and over r_b) of a summary.json → cracks entry, also of one written before 2026-12-06: its
    ``crushed_zone_radius`` was the rule now called the dense-cracking radius r_k, and r_c was not computed (NaN)."""
    if "dense_cracking_radius" in c:
        keys = ("crushed_zone_radius", "crushed_zone_radius_over_rb", "dense_cracking_radius",
                "dense_cracking_radius_over_rb")
        return {k: c[k] for k in keys}
    nan = float("nan")
    return {"crushed_zone_radius": nan, "crushed_zone_radius_over_rb": nan,
            "dense_cracking_radius": c["crushed_zone_radius"],
            "dense_cracking_radius_over_rb": c["crushed_zone_radius_over_rb"]}
