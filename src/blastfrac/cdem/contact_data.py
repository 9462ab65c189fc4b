"""Block contact, the arrays its kernels read and write, grouped as Warp structs (cdem/contact.py): the mesh's
topology, the spatial hash, the per-node caches, the contact history and the scheme's parameters. A kernel takes
these five and the rock state's arrays, instead of some fifty positional arguments."""

from __future__ import annotations

import warp as wp


@wp.struct
class ContactMesh:
    """What the contact reads of the model (fixed for a run)."""

    slot_iface: wp.array(dtype=wp.int32)      # interface of element edge slot 3e+k, −1 on the mesh boundary
    slot_l0: wp.array(dtype=wp.float64)       # reference length of each element edge [m]
    node_vertex: wp.array(dtype=wp.int32)     # mesh vertex of each block node
    vertex_start: wp.array(dtype=wp.int32)    # CSR of the nodes at each vertex (vertex_nodes)
    vertex_nodes: wp.array(dtype=wp.int32)
    fan_index: wp.array(dtype=wp.int32)       # position of each node in its vertex's list
    node_mass: wp.array(dtype=wp.float64)     # [kg/m]
    node_pairs: wp.array(dtype=wp.vec2i)      # the (at most two) spring pairs of each node
    pair_i: wp.array(dtype=wp.int32)
    pair_j: wp.array(dtype=wp.int32)


@wp.struct
class ContactHash:
    """The spatial hash of edge sample points: wp.HashGrid (without the fan cache) or the cell grid of our own."""

    grid: wp.uint64                           # wp.HashGrid id
    points: wp.array(dtype=wp.vec3d)          # its points
    sample_slot: wp.array(dtype=wp.int32)     # edge slot of each sample point
    cell_inv: wp.float64                      # 1 / cell width [1/m]
    cell_dim: wp.int32
    cell_starts: wp.array(dtype=wp.int32)
    cell_ends: wp.array(dtype=wp.int32)
    sorted_xy: wp.array(dtype=wp.vec2d)       # the points, cell by cell [m]
    sorted_code: wp.array(dtype=wp.int32)     # slot + 1 on an exposed edge, −(slot + 1) otherwise


@wp.struct
class ContactCache:
    """Per-node caches that change only with the spring states, and the wake and quiet windows."""

    node_face: wp.array(dtype=wp.vec2d)       # (tributary length [m], 1 if open)
    node_flag: wp.array(dtype=wp.int32)       # 0 no exposed edge, 1 held, 2 open
    fan_excl: wp.array(dtype=wp.int64)        # fan_exclusions mask
    fan_cand: wp.array2d(dtype=wp.int32)      # fan candidates, 4·node + exposure bits
    fan_count: wp.array(dtype=wp.int32)       # −1: not cached, walk the fan
    elem_near: wp.array(dtype=wp.int32)       # step at which an open face last came near each element (contact_fan
                                              # .wake_block: + WAKE_FLAG if woken then already)
    query_after: wp.array(dtype=wp.int32)     # first step an open node searches the hash again
    new_nodes: wp.array(dtype=wp.int32)       # the nodes whose flag a refresh turned from 0 (merge_candidates)
    new_count: wp.array(dtype=wp.int32)       # [1]: how many


@wp.struct
class ContactMarks:
    """What marking a spring's change of state reads and writes (contact_fan.mark_pair): each spring's vertex and
    the state last seen, the vertices' stamps, each interface's two edge slots and the hash points on them."""

    pair_vertex: wp.array(dtype=wp.int32)     # the mesh vertex of each spring
    seen_mode: wp.array(dtype=wp.int32)       # pair_mode as last seen
    seen_dropped: wp.array(dtype=wp.int32)    # pair_dropped as last seen
    vertex_stamp: wp.array(dtype=wp.int32)    # step at which a vertex was last listed
    iface_slots: wp.array(dtype=wp.vec2i)     # the two element edges of each interface
    slot_samples: wp.array(dtype=wp.vec2i)    # (first, count) of each edge's hash points
    sample_pos: wp.array(dtype=wp.int32)      # where each hash point sits in the cell order
    sorted_code: wp.array(dtype=wp.int32)     # ± (slot + 1) of each hash point in cell order: + if exposed


@wp.struct
class ContactHistory:
    """Each node's contact: its edge, friction force, overlap allowance, overlap and stiffness; the losses."""

    slot: wp.array(dtype=wp.int32)            # contact edge slot, −1 none
    state: wp.array(dtype=wp.vec4d)           # (Fs [N/m] tangential force, d0 [m] overlap allowance, p [m] overlap
                                              # the penalty acts on, Kc [N/m per m] penalty stiffness in use): one
                                              # record, so that a node's history is one load (the pass is latency-bound)
    loss_acc: wp.array(dtype=wp.float64)      # LOSS_SLIP, LOSS_PENALTY [J/m]


@wp.struct
class ContactParams:
    """The scheme's scalars (BlockContact sets them at every pass)."""

    kn_area: wp.float64                       # interface stiffness per area [Pa/m]
    mu_f: wp.float64                          # tan φ_r [-]
    search_radius: wp.float64                 # hash query radius [m]
    max_depth: wp.float64                     # deepest overlap a new contact is looked for at, h_min/2 [m]
    touch_tol: wp.float64                     # [m]
    wake_dist: wp.float64                     # h_min [m]
    near_window: wp.int32                     # steps a woken block stays woken
    quiet_steps: wp.int32                     # steps an open node with nothing near skips the hash
    held_faces: wp.int32                      # 1: held broken faces search their fan


@wp.struct
class ContactRecords:
    """What the contact of the i-th listed node adds to the rock, kept per list item instead of added at once, so
    that the pass can run in parts on two threads and ``apply_contact_records`` adds it all in list order (the
    sums of one pass over the list, to the bit)."""

    nodes: wp.array(dtype=wp.vec3i)           # (node, edge start, edge end); node −1: no force
    force: wp.array(dtype=wp.vec2d)           # contact force on the node [N/m]
    xi: wp.array(dtype=wp.float64)            # where it acts on the edge [-] (reactions (1 − ξ, ξ))
    energy: wp.array(dtype=wp.vec2d)          # (penalty energy dropped, slip work) [J/m]
