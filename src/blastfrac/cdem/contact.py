"""Node-to-edge frictional penalty contact between blocks (METHOD §1.4–1.5).

**Targets and candidates.** Target edges are the *exposed* element edges of METHOD §1.4: mesh-boundary
edges and interfaces whose two springs have both broken (dropped or not). A node is a candidate if one of
its own element's edges at it is exposed (the others exit at once). Nodes on an *open* face (a boundary
edge, or an interface with a dropped pair) are matched to every exposed edge near them: those that end at
their own vertex through the other blocks of that vertex (its fan), the others through a spatial hash
(edges sampled at spacing ≤ ℓ_ref, see ``BlockContact``), so the cost is linear in the number of nodes.
Nodes whose broken faces are all still held by undropped springs, the bulk of a crushed zone, only test the
other blocks at their own vertex (the nodes of that vertex, a list of ~6, no hash): that is where their
broken springs can carry them into a block they are not paired with. An open face that comes within h_min of
such a block "wakes" it for ``near_window`` steps, and its held nodes search the hash too, so they cannot
enter the open block unseen either: an open node wakes the blocks whose edges not at its vertex are within
h_min of it (hash) and the blocks of its fan whose other two nodes are within h_min of its own element's
edges at the vertex (``held_search`` with ``wake``); an edge that merely ends at the node's vertex touches
it there and wakes nothing (it did before, which kept every open node of a cracked face searching the hash at
every step and its fan woken). Running over all nodes gives both passes (A→B and B→A).

**Geometry.** Node x against edge a→b of length L: ξ = (x − x_a)·t̂/L and g = (x − x_a)·n̂ [m],
with n̂ = (t_y, −t_x) the outward normal of a counter-clockwise element (TriMesh orients them so).

**Shared vertices.** The faces of a crack belong to neighbouring elements and meet at the original mesh
vertices, so a node lies at the end of the opposite face's edge. Such a node/edge pair is a genuine contact
unless the spring stage already carries it: ``fan_exclusions`` skips an edge ending at the node's own
vertex only when the node and the edge's node at that vertex are (a) one *undropped* pair apart (the broken
or intact spring between them is that contact), or (b) joined by a chain of *intact* pairs around the vertex
(same block: a degenerate corner contact). A chain through broken pairs does not exclude: broken springs
slide up to L0/2 and open up to L0 before they drop, and a node carried by them into a third block of the
fan must meet its edges. (Excluding *every* edge that ends at the node's vertex, as this module once did,
meant that crack faces never touched once their springs dropped, and fragments passed through each other;
excluding whole chains of undropped pairs left nodes 0.3·h deep in the crushed zone of a blast.)

**Which edge.**
1. Candidates: 0 ≤ ξ ≤ 1 and −h_min/2 < g < 0 (behind the edge), and the node's own element
   faces the front of the edge (one of its two edges at the node points in front by > 0.6°).
2. The contact edge is the candidate with the least penetration (largest g).
3. Inside test: the exposed edge nearest to the node (distance to the segment) must not have the
   node in front of it, else the node is outside that block. Edges that end at the node's own vertex
   touch it at their end whatever side it is on, so they take part only when the node is inside that
   element's corner (behind the edge and behind the other exposed edge of the element there); otherwise
   a block merely touching the node's vertex vetoed its contact with another block (0.16·h deep).
A node that has just crossed one face of a block is also behind its other faces within h_min/2
(2 mm behind the neighbouring face of a 1 cm block); taking the deepest of these gave forces of
Kc·2 mm on first touch. (1) stops a face that is collinear with one of the node's own faces
(flush blocks) from being taken for a round-off g < 0; (3) rejects a node outside a block near
an acute corner, which is behind one face while in front of the other.

**First contact (overlap allowance).** A contact may be *found* already overlapping: a node of a crack face
at the end of the opposite edge, a node crossing an edge within one step, a compressed crack face handed
over by the spring stage when its pair drops. A penalty on that whole overlap releases ½Kc·g² of energy
that was never stored (Kc ≈ 10¹² N/m per m: 0.5 J/m for 1 µm, on every such node) and throws the node
out: this is what blew fractured runs up. So the penalty acts on the overlap *beyond* an allowance d0 [m]
set when the contact is found: Fn = Kc·p, p = −g − d0 ≥ 0, d0 = −g at first detection (the force starts
from zero and grows while the node keeps approaching). d0 only decreases: when the node moves back out
(−g < d0) it follows, d0 = −g, so the node leaves at p = 0, and one that returns to the surface meets the
full penalty. The potential ½Kc·p² is zero whenever d0 changes, so this is never a source of energy. The
price is that an overlap present at detection is kept, not pushed out (at most the approach of one step
for an ordinary contact); the blast test checks that blocks do not end up inside each other.
When the contact moves to another edge (sliding across a vertex) the overlap p is carried over (scaled by
Kc_old/Kc_new if Kc grew) so the normal force is continuous; when Kc grows on the same edge (Δt fell) p is
scaled the same way.

**Release.** Leapfrog conserves ½v^{n−½}·M·v^{n+½} + ½Kc·p_n² exactly while a contact holds, and entry at
p = 0 is exact, but cutting the force at the first step with p < 0 gains ½Kc·p_prev·|p| (up to (ω_cΔt)²/4
of the normal impact energy: 11 % at ω_cΔt = 0.8). That step applies a pull Kc·q, q = ½p·p_prev/(p_prev − p)
(``release_overlap``), which takes the gain back to first order; a sliding contact's last friction impulse
is corrected by the same factor. With Kc ≤ KC_CAP·m_min/Δt² (ω_cΔt ≤ 0.71) the elastic rebound tests
close to 1 %.

**Forces** (per unit thickness). Normal Fn = Kc·p [N/m] with Kc = kn·A_node [Pa], kn [Pa/m] the interface
stiffness per area and A_node [m] half the reference length of the node's own exposed edges, capped at
KC_CAP·m_min/Δt² (m_min the smallest of the three node masses [kg/m]). Tangential Fs is incremental,
Fs ← Fs − Kc·(v_rel·t̂)·Δt, capped at μ·Fn with μ = tan φ_r; its history is kept per node and reset when
the contact edge changes. Reactions go to the edge's nodes with weights (1 − ξ, ξ), so linear momentum is
conserved to round-off. The slip work and the penalty energy that disappears (contact lost while p > 0,
carried overlap smaller, friction spring reset) go to energy_acc[CONTACT_DISSIPATED], so the energy budget
still closes; ``BlockContact.losses()`` keeps them apart and ``stored_energy()`` gives the energy held by
active contacts.

**Cost.** The hash holds sample points of every edge (rebuilt when a node has moved h_min/4 since the last build,
checked every 5 steps: a schedule kept on the device, so that the pass reads nothing back and a graph can hold it,
``apply``); an open node that found nothing
within h_min skips the next 10 searches (the same speed bound as the rebuild). Held broken faces, the bulk of a
crushed zone, would make every step cost what its cracking made (7,000 of 11,900 nodes walking their fan at the
end of the demo), so the pass works from caches that change only when a spring does (``BlockContact.fan_cache``):

- per node, its tributary length and open flag, its fan_exclusions mask and its fan candidates: the nodes at its
  vertex of other blocks, not excluded, with an exposed edge there (at most FAN_CACHE; more: walk the fan). They
  depend on spring states only; the spring kernel lists the springs it breaks or drops (kernels_spring.list_change),
  mark_listed_changes compares those with the states last seen (the first pass, and one after ``rescan_springs``,
  scans every spring: mark_pair_changes) and refresh_fan_cache rebuilds the caches of the nodes at both vertices of
  a changed spring's interface;
- select_contact_nodes lists the nodes the contact pass has anything to do for, from the caches: a held node
  without contact only if one of its candidates passes the corner sign test and one of that corner's exposed
  edges may pass consider_edge (edge_may_take, a conservative ξ and wedge test). At the demo's end ~200 of
  ~5,000 such nodes are listed. eval_block_contact runs over the list in node order and makes every decision
  again, so the result is that of one pass over all nodes, to the last bit on a CPU;
- the hash is a cell grid of our own with the cells and the point order of wp.HashGrid (the same points met in the
  same order), each cell's points stored together with the exposure of their edge (kept by mark_pair_changes):
  a query reads memory in sequence and loads no spring state;
- the pass reads only the state of its start and writes per node (history, quiet window), so that its order does
  not matter: a wake written in the pass keeps whether the block was woken before it (``contact_fan.wake_block``),
  and the woken test reads that (before 2026-12-06 a block re-woken earlier in a pass read as not woken for the
  nodes after: a wake could switch a block off for one step, and the result depended on the list order; the demo
  and the shipped P0 were the same to the bit either way). With two threads and a long
  list (CDEMSolver stage "contact": from 1,500 listed nodes) the pass runs in two halves, each node's force and
  energies kept in its record (``ContactRecords``), which ``apply_contact_records`` then adds in list order: the
  sums of one pass in one thread, to the bit (tests/unit/test_threads.py). In one part the pass adds them at once;
- the kernels take their arrays as six Warp structs (``contact_data``: mesh, hash, caches, history, parameters,
  records)
  and the rock state's arrays, and the launches are recorded once and replayed (``_warp.Launcher``): packing the
  ~50 arrays of a launch cost more than a pass over the nodes of a small mesh.

With ``fan_cache`` off every node is evaluated as before (wp.HashGrid, every held node walks its fan; ~15 %
slower than the code before the cache, a reference only). Demo end state (3,966 blocks, 39.5 % of the springs
broken, benchmarks/contact_cache.py, CPU): the rock step costs ×2.4 the intact one (×3.6–4.1 before the
cache); open nodes searching their own vertex through the fan and the hash rebuilt on displacement took
0.80 → 0.65 ms intact and 1.95 → 1.56 ms cracked. What is left is mostly the contact of ~1,300 held nodes in
contact (~0.3 ms) and the corner test of ~6,500 held ones in the listing pass (~0.25 ms). Before the cache, on
59k elements (CPU): ×1.35 per step on nearly intact rock,
×2.9 with 17 % of the springs broken (×1.4 with ``held_faces`` off, at the price of 0.3·h overlaps in the
crushed zone).

**Stable step** (METHOD §1.7). ModelBuilder adds 2·K_c to each node's row sums of a breakable model, one
contact of the stiffness this module applies: K_c = kn_area·A_node with A_node half of each of the node's two
element edges (``contact_stiffness_per_area``, ``node_tributary_length``; until 2026-12-06 it doubled the spring
rows, which on a graded mesh allowed for a contact several times stiffer than this one where the step is set).
``BlockContact.stable_dt()`` is the Gershgorin bound with every spring intact *and* every node in one such
contact; model.stable_dt is below it (checked in the tests), and the cap keeps contacts beyond that allowance
stable (a node that is the end of other nodes' contact edges, light nodes at slivers).
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from .._warp import Launcher
from ..model.builder import contact_stiffness_per_area, element_row_sums, node_tributary_length
from .contact_data import (
    ContactCache,
    ContactHash,
    ContactHistory,
    ContactMarks,
    ContactMesh,
    ContactParams,
    ContactRecords,
)
from .contact_fan import (
    append_vertices,
    list_candidates,
    mark_listed_changes,
    mark_pair_changes,
    merge_candidates,
    refresh_fan_cache,
    select_contact_nodes,
)
from .contact_geometry import FAN_CACHE, HIST_FS, HIST_KC, HIST_P, LOSS_PENALTY, LOSS_SLIP
from .contact_hash import (
    compute_edge_samples,
    compute_sample_cells,
    contact_tick,
    gather_sample_cells,
    largest_displacement,
    rebuild_decision,
)
from .contact_kernels import apply_contact_records, eval_block_contact, flag_any_dropped


class BlockContact:
    """Preallocated spatial hash and per-node contact history; ``apply`` runs once per step."""

    def __init__(self, model):
        self.model = model
        d = model.device
        n = model.node_count
        h = model.host
        lengths = model.mesh.edge_lengths()                       # [E, 3], slot 3e+k has length [e, k]
        self.l_max = float(lengths.max())
        self.h_min = float(np.min(2.0 * h["elem_area0"] / lengths.max(axis=1)))
        self.kn_area = contact_stiffness_per_area(h)
        self.mu_f = model.tan_phi_r
        # Hash points: every edge sampled at spacing ≤ ℓ_ref (its midpoint if shorter), so a query of radius
        # ½ℓ_ref·1.25 + h_min around a node finds every edge within h_min/2 of it with h_min/2 to spare, however
        # graded the mesh (midpoints alone would need a radius of ½·l_max, the *largest* edge, everywhere).
        # ℓ_ref = 2·h_min (at least an eighth of the median edge, so that one sliver cannot multiply the points):
        # the query radius then follows the smallest elements, where blasts crack. With ½ the median edge, as
        # before, a query near the confined example's borehole (1 mm edges, 8.6 mm median) visited ~300 points
        # (3 µs); at 2·h_min it visits a fifth as many, for twice the hash points (rebuilt rarely, see below).
        # The same points are found within reach, so the same contacts (bit-identical runs of both examples).
        L0 = lengths.ravel()
        self.l_ref = float(min(self.l_max, max(2.0 * self.h_min, 0.125 * float(np.median(L0)))))
        k = np.maximum(1, np.ceil(L0 / self.l_ref).astype(np.int64))
        slot = np.repeat(np.arange(len(L0)), k)
        first = np.repeat(np.cumsum(k) - k, k)
        frac = (np.arange(len(slot)) - first + 0.5) / np.repeat(k, k)
        self.sample_slot = wp.array(slot.astype(np.int32), dtype=wp.int32, device=d)
        self.slot_samples = wp.array(np.stack([np.cumsum(k) - k, k], 1).astype(np.int32), dtype=wp.vec2i, device=d)
        self.sample_frac = wp.array(frac, dtype=wp.float64, device=d)
        self.radius = 0.5 * 1.25 * self.l_ref + self.h_min       # 25 % allowance for edges that stretch
        # about one hash cell per point keeps the bucket occupancy constant as meshes grow
        dim = int(min(4096, max(16, math.sqrt(len(slot)))))
        self.grid = wp.HashGrid(dim, dim, 1, device=d, dtype=wp.float64)
        self.points = wp.zeros(len(slot), dtype=wp.vec3d, device=d)
        # The same hash as a cell grid of our own (with the fan cache): the cells wp.HashGrid would hold, each
        # cell's points stored together in its order, so that a query reads them in sequence and meets the same
        # points in the same order (the same results); their exposure is in sorted_code (no loads of the springs).
        # Built from a stable radix sort by cell, as wp.HashGrid builds its own.
        self.cell_dim = dim
        self._key_bits = max(1, int(dim * dim - 1).bit_length())     # cell keys are below 2**_key_bits
        self.cell_inv = 1.0 / self.radius                         # wp.HashGrid: cell width = query radius
        ns = len(slot)
        self._keys = wp.zeros(2 * ns, dtype=wp.int32, device=d)
        self._values = wp.zeros(2 * ns, dtype=wp.int32, device=d)
        self.sample_xy = wp.zeros(ns, dtype=wp.vec2d, device=d)
        self.sample_code = wp.zeros(ns, dtype=wp.int32, device=d)
        self.sorted_xy = wp.zeros(ns, dtype=wp.vec2d, device=d)
        self.sorted_code = wp.zeros(ns, dtype=wp.int32, device=d)
        self.sample_pos = wp.zeros(ns, dtype=wp.int32, device=d)
        self.cell_starts = wp.zeros(dim * dim, dtype=wp.int32, device=d)
        self.cell_ends = wp.zeros(dim * dim, dtype=wp.int32, device=d)
        self._grid_kind = -1                                      # which hash the last rebuild built (use_cache)
        self.slot_iface = wp.array(model.topology.slot_iface.astype(np.int32), dtype=wp.int32, device=d)
        self.slot_l0 = wp.array(lengths.ravel(), dtype=wp.float64, device=d)
        vertex = model.topology.node_vertex
        self.node_vertex = wp.array(vertex.astype(np.int32), dtype=wp.int32, device=d)
        # the nodes at each original mesh vertex (CSR): the blocks a node can meet at its own vertex
        order = np.argsort(vertex, kind="stable")
        start = np.searchsorted(vertex[order], np.arange(int(vertex.max()) + 2))
        self.vertex_start = wp.array(start.astype(np.int32), dtype=wp.int32, device=d)
        self.vertex_nodes = wp.array(order.astype(np.int32), dtype=wp.int32, device=d)
        fan = np.empty(n, np.int64)
        fan[order] = np.arange(n) - start[vertex[order]]            # position of each node in its vertex's list
        if fan.max() >= 63:
            raise ValueError(f"a mesh vertex is shared by {fan.max() + 1} triangles; block contact allows 63")
        self.fan_index = wp.array(fan.astype(np.int32), dtype=wp.int32, device=d)
        self.contact_slot = wp.full(n, -1, dtype=wp.int32, device=d)
        # per node (Fs [N/m], d0 [m] overlap allowance, p [m] overlap the penalty acts on, Kc [N/m per m]); HIST_*
        self.contact_state = wp.zeros(n, dtype=wp.vec4d, device=d)
        self.loss_acc = wp.zeros(2, dtype=wp.float64, device=d)       # LOSS_SLIP, LOSS_PENALTY [J/m]
        # on from the start: a node with no exposed edge costs one test, so an unbroken model pays little
        self.active = True
        # The hash is queried with a margin of h_min/2 beyond the depth limit: it finds every edge that can be a
        # contact while no hash point has moved more than h_min/2 since the hash was built. The speed bound of the
        # contact pass is h_min/(20·Δt) (2.5 km/s on the blast test's mesh, whose wall fragments fly at up to
        # 1 km/s), i.e. h_min/2 in rebuild_interval = 10 steps. Rather than rebuild every 10 steps, the largest
        # node displacement since the last build is checked every rebuild_check = 5 steps and the hash rebuilt
        # when it exceeds h_min/4 (within the next 5 steps it grows by at most h_min/4 more): a hash point (on an
        # edge between two nodes) moves no more than its nodes. Intact or slow rock then rebuilds rarely (the
        # rebuild, ~1 ms on the demo's mesh, was 0.1 ms of every step).
        self.rebuild_interval = 10
        self.rebuild_check = 5
        self.rebuild_skin = 0.25 * self.h_min                          # [m]
        self._built = False
        self._x_build = wp.zeros(n, dtype=wp.vec2d, device=d)         # node positions when the hash was built
        self._moved = wp.zeros(2, dtype=wp.float64, device=d)          # largest squared displacement since [m²]
        #                                                                 (of each half of the nodes)
        # the schedule on the device (contact_tick): step count and steps since the build (checked at the first
        # call), the two branch flags of wp.capture_if, the number of builds
        self._clock = wp.array([0, self.rebuild_check], dtype=wp.int32, device=d)
        self._check_due = wp.zeros(1, dtype=wp.int32, device=d)
        self._rebuild_due = wp.zeros(1, dtype=wp.int32, device=d)
        self._rebuilds = wp.zeros(1, dtype=wp.int32, device=d)
        # Blocks an open face has come within h_min of stay "woken" for near_window steps: their held-broken
        # nodes then search the hash too, so a node of theirs cannot enter the open block unseen (module doc).
        self.near_window = 2 * self.rebuild_interval
        self.elem_near = wp.full(model.element_count, -(1 << 30), dtype=wp.int32, device=d)
        # An open node that found no exposed edge within h_min (and no contact) skips the search for
        # rebuild_interval steps: under the speed bound above nothing can close h_min in that time. On intact
        # rock this leaves the mesh-boundary nodes one search per rebuild instead of one per step.
        self.query_after = wp.zeros(n, dtype=wp.int32, device=d)
        # Search the vertex fans of broken faces still held by their springs (the bulk of a crushed zone). Off,
        # a crushed zone costs ~2x less (17 % of springs broken: 7.5 instead of 15 ms/step on 59k elements,
        # 5.2 without contact)
        # but its blocks can slide up to ~0.3·h into their fan neighbours before their springs drop.
        self.held_faces = True
        # Fan cache (module doc, "Cost"): each node's fan_exclusions mask and its fan candidates (the nodes of the
        # other blocks at its vertex that it may meet: not excluded, an exposed edge at the vertex), rebuilt for
        # the nodes of a vertex only when a spring whose state they depend on changes (mark_pair_changes
        # compares the spring states with those of the last step). Off, every held node walks its fan every step;
        # the results are the same (tests/unit/test_contact_cache.py).
        self.fan_cache = True
        pn = model.topology.pair_nodes
        si = model.topology.slot_iface
        both = np.flatnonzero(si >= 0)                               # the two element edges of each interface
        iface_slots = both[np.argsort(si[both], kind="stable")].reshape(-1, 2)
        self.iface_slots = wp.array(iface_slots.astype(np.int32), dtype=wp.vec2i, device=d)
        self.pair_vertex = wp.array(vertex[pn[:, 0]].astype(np.int32), dtype=wp.int32, device=d)
        self.seen_mode = wp.full(len(pn), -1, dtype=wp.int32, device=d)
        self.seen_dropped = wp.full(len(pn), -1, dtype=wp.int32, device=d)
        self.vertex_stamp = wp.full(int(vertex.max()) + 1, -(1 << 30), dtype=wp.int32, device=d)
        self.node_face = wp.zeros(n, dtype=wp.vec2d, device=d)       # node_faces: (tributary length, open)
        self.node_flag = wp.zeros(n, dtype=wp.int32, device=d)       # 0 no exposed edge, 1 held, 2 open
        self.fan_excl = wp.zeros(n, dtype=wp.int64, device=d)
        self.fan_cand = wp.zeros((n, int(FAN_CACHE)), dtype=wp.int32, device=d)
        self.fan_count = wp.full(n, -1, dtype=wp.int32, device=d)     # −1: not cached, walk the fan
        self.vertex_count = int(vertex.max()) + 1
        # the vertices whose caches are stale; the second half of the springs lists its own (dirty_b), appended to
        # the first's: a vertex may then be listed by both halves, so the joined list holds up to twice the vertices
        self._dirty_vertices = wp.zeros(2 * self.vertex_count, dtype=wp.int32, device=d)
        self._dirty_b = wp.zeros(self.vertex_count, dtype=wp.int32, device=d)
        self._counts_b = wp.zeros(1, dtype=wp.int32, device=d)
        # CDEMSolver._in_halves, where the solver runs stages in two threads (it sets this): the scan of every
        # spring's change and the pass over the listed nodes then run in two halves
        self.in_halves = None
        # (changes, change_count): the springs whose state changed since the last pass, as the spring kernel lists
        # them (kernels_spring.list_change; CDEMSolver sets it). None: scan every spring each pass
        self.changes = None
        self._b_listed = False
        self._cache_fresh = False
        self._counts = wp.zeros(2, dtype=wp.int32, device=d)          # dirty vertices, listed nodes
        self._node_list = wp.zeros(n, dtype=wp.int32, device=d)       # the nodes of this step's contact pass
        # what each listed node's contact adds to the rock (contact_data.ContactRecords), added in list order after
        # the pass, which can then run in two parts (CDEMSolver._in_halves, stage "contact")
        self.rec_nodes = wp.zeros(n, dtype=wp.vec3i, device=d)
        self.rec_force = wp.zeros(n, dtype=wp.vec2d, device=d)
        self.rec_xi = wp.zeros(n, dtype=wp.float64, device=d)
        self.rec_energy = wp.zeros(n, dtype=wp.vec2d, device=d)
        self._parts = False                                           # this step's pass ran in parts
        self.passes_in_parts = 0                                      # how many passes have (a diagnostic)
        self._all_nodes = wp.array(np.arange(n, dtype=np.int32), dtype=wp.int32, device=d)   # without the cache
        self._counts_all = wp.array([0, n], dtype=wp.int32, device=d)
        self._cand_list = wp.zeros(n, dtype=wp.int32, device=d)       # list_candidates
        self._cand_count = wp.zeros(1, dtype=wp.int32, device=d)
        self.new_nodes = wp.zeros(n, dtype=wp.int32, device=d)        # flagged by this refresh for the first time
        self.new_count = wp.zeros(1, dtype=wp.int32, device=d)
        self._cpu = wp.get_device(d).is_cpu
        self._dropped_flag = wp.zeros(1, dtype=wp.int32, device=d)     # any_dropped on a GPU
        # on a CPU, NumPy views of the two count arrays the pass may run over (its length, read where it may split)
        self._host_counts = {id(a): a.numpy() for a in (self._counts, self._counts_all)} if self._cpu else {}
        self._launch = Launcher()                 # recorded launches (packing costs more than a small mesh's pass)
        self._structs()

    def _structs(self) -> None:
        """The kernels' arguments as Warp structs (contact_data): the same array objects as the attributes above."""
        m = self.model
        mesh = self.s_mesh = ContactMesh()
        for k in ("slot_iface", "slot_l0", "node_vertex", "vertex_start", "vertex_nodes", "fan_index"):
            setattr(mesh, k, getattr(self, k))
        mesh.node_mass, mesh.node_pairs, mesh.pair_i, mesh.pair_j = m.node_mass, m.node_pairs, m.pair_i, m.pair_j
        hsh = self.s_hash = ContactHash()
        hsh.grid, hsh.points, hsh.sample_slot = self.grid.id, self.points, self.sample_slot
        hsh.cell_inv, hsh.cell_dim = self.cell_inv, self.cell_dim
        hsh.cell_starts, hsh.cell_ends, hsh.sorted_xy, hsh.sorted_code = (self.cell_starts, self.cell_ends,
                                                                          self.sorted_xy, self.sorted_code)
        cache = self.s_cache = ContactCache()
        for k in ("node_face", "node_flag", "fan_excl", "fan_cand", "fan_count", "elem_near", "query_after",
                  "new_nodes", "new_count"):
            setattr(cache, k, getattr(self, k))
        marks = self.s_marks = ContactMarks()
        for k in ("pair_vertex", "seen_mode", "seen_dropped", "vertex_stamp", "iface_slots", "slot_samples",
                  "sample_pos", "sorted_code"):
            setattr(marks, k, getattr(self, k))
        hist = self.s_hist = ContactHistory()
        hist.slot, hist.state = self.contact_slot, self.contact_state
        hist.loss_acc = self.loss_acc
        rec = self.s_rec = ContactRecords()
        rec.nodes, rec.force, rec.xi, rec.energy = self.rec_nodes, self.rec_force, self.rec_xi, self.rec_energy
        self.s_prm = ContactParams()
        self._prm_values = None

    def _params_values(self) -> tuple:
        return (self.kn_area, self.mu_f, self.radius, self.h_min, int(self.near_window), int(self.rebuild_interval),
                int(bool(self.held_faces)))

    def _params(self) -> ContactParams:
        """The scheme's scalars as they are now (tests and benchmarks change held_faces and near_window); the
        struct's fields are set only when one has changed."""
        values = self._params_values()
        if values != self._prm_values:
            prm = self.s_prm
            prm.kn_area, prm.mu_f, prm.search_radius = self.kn_area, self.mu_f, self.radius
            prm.max_depth, prm.touch_tol, prm.wake_dist = 0.5 * self.h_min, 1e-9 * self.h_min, self.h_min
            prm.near_window, prm.quiet_steps, prm.held_faces = values[4], values[5], values[6]
            self._prm_values = values
        return self.s_prm

    def apply(self, state, dt: float, hand_over=None) -> None:
        """Add the contact forces of the current configuration to state.f; dt [s] drives the friction.
        ``hand_over``: called once the scans over the whole rock (which two threads may split) are done, before the
        cache refresh and the passes over this step's lists (CDEMSolver.forces_rest hands another stage group to the
        second thread there).

        Nothing is read back to the host, so the pass can be captured in a graph (CDEMSolver.step_captured): the
        schedule (step count, hash check and rebuild) lives on the device (``contact_tick``) and its branches run
        through ``wp.capture_if`` (which reads its flag on the host when not capturing: free on a CPU, a sync on a
        GPU); the launches over this step's lists run one thread per item on a GPU and one thread over the whole
        list on a CPU (``_lanes``), whatever its length."""
        if not self.active or self.kn_area == 0.0:
            return
        m = self.model
        use_cache = int(bool(self.fan_cache))
        # (a switch of fan_cache builds the other hash at once: only tests and benchmarks switch)
        force = int(not self._built or use_cache != self._grid_kind)
        self._launch(contact_tick, 1, [self._clock, self._check_due, self._rebuild_due, self._rebuilds, force,
                                       int(self.rebuild_check)])
        self._grid_kind = use_cache
        self._built = True
        wp.capture_if(self._check_due, on_true=self._check_moved, state=state)
        wp.capture_if(self._rebuild_due, on_true=self._rebuild, state=state)
        self._counts.zero_()
        if use_cache and m.spring_count:
            # caches of the vertices where a spring changed state since the last call (of every vertex at first):
            # the first pass scans every spring, the later ones the springs the spring kernel listed
            if self._cache_fresh and self.changes is not None:
                dim, stride = self._lanes(len(self.changes[0]))
                self._launch(mark_listed_changes, dim,
                             [stride, self.changes[0], self.changes[1], state.pair_mode, state.pair_dropped,
                              self._clock, self.s_marks, self._counts, self._dirty_vertices])
            else:
                self._halves("pair_changes", m.spring_count, self._mark_pair_changes, state)
                if self._b_listed:
                    self._launch(append_vertices, 1, [self._counts, self._dirty_vertices, self._counts_b,
                                                      self._dirty_b])
                    self._b_listed = False
            if self.changes is not None:
                self.changes[1].zero_()
        if hand_over is not None:
            hand_over()
        if use_cache:
            if not self._cache_fresh:
                self._refresh(state, 1)
            else:
                wp.capture_if(self._counts, on_true=self._refresh, state=state, refresh_all=0)
        self._cache_fresh = bool(use_cache)
        prm = self._params()
        node_list, counts, n = self._all_nodes, self._counts_all, m.node_count
        if use_cache:
            dim, stride = self._lanes(m.node_count)
            self._launch(select_contact_nodes, dim,
                         [self._cand_list, self._cand_count, stride, state.x, prm, self._clock, self.s_cache,
                          self.contact_slot, self._counts, self._node_list])
            node_list, counts = self._node_list, self._counts
        # the pass over the list, in two parts on two threads where the list is long (its length is read on a CPU
        # only, where that costs nothing), then its records added in list order
        listed = int(self._host_counts[id(counts)][1]) if self._cpu and self.in_halves is not None else 0
        self._parts = False
        self._halves("contact", listed, self._eval, state, node_list, counts, use_cache, prm, dt)
        if self._parts:
            self._launch(apply_contact_records, 1, [counts, self.s_rec, state.f, state.energy_acc, self.loss_acc, 1])
            self.passes_in_parts += 1

    def rescan_springs(self) -> None:
        """The spring states (pair_mode, pair_dropped) were changed outside the spring kernel, which lists the
        springs it breaks and drops (a test, a stage that edits them): the next pass scans every spring."""
        self._cache_fresh = False

    def _halves(self, stage: str, n: int, launch, *args) -> None:
        """``launch(*args, first=…, count=…, key=…)`` over items 0 … n − 1, in two halves on two threads where the
        solver gives ``in_halves`` (see CDEMSolver._in_halves), else in one launch."""
        if self.in_halves is None:
            launch(*args)
        else:
            self.in_halves(stage, n, launch, *args)

    def _mark_pair_changes(self, state, first: int = 0, count: int | None = None, key=None) -> None:
        """mark_pair_changes over springs first … first + count − 1; the second half (first > 0) lists into its own
        buffer, which append_vertices then joins to the first's."""
        n = self.model.spring_count
        count = n - first if count is None else count
        second = first > 0
        if second:
            self._counts_b.zero_()
        self._launch(mark_pair_changes, count,
                     [first, state.pair_mode, state.pair_dropped, self._clock, self.s_marks,
                      self._counts_b if second else self._counts, self._dirty_b if second else self._dirty_vertices],
                     key=key)
        self._b_listed = self._b_listed or second        # joined by append_vertices once both halves have run

    def _eval(self, state, node_list, counts, use_cache, prm, dt, first: int = 0, count: int | None = None,
              key=None) -> None:
        """eval_block_contact over the list; called by in_halves with first/count (stand-ins: the list's length is
        on the device), over its first half (first = 0) or its second."""
        part = 0 if count is None else (1 if first == 0 else 2)
        self._parts = self._parts or part != 0       # then apply_contact_records adds the parts' records
        dim, stride = self._lanes(self.model.node_count)
        self._launch(eval_block_contact, dim,
                     [node_list, counts, part, stride, use_cache, self.s_mesh, self.s_hash, self.s_cache, self.s_hist,
                      prm, state.pair_mode, state.pair_dropped, state.x, state.v, self._clock, float(dt), self.s_rec,
                      state.f, state.energy_acc], key=key)

    def _largest_displacement(self, state, first: int = 0, count: int | None = None, key=None) -> None:
        """largest_displacement over nodes first … first + count − 1, into _moved[0] (first half) or _moved[1]."""
        count = self.model.node_count - first if count is None else count
        self._launch(largest_displacement, 1 if self._cpu else count,
                     [first, count, int(self._cpu), int(first > 0), state.x, self._x_build, self._moved], key=key)

    def _lanes(self, n: int) -> tuple[int, int]:
        """(threads, stride) of a launch over a list of at most n items whose length is on the device: one thread
        per item on a GPU; on a CPU one thread that runs the list in order (each CPU thread copies the kernel's
        structs, ~100 ns, so n threads that mostly leave at once cost more than the pass)."""
        return (1, 1) if self._cpu else (n, n)

    def full_scan_due(self) -> bool:
        """True when this step's pass scans every spring's state (the first pass, or one after rescan_springs; the
        others read the springs the spring kernel listed): the one scan of the pass that two threads split."""
        return bool(self.fan_cache) and not (self._cache_fresh and self.changes is not None)

    def capturable(self) -> bool:
        """True when ``apply`` can be captured in a graph: the fan cache on (wp.HashGrid's build is not captured),
        its caches and the hash built (the first call builds them on the host)."""
        return bool(self.fan_cache) and self._cache_fresh and self._built and self._grid_kind == 1

    def graph_key(self) -> tuple:
        """What a captured contact pass holds fixed: a graph is captured again when it changes."""
        return (self.active, bool(self.fan_cache), self._params_values())

    # ------------------------------------------------------------------ the pass's branches (wp.capture_if)
    def _check_moved(self, state) -> None:
        """The displacement check: rebuild_due when a node has moved more than rebuild_skin since the build."""
        self._moved.zero_()
        # in one thread: the check streams two position arrays, and in two halves on two threads it took longer
        # (the shipped P0's end state: 0.66 against 0.84 ms a step, benchmarks/RESULTS.md, stop 28)
        self._largest_displacement(state)
        self._launch(rebuild_decision, 1, [self._moved, self.rebuild_skin ** 2, self._rebuild_due, self._rebuilds])

    def _rebuild(self, state) -> None:
        """The hash of the edges' sample points at the current positions (the cell grid, or wp.HashGrid without
        the fan cache)."""
        m = self.model
        ns = self.points.shape[0]
        if self.fan_cache:
            self._launch(compute_sample_cells, ns,
                         [state.x, self.sample_slot, self.sample_frac, self.slot_iface, state.pair_mode,
                          self.cell_inv, self.cell_dim, self.sample_xy, self.sample_code, self._keys, self._values])
            wp.utils.radix_sort_pairs(self._keys, self._values, ns, end_bit=self._key_bits)
            self.cell_starts.zero_()
            self.cell_ends.zero_()
            self._launch(gather_sample_cells, ns,
                         [self._keys, self._values, ns, self.sample_xy, self.sample_code, self.cell_starts,
                          self.cell_ends, self.sorted_xy, self.sorted_code, self.sample_pos])
        else:
            wp.launch(compute_edge_samples, dim=ns, inputs=[state.x, self.sample_slot, self.sample_frac],
                      outputs=[self.points], device=m.device)
            self.grid.build(self.points, self.radius)
        wp.copy(self._x_build, state.x)

    def _refresh(self, state, refresh_all: int) -> None:
        """Rebuild the fan caches of the listed vertices (of all with refresh_all), then the candidate list."""
        m = self.model
        dim, stride = self._lanes(self.vertex_count)
        self.new_count.zero_()
        self._launch(refresh_fan_cache, dim,
                     [refresh_all, self._counts, self._dirty_vertices, self.s_mesh, state.pair_mode,
                      state.pair_dropped, self.s_cache, self.vertex_count, stride])
        if self._cpu and not refresh_all:
            # the new candidates merged in node order, the list kept (flags never return to 0)
            self._launch(merge_candidates, 1, [self.s_cache, self._cand_count, self._cand_list])
        else:
            self._cand_count.zero_()
            self._launch(list_candidates, m.node_count, [self.node_flag, self._cand_count, self._cand_list])

    @property
    def rebuilds(self) -> int:
        """How many times the hash has been built."""
        return int(self._rebuilds.numpy()[0])

    # ------------------------------------------------------------------ diagnostics (host side, not per step)
    def stored_energy(self) -> float:
        """Energy held by the active contacts, Σ ½Kc·p² + ½Fs²/Kc [J/m] (not in rock_energies' terms)."""
        h = self.contact_state.numpy()
        kc = h[:, HIST_KC]
        on = (self.contact_slot.numpy() >= 0) & (kc > 0.0)
        p, fs = h[on, HIST_P], h[on, HIST_FS]
        return float(np.sum(0.5 * kc[on] * p * p + 0.5 * fs * fs / kc[on]))

    def losses(self) -> dict[str, float]:
        """Energy removed by block contact since the start [J/m]: Coulomb slip, dropped penalty energy."""
        a = self.loss_acc.numpy()
        return {"slip": float(a[LOSS_SLIP]), "penalty_dropped": float(a[LOSS_PENALTY])}

    def any_dropped(self, state) -> bool:
        """Whether a spring has dropped (the run switches block contact on at the first): on a CPU a look at the
        array itself; on a GPU a flag set on the device and read back, 4 bytes where the array is 4 per spring."""
        if self._cpu:
            return bool(np.any(state.pair_dropped.numpy()))
        self._dropped_flag.zero_()
        wp.launch(flag_any_dropped, dim=self.model.spring_count, inputs=[state.pair_dropped, self._dropped_flag],
                  device=self.model.device)
        return bool(self._dropped_flag.numpy()[0])

    def active_count(self) -> int:
        return int(np.count_nonzero(self.contact_slot.numpy() >= 0))

    def stable_dt(self) -> float:
        """Gershgorin bound 2/ω_max [s] with every node in one block contact of its largest Kc (METHOD §1.7):
        CST rows + 2·max(Kn, Ks) per intact spring + 2·Kc, Kc = kn·(half of each of its element's edges at it)."""
        m, h = self.model, self.model.host
        X = h["node_X"]
        row = element_row_sums(X, m.lam, m.mu).max(axis=1)
        pn = m.topology.pair_nodes
        k = 2.0 * np.maximum(h["pair_kn"], h["pair_ks"])
        np.add.at(row, pn[:, 0], k)
        np.add.at(row, pn[:, 1], k)
        row += 2.0 * self.kn_area * node_tributary_length(X)
        return 2.0 / math.sqrt(float(np.max(row / h["node_mass_dt"])))
