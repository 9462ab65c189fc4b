"""GasRockCoupler: the particle–edge contact stage between the MPM explosive and the CDEM rock (METHOD §3).

Per step (``apply``): the forces on the gas particles are written to ``mpm.f_ext_p`` and their moments about
the particle centres to ``mpm.f_ext_moment`` (they enter the grid in the next P2G, at the contact points) and
the reactions are added to the rock node forces (and kept in ``f_react`` for the work bookkeeping). Candidate elements are those with an
exposed edge; their centroids are hashed (a cell grid in wp.HashGrid's cells and order, of our own so that a CUDA
graph replays its builds: kernels_contact.ListedHash) and each particle queries the hash, so the cost is linear in the
number of particles. The list is rebuilt every ``rebuild_interval`` steps; between rebuilds the
exposure of every listed edge is re-tested, and a newly cracked element joins at the next rebuild.

Nothing the kernels need is read back: the list's length and largest reach stay on the device (the kernels read
them). The listed elements are hashed in two size classes, each in its own hash, so that the few large blocks of a
coarse far mesh do not widen every particle's search; the split and the cell widths follow the list's reach in steps
of CELL_GROWTH (``note_reach``: from the reach the host last read, at the MPM box's renewal, where it reads the box
anyway), so they change a few times a run. So a step can be captured as a graph
(``captured = True``, set by Simulation while it captures): its launches then cover the list's capacity (the
threads beyond its length return), its hashes hold the whole capacity with the points past the list's length filed
after every cell (the points and the order a search meets them in are those of a hash of the listed points alone),
and the empty list's branch
is taken on the device (``wp.capture_if``). Outside a capture the launches cover the list as the host reads it (a
view on a CPU), so that a large rock with a short list costs what the list does.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from .._warp import Launcher
from ..mpm.grid import BOX_STEPS
from .particle_edge import CONTACT_HISTORY, MAX_PRESSURE_OFFSET_NP
from .kernels_contact import (ACC_ABSORBED, ACC_CONTACTS, ACC_HEAT_NEW, ACC_HEATED, ACC_SIZE, ACC_STORED, LARGE,
                              REACH_COUNT, REACH_MAX, REACH_SUM, SMALL, account_rock_work_and_clear,
                              accumulate_gas_contact_work, add_reactions_with_work, collect_exposed_elements, eval_particle_edge_contact,
                              gather_listed, hash_listed_points, heat_gas_from_contacts, listed_cell_ranges,
                              listed_element_keys, ListedHash)


#: ratio of one hash cell width to the next (GasRockCoupler.note_reach) [-]
CELL_GROWTH = 1.25
#: the small elements' hash holds those of reach up to this multiple of the list's mean (GasRockCoupler.note_reach) [-]
CELL_REACH = 1.5


def default_contact_stiffness(p_cj: float, factor: float = 20.0) -> float:
    """k_c = factor·P_CJ [Pa]: the overlap at pressure p is about 2p/k_c·r_p (r_p/10 at P_CJ for factor 20)."""
    return factor * p_cj


class GasRockCoupler:
    """Particle–edge contact between ``mpm`` (an MPMSolver) and the rock ``model``; buffers allocated once.

    kc: contact stiffness [Pa = N/m per m of overlap, per unit thickness]; zeta: dashpot damping ratio [-];
    mu: friction coefficient [-]; r_max: cap on the particle radius r_p = ½√V_p [m]; force_cap: κ of the
    pressure-based cap on the normal force (0: none), see :func:`particle_edge.normal_force_cap`;
    surface_forces: apply the force on the gas at the disk's surface (through a moment), not at its centre;
    pressure_preload: contact radius r_p + p·2r_p/k_c, so that a touching particle pushes with its pressure.
    Both are on by default and documented in :mod:`blastfrac.coupling.particle_edge`; switching them off
    gives the former scheme, whose wall load exceeds the gas pressure (tests/verification/test_coupling_wall_load.py).
    """

    def __init__(self, model, mpm, kc: float, zeta: float = 0.0, mu: float = 0.0, rebuild_interval: int = 5,
                 r_max: float | None = None, force_cap: float = 0.0, surface_forces: bool = True,
                 pressure_preload: bool = True, contact_heating: bool = False):
        self.model, self.mpm = model, mpm
        # the contacts' dissipation heats the gas (not with elastic bodies, whose contacts share the book)
        self.contact_heating = bool(contact_heating) and mpm.n_solid == 0
        self.surface_forces, self.pressure_preload = bool(surface_forces), bool(pressure_preload)
        self.force_cap = float(force_cap)
        self.kc, self.zeta, self.mu = float(kc), float(zeta), float(mu)
        self.rebuild_interval = int(rebuild_interval)
        d = model.device
        X = model.host["node_X"]
        cent = (X[0::3] + X[1::3] + X[2::3]) / 3.0
        reach = np.linalg.norm(X.reshape(-1, 3, 2) - cent[:, None, :], axis=2).max(axis=1)
        # 25 % allowance for block deformation and rotation between rebuilds
        self.elem_reach = wp.array(1.25 * reach, dtype=wp.float64, device=d)
        vol0 = mpm.vol0.numpy()
        self.r_max = float(r_max if r_max is not None else 0.5 * mpm.spec.h)
        self.r_p0 = 0.5 * math.sqrt(float(vol0.max())) if len(vol0) else 0.0
        E = model.element_count
        self.slot_iface = wp.array(model.topology.slot_iface.astype(np.int32), dtype=wp.int32, device=d)
        self.count = wp.zeros(1, dtype=wp.int32, device=d)
        self.reach = wp.zeros(3, dtype=wp.float64, device=d)     # the list's largest and summed reach, its length
        self.elems = wp.zeros(E, dtype=wp.int32, device=d)
        # the list by size class (kernels_contact SMALL, LARGE), each with its own hash: elements, points, counts
        self.cls_elems = wp.zeros(2 * E, dtype=wp.int32, device=d)      # class c from c·E on
        self.cls_points = wp.zeros(2 * E, dtype=wp.vec3d, device=d)
        self.cls_count = wp.zeros(2, dtype=wp.int32, device=d)
        self.acc = wp.zeros(ACC_SIZE, dtype=wp.float64, device=d)
        self.diss_p = wp.zeros(max(1, mpm.n), dtype=wp.float64, device=d)   # contacts' dissipation rate per point [W/m]
        self._launch = Launcher()                 # recorded launches of the per-step kernels (_warp.Launcher)
        self.f_react = wp.zeros(model.node_count, dtype=wp.vec2d, device=d)   # this step's reactions [N/m]
        self._dt_work = 0.0                     # step length of the forces whose second half of work is pending [s]
        self._w_react = 0.0                     # ½Δt of this step's reactions, whose first half add_reactions books [s]
        # (particle, element) contact histories, read from one pair and written to the other each step
        nh = max(1, mpm.n) * CONTACT_HISTORY
        self._hist = [(wp.full(nh, -1, dtype=wp.int32, device=d), wp.zeros(nh, dtype=wp.float64, device=d),
                       wp.zeros(nh, dtype=wp.float64, device=d)) for _ in range(2)]
        # the two classes' hashes (kernels_contact.ListedHash: wp.HashGrid's cells and order in arrays of our own,
        # which a graph replays; the sort's keys and values take twice the list's capacity)
        dim = int(min(1024, max(16, math.sqrt(E))))
        self.hash = ListedHash()
        self.hash.values = wp.zeros(2 * 2 * E, dtype=wp.int32, device=d)
        self.hash.starts = wp.zeros(2 * dim * dim, dtype=wp.int32, device=d)
        self.hash.ends = wp.zeros(2 * dim * dim, dtype=wp.int32, device=d)
        self.hash.cell_inv = wp.vec2d(0.0, 0.0)
        self.hash.dim = dim
        self.hash.stride = 2 * E
        self._keys = wp.zeros(2 * E, dtype=wp.int32, device=d)
        self._order = wp.zeros(2 * E, dtype=wp.int32, device=d)             # a class's list, sorted by element
        self._tmp_elems = wp.zeros(E, dtype=wp.int32, device=d)
        self._tmp_points = wp.zeros(E, dtype=wp.vec3d, device=d)
        # each class's part of them (views made once: the launches' records keep their arrays)
        self._hash_views = [(self.hash.values[c * 2 * E: (c + 1) * 2 * E],
                             self.hash.starts[c * dim * dim: (c + 1) * dim * dim],
                             self.hash.ends[c * dim * dim: (c + 1) * dim * dim]) for c in (SMALL, LARGE)]
        # search radius = the list's largest reach (device) + this margin [m]: contact radius r_max with its preload
        self.query_margin = (1.0 + MAX_PRESSURE_OFFSET_NP) * self.r_max
        self.cell_size = 0.0                    # the small hash's cell width [m] (note_reach; 0 until the first rebuild)
        self.cell_large = 0.0                   # the large hash's [m]
        self.split = math.inf                   # an element is small where its reach + query_margin is within it [m]
        self.n_exposed = 0                      # the list's length as the host last read it (count: the device's)
        self.n_class = [0, 0]                   # ... and its classes'
        self.captured = False                   # the step is being captured: launches over the list's capacity
        self._count_stale = False               # captured steps have run since n_exposed was read
        self._since = self.rebuild_interval
        self._dt: float | None = None
        self.mass_floor = 1.0        # lightest a particle can become, as a fraction of its seeded mass (crack gas)

    # ------------------------------------------------------------------ stable step
    def stable_dt(self) -> float:
        """2/ω of the stiffest contact [s], computed once (masses and k_c do not change); see ``_contact_dt``."""
        if self._dt is None:
            self._dt = self._contact_dt()
        return self._dt

    def _contact_dt(self) -> float:
        """2/ω of the stiffest contact [s]: a particle held by two edges (2k_c·C/m_p) and a rock node loaded by
        the particles along its two element edges (k_c·(L₁ + L₂)/(2r_p)/m_node); METHOD §3.6.

        C = 1 + S·(r_max/h)² when the force acts at the particle's surface: the moment spreads it over the grid
        nodes with weights Ñ_I = N_I + o·∇N_I, and a particle alone on its nodes (m_I = N_I·m_p) then has the
        stiffness k_c·Σ Ñ_I²/(N_I·m_p) = k_c·(1 + Σ(o·∇N_I)²/N_I)/m_p, S = max over positions of Σ(h·∂N_I)²/N_I
        (6 for the quadratic B-spline, 9.3 for uGIMP at 2 points per cell; C = 2.5 for B-splines at r_max = h/2).
        In the single-hole example the rock-node bound is the smaller one, so C leaves its step unchanged.
        """
        m_p = self.mass_floor * float(self.mpm.mass.numpy().min()) if self.mpm.n else math.inf
        om2_p = 2.0 * self.kc * self.lever_stiffness_factor() / m_p
        L = self.model.mesh.edge_lengths()                              # [E, 3], edge k runs k → k+1
        adj = np.stack([L[:, 0] + L[:, 2], L[:, 1] + L[:, 0], L[:, 2] + L[:, 1]], 1).reshape(-1)
        r_p = max(self.r_p0, 1e-12)
        om2_r = float(np.max(self.kc * np.maximum(adj / (2.0 * r_p), 1.0) / self.model.host["node_mass_dt"]))
        return 2.0 / math.sqrt(max(om2_p, om2_r))

    def lever_stiffness_factor(self) -> float:
        """C = 1 + S·(r_max/h)² [-] (see ``_contact_dt``); 1 when the force acts at the particle centre."""
        if not self.surface_forces:
            return 1.0
        from blastfrac.mpm.shape import shape_1d_np

        kind = "bspline2" if self.mpm.shape_kind == 0 else "ugimp"
        f = np.linspace(0.0, 1.0, 401)[:-1, None] + 0.5 - np.arange(-1, 3)[None, :]   # 4 nodes around each position
        N, dN = shape_1d_np(f, kind, self.mpm.shape_l)
        S = float(np.max(np.sum(np.where(N > 1e-12, dN * dN / np.maximum(N, 1e-300), 0.0), axis=1)))
        return 1.0 + S * (self.r_max / self.mpm.spec.h) ** 2

    # ------------------------------------------------------------------ per step
    def _rebuild(self, state) -> None:
        m = self.model
        self.count.zero_()
        self.cls_count.zero_()
        self.reach.zero_()
        # the elements a particle can reach before the next rebuild: within the MPM grid's active node box (which
        # holds every particle until its next renewal, mpm/grid.py), widened by a cell per step to this list's next
        # rebuild plus one renewal period (a particle moves less than a cell per step); not the whole grid, whose
        # far-field boundary elements would set a large search radius for every particle
        sp, g = self.mpm.spec, self.mpm.grid
        grow = (self.rebuild_interval + BOX_STEPS) * sp.h
        i0, j0, i1, j1 = g.box
        lo = wp.vec2d(max(sp.x0, sp.x0 + i0 * sp.h - grow), max(sp.y0, sp.y0 + j0 * sp.h - grow))
        hi = wp.vec2d(min(sp.x0 + (sp.nx - 1) * sp.h, sp.x0 + i1 * sp.h + grow),
                      min(sp.y0 + (sp.ny - 1) * sp.h, sp.y0 + j1 * sp.h + grow))
        margin = wp.float64(self.query_margin)
        wp.launch(collect_exposed_elements, dim=m.element_count,
                  inputs=[self.slot_iface, state.pair_mode, state.x, self.elem_reach, lo, hi, margin,
                          wp.float64(self.split)],
                  outputs=[self.count, self.elems, self.cls_count, self.cls_elems, self.cls_points, self.reach],
                  device=m.device)
        if self.captured:
            self.build_hash(captured=True)
            self._count_stale = True
        else:
            self._count_stale = True
            self._read_count()
            if self.cell_size == 0.0:                    # the first rebuild (never captured)
                self.note_reach()
            self.build_hash()

    def note_reach(self) -> None:
        """Read the list's reach statistics back and set the cell widths of the two hashes for the next rebuilds:
        the small elements' CELL_REACH times the list's mean reach + query_margin, the large ones' its largest reach
        + query_margin, each rounded down to query_margin·CELL_GROWTH^k; the first is also the split (``split``: an
        element is small where its reach + query_margin is within it). Where the second is less than CELL_GROWTH³ (≈ 2)
        times the first, every element is small (split = ∞) and searched within the largest reach, in a hash of the
        second width. An element whose reach + query_margin fits
        in the small hash's cell is small: a particle finds it with a search one cell wide; the larger ones (a coarse
        far mesh's blocks that cracks expose), with a search of the largest reach in their own sparse hash, so that
        they no longer widen every particle's search. Called at the first rebuild and by Simulation after each
        renewal of the MPM box (every 5 steps, where the step reads the box back anyway), in a captured run and
        through the launches alike, so both build the same hashes; the steps keep the widths, and so the graphs
        that hold them, to a few a run.

        Measured at the end states of the benchmark's demo (6 mm far mesh, 896 listed elements of reach 0.65–3.33 mm,
        median 1.27) and confined P0 (10 mm far mesh, 919 listed), the coupler's pass on one thread
        (benchmarks/RESULTS.md, stop 29): one hash with a cell of the largest search radius (3.64 / 3.02 mm) 0.89 /
        0.32 ms a step; with the reach in the points' z 0.76–0.79 / 0.32; two classes (small cell 1.86 mm: 652 /
        660 small, 244 / 259 large) 0.63 / 0.35, hence one class where the largest radius is under about twice the
        small one (P0: 2.91 against 1.86 mm).
        """
        st = self.reach.numpy()
        mean = st[REACH_SUM] / st[REACH_COUNT] if st[REACH_COUNT] > 0 else 0.0
        self.cell_large = self._cell(st[REACH_MAX] + self.query_margin)
        self.cell_size = self.split = self._cell(CELL_REACH * mean + self.query_margin)
        if self.cell_large < CELL_GROWTH ** 3 * self.cell_size * (1.0 - 1e-9):
            self.cell_size, self.split = self.cell_large, math.inf    # a second search would save less than it costs

    def _cell(self, radius: float) -> float:
        """radius [m] rounded down to query_margin·CELL_GROWTH^k (k ≥ 0)."""
        k = max(0, math.floor(math.log(radius / self.query_margin) / math.log(CELL_GROWTH)))
        return self.query_margin * CELL_GROWTH ** k

    def build_hash(self, captured: bool = False) -> None:
        """The hashes of the listed points of each class with their cell widths: over the n_class points the host
        read (a rebuild outside a capture, a restart), or over the list's capacity with the points past its length
        (on the device) sorted after every cell (a captured rebuild); either way the same cells in the same order.
        Each class's list is first put in element order (the order a CPU appends it in; a GPU appends in any order),
        then hashed by a stable sort by cell, as wp.HashGrid builds its own."""
        m, h = self.model, self.hash
        E, dim = m.element_count, h.dim
        h.cell_inv = wp.vec2d(1.0 / self.cell_size if self.cell_size else 0.0,
                              1.0 / self.cell_large if self.cell_large else 0.0)
        for c, cell in ((SMALL, self.cell_size), (LARGE, self.cell_large)):
            n = E if captured else self.n_class[c]
            if n == 0:
                continue                     # (the search skips an empty class)
            # the class's list in element order (a CPU appends it so; a GPU in any order)
            self._launch(listed_element_keys, n, [self.cls_count, c, self.cls_elems, c * E, E, self._keys,
                                                  self._order], device=m.device, key=c)
            wp.utils.radix_sort_pairs(self._keys, self._order, n, end_bit=max(1, E.bit_length()))   # keys ≤ E
            self._launch(gather_listed, n, [self._order, self.cls_count, c, c * E, self.cls_elems, self.cls_points,
                                            self._tmp_elems, self._tmp_points], device=m.device, key=c)
            wp.copy(self.cls_elems, self._tmp_elems, dest_offset=c * E, count=n)
            wp.copy(self.cls_points, self._tmp_points, dest_offset=c * E, count=n)
            values, starts, ends = self._hash_views[c]
            self._launch(hash_listed_points, n, [self.cls_count, c, self.cls_points, c * E, wp.float64(1.0 / cell),
                                                 dim, self._keys, values], device=m.device, key=c)
            wp.utils.radix_sort_pairs(self._keys, values, n, end_bit=(dim * dim).bit_length())     # keys ≤ dim²
            starts.zero_()
            ends.zero_()
            self._launch(listed_cell_ranges, n, [self._keys, n, dim, c * dim * dim, h.starts, h.ends],
                         device=m.device, key=c)

    def _read_count(self) -> None:
        """n_exposed and n_class from the device after a rebuild (a view on a CPU, a synchronisation on a GPU)."""
        if self._count_stale:
            self.n_exposed = int(self.count.numpy()[0])
            self.n_class = [int(v) for v in self.cls_count.numpy()]
            self._count_stale = False

    def apply(self, state, dt: float) -> None:
        """Contact forces at the current positions: f_ext_p and f_ext_moment of the gas (assigned) and the rock
        reactions (into f_react; ``add_reactions`` adds them to state.f), and the work bookkeeping
        (kept inside the kernels: each step's work with the mean of the velocities before and after it, see
        ``energies``). Reads state.x, state.v and state.pair_mode only, so it may run
        beside the rock's force stages once the springs have failed for this step."""
        m = self.model
        nodes = self._list_nodes()                        # the last list's nodes (before a rebuild replaces it)
        rebuild, w_old, h_in, h_out = self.host_step(dt)
        # the second half of the last step's reactions' work over the nodes they came from, f_react cleared
        self._launch(account_rock_work_and_clear, dim=max(1, nodes),
                     inputs=[self.elems, self.count, self.f_react, state.v, w_old, self.acc], device=m.device)
        if rebuild:
            self._rebuild(state)
        if self.captured:                                 # the list's length is known on the device only
            wp.capture_if(self.count, on_true=lambda: self._contacts(state, dt, w_old, h_in, h_out),
                          on_false=lambda: self._no_contacts(w_old, h_out))
        elif self.n_exposed:
            self._contacts(state, dt, w_old, h_in, h_out)
        else:
            self._no_contacts(w_old, h_out)

    def host_step(self, dt: float) -> tuple:
        """The host's side of a step (``apply`` calls it; a replayed step, Simulation, calls it alone): the rebuild
        schedule, the step lengths of the work books, and the contact histories' buffers, read from one pair and
        written to the other. Returns (rebuild now, w_old = ½Δt of the last step [s], histories in, out)."""
        rebuild = self.rebuild_due()
        self._since = 1 if rebuild else self._since + 1
        w_old = 0.5 * self._dt_work                       # the last step's forces, velocities after that step
        self._dt_work = dt
        self._w_react = 0.5 * dt                          # add_reactions books the first half of this step's
        h_in, h_out = self._hist
        self._hist = [h_out, h_in]                        # this step's histories are the next step's input
        return rebuild, w_old, h_in, h_out

    def rebuild_due(self) -> bool:
        """True when this step rebuilds the list and its hashes (every ``rebuild_interval`` steps)."""
        return self._since >= self.rebuild_interval

    def graph_key(self) -> tuple:
        """What a captured step holds fixed of this stage from step to step (a graph for each, coupled_graph.py):
        whether it rebuilds the list, the buffer its histories come from, the last step's length."""
        return self.rebuild_due(), id(self._hist[0][0]), self._dt_work

    def graph_held(self) -> tuple:
        """What it holds fixed for longer (every graph is captured again when it changes): the MPM box the list
        covers, the hashes' cell widths and split."""
        return self.mpm.grid.box, self.cell_size, self.cell_large, self.split

    def host_state(self) -> tuple:
        """The host's side of the stage (``host_step`` moves it on), to be put back by ``set_host_state``."""
        return self._since, self._dt_work, self._w_react, list(self._hist)

    def set_host_state(self, saved: tuple) -> None:
        self._since, self._dt_work, self._w_react, self._hist = saved[0], saved[1], saved[2], list(saved[3])

    def _list_nodes(self) -> int:
        """Threads of a launch over the listed elements' nodes: the list's capacity in a capture, else its length."""
        if self.captured:
            self._count_stale = True
            return 3 * self.model.element_count
        self._read_count()
        return 3 * self.n_exposed

    def _contacts(self, state, dt: float, w_old: float, h_in, h_out) -> None:
        mpm, m = self.mpm, self.model
        self._launch(eval_particle_edge_contact, dim=mpm.n,
                     inputs=[self.hash, self.cls_count, self.cls_elems,
                             self.cls_points, self.slot_iface, state.pair_mode,
                             state.x, state.v, m.node_mass, mpm.x, mpm.v_pic, mpm.grad_v, mpm.mass, mpm.vol, mpm.p,
                             mpm.rho, mpm.active, wp.float64(self.kc), wp.float64(self.force_cap),
                             wp.float64(self.zeta), wp.float64(self.mu), wp.float64(self.r_max), self.reach,
                             wp.float64(self.query_margin), wp.float64(self.split), wp.float64(dt), wp.float64(float(self.surface_forces)),
                             wp.float64(float(self.pressure_preload)), wp.float64(w_old), wp.float64(0.5 * dt),
                             wp.float64(float(self.contact_heating)), mpm.mat_kind, *h_in],
                     outputs=[mpm.f_ext_p, mpm.f_ext_moment, self.f_react, self.acc, *h_out, self.diss_p],
                     device=m.device, key=id(h_in[0]))                   # one record per history buffer

    def _no_contacts(self, w_old: float, h_out) -> None:
        """No listed element: no force on the gas, an empty history (the one the step hands on), and the second half
        of the last step's work."""
        mpm = self.mpm
        if w_old > 0.0:
            self._launch(accumulate_gas_contact_work, dim=mpm.n,
                         inputs=[mpm.f_ext_p, mpm.f_ext_moment, mpm.v_pic, mpm.grad_v, mpm.active, w_old],
                         outputs=[self.acc], device=self.model.device)
        mpm.f_ext_p.zero_()
        mpm.f_ext_moment.zero_()
        h_out[0].fill_(-1)

    def add_reactions(self, state) -> None:
        """state.f += this step's contact reactions (f_react), and the first half of their work at the rock's
        velocities before the step; over the nodes of the listed elements, the only ones the contacts load."""
        self._launch(add_reactions_with_work, dim=self._list_nodes(),
                     inputs=[self.elems, self.count, state.f, self.f_react, state.v, self._w_react, self.acc],
                     device=self.model.device)
        if self.contact_heating:                          # the contacts' dissipation so far heats the gas in contact
            self._launch(heat_gas_from_contacts, dim=self.mpm.n, inputs=[self.acc, self.diss_p],
                         outputs=[self.mpm.ie], device=self.model.device)

    def energies(self) -> dict[str, float]:
        """contact_energy: work absorbed by the contacts so far, −∫(P_gas + P_rock) dt [J/m] with the power put into
        the gas (f·v + M:L per particle) and into the rock (f·v per node) at mid-step velocities (penalty energy held
        now plus dashpot, friction and force-cap losses; negative where the contacts do net work, see
        docs/results.md); contact_penalty: ½k_c·δ² now (uncapped, for reference) [J/m]; contacts: particle–element
        contacts now [-]. The work of the last step is in up to its first half (the second half is added with the
        next step's forces)."""
        a = self.acc.numpy()
        # the heat handed over at the last step is booked at the next one (account_rock_work_and_clear)
        return {"contact_energy": float(a[ACC_ABSORBED] - a[ACC_HEAT_NEW]), "contact_penalty": float(a[ACC_STORED]),
                "contacts": int(a[ACC_CONTACTS]), "contact_heat": float(a[ACC_HEATED] + a[ACC_HEAT_NEW])}
