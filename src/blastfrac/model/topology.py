"""CDEM topology: split a shared-vertex mesh into blocks that each own their nodes.

Numbering (implicit, no lookup tables needed):
- node ``3*e + k`` is local vertex ``k`` of element ``e``;
- element-local edge slot ``3*e + k`` joins local vertices ``k`` and ``(k+1) % 3``;
- interface ``q`` (an interior edge shared by elements e1, e2) owns the two node pairs
  ``2*q`` (pair A, at the edge's first vertex as seen from e1) and ``2*q + 1`` (pair B).

For a pair (i ∈ e1, j ∈ e2) the spring force acts on j as ``+f`` and on i as ``-f``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.mesh import TriMesh


@dataclass
class Topology:
    """Host-side connectivity of the block system (all int64 numpy arrays).

    node_vertex: original mesh vertex of each node, shape [N]
    iface_elems: (e1, e2) of each interface, shape [Q, 2]
    iface_slots: element-local edge slots (3*e1+k1, 3*e2+k2), shape [Q, 2]
    pair_nodes: (i, j) nodes of each pair, shape [P, 2] (P = 2Q)
    node_pairs: the (at most two) pairs of each node, -1 if none, shape [N, 2]
    node_pair_sign: +1 if the node is the j side of that pair, -1 if the i side, 0 if none, shape [N, 2]
    slot_iface: interface of each element edge slot, -1 for a boundary edge, shape [3E]
    boundary_slots: element edge slots on the mesh boundary, shape [B]
    boundary_slot_tags: side name of each boundary slot, length B
    iface_joint: joint set (index into geometry.joints) of each interface, −1 for rock, shape [Q]
    """

    node_vertex: np.ndarray
    iface_elems: np.ndarray
    iface_slots: np.ndarray
    pair_nodes: np.ndarray
    node_pairs: np.ndarray
    node_pair_sign: np.ndarray
    slot_iface: np.ndarray
    boundary_slots: np.ndarray
    boundary_slot_tags: list[str]
    iface_joint: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.iface_joint is None:
            self.iface_joint = np.full(len(self.iface_elems), -1, np.int64)


def build_topology(mesh: TriMesh) -> Topology:
    tri = mesh.triangles
    n_elem = len(tri)
    nv = len(mesh.vertices)
    a = tri.ravel()                                  # first vertex of slot 3e+k
    b = tri[:, [1, 2, 0]].ravel()                    # second vertex
    key = np.minimum(a, b) * nv + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    same = ks[1:] == ks[:-1]
    if np.any(same[1:] & same[:-1]):
        raise ValueError("non-manifold mesh: an edge is shared by more than two triangles")
    first = np.flatnonzero(same)
    s1, s2 = order[first], order[first + 1]
    # any consistent choice works: the lower slot index is e1
    swap = s1 > s2
    s1, s2 = np.where(swap, s2, s1), np.where(swap, s1, s2)
    o = np.argsort(s1, kind="stable")               # interfaces in element order: memory locality
    s1, s2 = s1[o], s2[o]
    e1, k1 = s1 // 3, s1 % 3
    e2, k2 = s2 // 3, s2 % 3
    if not np.all(a[s1] == b[s2]) or not np.all(b[s1] == a[s2]):
        raise ValueError("inconsistent triangle orientation")
    n_if = len(s1)
    # pair A at vertex a(s1): node (e1,k1) <-> node (e2,(k2+1)%3); pair B at b(s1): (e1,(k1+1)%3) <-> (e2,k2)
    pair_nodes = np.empty((2 * n_if, 2), np.int64)
    pair_nodes[0::2, 0] = 3 * e1 + k1
    pair_nodes[0::2, 1] = 3 * e2 + (k2 + 1) % 3
    pair_nodes[1::2, 0] = 3 * e1 + (k1 + 1) % 3
    pair_nodes[1::2, 1] = 3 * e2 + k2

    n_node = 3 * n_elem
    node_pairs = np.full((n_node, 2), -1, np.int64)
    node_pair_sign = np.zeros((n_node, 2), np.int64)
    _fill_node_pairs(pair_nodes, node_pairs, node_pair_sign)

    slot_iface = np.full(3 * n_elem, -1, np.int64)
    slot_iface[s1] = np.arange(n_if)
    slot_iface[s2] = np.arange(n_if)
    boundary_slots = np.flatnonzero(slot_iface < 0)
    tags = _tag_boundary_slots(mesh, a[boundary_slots], b[boundary_slots])
    iface_joint = _joint_interfaces(mesh, key[s1], nv)
    return Topology(
        node_vertex=a.copy(),
        iface_elems=np.stack([e1, e2], 1),
        iface_slots=np.stack([s1, s2], 1),
        pair_nodes=pair_nodes,
        node_pairs=node_pairs,
        node_pair_sign=node_pair_sign,
        slot_iface=slot_iface,
        boundary_slots=boundary_slots,
        boundary_slot_tags=tags,
        iface_joint=iface_joint,
    )


def _joint_interfaces(mesh: TriMesh, iface_key: np.ndarray, nv: int) -> np.ndarray:
    """Joint set of each interface (−1: rock), from the mesh's joint edges; every joint edge must be interior."""
    out = np.full(len(iface_key), -1, np.int64)
    je = mesh.joint_edges
    if not len(je):
        return out
    jkey = np.minimum(je[:, 0], je[:, 1]) * nv + np.maximum(je[:, 0], je[:, 1])
    order = np.argsort(iface_key)
    pos = np.searchsorted(iface_key[order], jkey)
    pos = np.minimum(pos, len(order) - 1)
    found = iface_key[order][pos] == jkey if len(order) else np.zeros(len(jkey), bool)
    if not np.all(found):
        raise ValueError(f"{int((~found).sum())} joint edges are not interior edges of the mesh (a joint on the boundary?)")
    out[order[pos]] = mesh.joint_sets
    return out


def _fill_node_pairs(pair_nodes, node_pairs, node_pair_sign) -> None:
    """Each node belongs to at most two pairs (one per interior edge of its element at that vertex)."""
    p_idx = np.concatenate([np.arange(len(pair_nodes))] * 2)
    nodes = np.concatenate([pair_nodes[:, 0], pair_nodes[:, 1]])
    signs = np.concatenate([-np.ones(len(pair_nodes), np.int64), np.ones(len(pair_nodes), np.int64)])
    order = np.argsort(nodes, kind="stable")
    nodes, p_idx, signs = nodes[order], p_idx[order], signs[order]
    starts = np.r_[0, np.flatnonzero(nodes[1:] != nodes[:-1]) + 1]
    rank = np.arange(len(nodes)) - np.repeat(starts, np.diff(np.r_[starts, len(nodes)]))
    if rank.size and rank.max() > 1:
        raise ValueError("a node belongs to more than two springs (corrupt topology)")
    node_pairs[nodes, rank] = p_idx
    node_pair_sign[nodes, rank] = signs


def _tag_boundary_slots(mesh: TriMesh, va: np.ndarray, vb: np.ndarray) -> list[str]:
    nv = len(mesh.vertices)
    tag_of = {}
    for (p, q), t in zip(mesh.boundary_edges, mesh.boundary_tags):
        tag_of[min(p, q) * nv + max(p, q)] = t
    keys = np.minimum(va, vb) * nv + np.maximum(va, vb)
    return [tag_of.get(int(k), "outer") for k in keys]
