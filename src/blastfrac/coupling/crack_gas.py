"""CrackGas: detonation gas inside cracks narrower than a material point (docs/explosive.md, "Gas in cracks").

Blast cracks open 0.1–0.2 mm near the hole, far below any affordable particle, so the MPM gas cannot enter
them as particles. This stage carries the gas there as a network of *cells*, one per broken interface
(coupling/kernels_crack_gas.py):

* **Network.** A cell is an interface whose two springs have broken; cells sharing a mesh vertex are joined
  (all broken interfaces at a vertex meet in the void there). A cell end on a surface vertex (borehole wall,
  free face) with fully burnt gas within ``mouth_radius`` of it is a *mouth*, fed by the nearest particle (found
  in a hash of the burnt particles built with the network, ``hash_burnt``).
  Intact interfaces hold no gas and pass none: gas reaches a cell only along broken ones.
* **State.** Each cell holds a gas mass and internal energy in its volume (the area between its faces, at
  least ``min_aperture``·L); its pressure, sound speed and γ come from the products' JWL.
* **Load.** The pressure pushes on the four face nodes with p·∂V/∂x, and the gas pays the work the faces
  receive (mid-step velocities, as the particle–edge contact): the crack gas expands adiabatically.
* **Flow.** Along each path (cell–cell at their shared vertex, cell–particle at a mouth) the mass flux is the
  cubic law, capped by the choked flux of the donor (materials/crack_flow.py), carrying the donor's total
  enthalpy. A donor gives at most ``cell_fraction`` (cells) or ``particle_fraction`` (particles) of its mass
  per step, and a particle keeps at least ``particle_floor`` of its initial mass; mass and energy leave one
  side exactly as they reach the other. A particle that gives (or takes) gas keeps its volume: its density
  and pressure fall as in an isentropic expansion, and its reference volume V0 = m/ρ0 follows its mass.

* **Wide cracks belong to the particles.** A cell open wider than a material point (the spacing h/ppc) at both
  ends hands its gas (mass, energy and volume) to the nearest burnt particle and leaves the network for good:
  particles enter such a crack and load it by contact, and the gas is not counted twice.

The network (wet-cell paths and mouths) is rebuilt every ``rebuild_interval`` steps; a cell that breaks in
between is loaded from the next rebuild on. Units SI, per unit thickness.

Nothing the step needs is read back: the counts of paths, mouths and released cells stay on the device, the
launches over the paths cover the list's capacity (its kernels return beyond ``links.count``), and the branches
(no path, no mouth, no released cell) are taken through ``wp.capture_if`` in a captured step (``captured = True``,
set by Simulation while it captures). Outside a capture the host reads the counts (a view on a CPU) and launches
over the paths in use.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from .._warp import Launcher
from .kernels_contact import listed_cell_ranges
from .kernels_crack_gas import (CrackCells, CrackGasParams, CrackGasState, CrackLinks, FaceLoads, GasHash,
                                GasParticles, add_face_loads, clear_face_loads, collect_cell_links, collect_mouths,
                                count_paths, crack_apply_flux, crack_donor_scale, crack_link_flux,
                                crack_particle_scale, crack_refresh_particles, hash_burnt_particles, note_paths,
                                release_wide_cells, update_crack_cells)


def static_cell_links(pair_nodes: np.ndarray, node_vertex: np.ndarray, X: np.ndarray):
    """Every pair of interfaces that share a mesh vertex.

    Returns (pairs [K, 2] interface indices, ends [K, 2] the end (0 = A, 1 = B) of each at the shared vertex,
    dx [K] distance between their reference midpoints [m]) and the (interface, end) → vertex table [Q, 2].
    """
    iA, iB = pair_nodes[0::2, 0], pair_nodes[1::2, 0]
    vert = np.stack([node_vertex[iA], node_vertex[iB]], 1)                 # [Q, 2]
    mid = 0.5 * (X[iA] + X[iB])
    q = np.repeat(np.arange(len(vert)), 2)
    end = np.tile([0, 1], len(vert))
    v = vert.ravel()
    order = np.argsort(v, kind="stable")
    v, q, end = v[order], q[order], end[order]
    starts = np.r_[0, np.flatnonzero(v[1:] != v[:-1]) + 1, len(v)]
    pa, pb, ea, eb = [], [], [], []
    for s, t in zip(starts[:-1], starts[1:]):
        n = t - s
        if n < 2:
            continue
        i, j = np.triu_indices(n, 1)
        pa.append(q[s + i]); pb.append(q[s + j]); ea.append(end[s + i]); eb.append(end[s + j])
    if not pa:
        z = np.zeros((0, 2), np.int64)
        return z, z, np.zeros(0), vert
    pairs = np.stack([np.concatenate(pa), np.concatenate(pb)], 1)
    ends = np.stack([np.concatenate(ea), np.concatenate(eb)], 1)
    dx = np.linalg.norm(mid[pairs[:, 0]] - mid[pairs[:, 1]], axis=1)
    return pairs, ends, dx, vert


def hash_burnt(parts: GasParticles, hsh: GasHash, keys: wp.array, n: int, device, launch=wp.launch) -> None:
    """File the active, fully burnt of the ``n`` particles ``parts`` in the cells of ``hsh`` (a stable sort by cell,
    wp.HashGrid's order; nothing read back, so a graph can hold it). ``keys`` and ``hsh.values`` hold 2n entries
    (the radix sort's scratch), ``hsh.starts``/``ends`` dim²; ``launch`` is wp.launch or a Launcher."""
    launch(hash_burnt_particles, dim=n, inputs=[parts, hsh, keys], device=device)
    wp.utils.radix_sort_pairs(keys, hsh.values, n, end_bit=(hsh.dim * hsh.dim).bit_length())     # keys ≤ dim²
    hsh.starts.zero_()
    hsh.ends.zero_()
    launch(listed_cell_ranges, dim=n, inputs=[keys, n, hsh.dim, 0, hsh.starts, hsh.ends], device=device)


#: a crack cell at or above this pressure [Pa] counts as pressurised in reports and figures
PRESSURISED = 1e6


class CrackGas:
    """The crack-gas stage between the rock ``model`` and the MPM gas ``mpm``; buffers allocated once.

    viscosity: μ of the products [Pa·s]; min_aperture: floor of a cell's volume per unit length [m];
    mouth_radius: burnt gas within this distance of a cell end on a surface feeds it [m];
    rebuild_interval: steps between network rebuilds [-]; cell_fraction, particle_fraction: most of its mass
    a donor gives in one step [-]; particle_floor: a particle keeps at least this fraction of its initial mass [-].
    """

    def __init__(self, model, mpm, viscosity: float, min_aperture: float, mouth_radius: float,
                 rebuild_interval: int = 5, cell_fraction: float = 0.5, particle_fraction: float = 0.2,
                 particle_floor: float = 0.5, material=None, p_max: float | None = None):
        """``mpm`` may be None (verification: cells only, no mouths); then give the products' ``material``
        (JWLParams) and the pressure cap ``p_max`` [Pa]."""
        self.model, self.mpm = model, mpm
        d = model.device
        self.device = d
        self._launch = Launcher()                 # recorded launches (_warp.Launcher): ~10 a step
        topo = model.topology
        pn = topo.pair_nodes
        X = model.host["node_X"]
        Q = len(pn) // 2
        self.Q = Q
        self.rebuild_interval = int(rebuild_interval)
        self.mouth_radius = float(mouth_radius)
        self.particle_floor = float(particle_floor)
        nodes = np.stack([pn[0::2, 1], pn[1::2, 1], pn[1::2, 0], pn[0::2, 0]], 1).astype(np.int32)  # jA jB iB iA
        length = np.linalg.norm(X[pn[1::2, 0]] - X[pn[0::2, 0]], axis=1)
        self.cells = CrackCells()
        self.cells.nodes = wp.array(nodes, dtype=wp.vec4i, device=d)
        self.cells.length = wp.array(length, dtype=wp.float64, device=d)
        self.host_length = length

        def z(n, dtype=wp.float64):
            return wp.zeros(max(1, n), dtype=dtype, device=d)

        g = CrackGasState()
        g.mass, g.energy, g.vol, g.pres, g.cs, g.gamma = z(Q), z(Q), z(Q), z(Q), z(Q), z(Q)
        g.gap, g.force = z(Q, wp.vec2d), z(4 * Q, wp.vec2d)
        g.wet = z(Q, wp.int32)
        g.p_fixed = wp.full(max(1, Q), -1.0, dtype=wp.float64, device=d)
        g.out, g.scale = z(Q), wp.ones(max(1, Q), dtype=wp.float64, device=d)
        self.gas = g

        P = mpm.material if mpm is not None else material
        prm = CrackGasParams()
        prm.rho0, prm.A, prm.B, prm.R1, prm.R2, prm.omega = P.rho0, P.A, P.B, P.R1, P.R2, P.omega
        prm.p_max = float(p_max if p_max is not None else mpm.p_cj)
        prm.mu, prm.w_min = float(viscosity), float(min_aperture)
        prm.cell_fraction, prm.particle_fraction = float(cell_fraction), float(particle_fraction)
        self.params = prm

        pairs, ends, dx, vert = static_cell_links(pn, topo.node_vertex, X)
        self.n_static = len(pairs)
        self.static_pairs = wp.array(pairs.astype(np.int32), dtype=wp.vec2i, device=d)
        self.static_ends = wp.array(ends.astype(np.int32), dtype=wp.vec2i, device=d)
        self.static_dx = wp.array(dx, dtype=wp.float64, device=d)
        surf = np.zeros(len(model.mesh.vertices), bool)
        surf[np.asarray(model.mesh.boundary_edges, np.int64).ravel()] = True
        cq, ce = np.nonzero(surf[vert]) if mpm is not None else (np.zeros(0, int), np.zeros(0, int))
        self.n_cand = len(cq)
        self.cand_cell = wp.array(cq.astype(np.int32), dtype=wp.int32, device=d)
        self.cand_end = wp.array(ce.astype(np.int32), dtype=wp.int32, device=d)

        cap = max(1, self.n_static + self.n_cand)
        lk = CrackLinks()
        lk.a, lk.b = z(cap, wp.int32), z(cap, wp.int32)
        lk.ends, lk.dx, lk.dm, lk.h = z(cap, wp.vec2i), z(cap), z(cap), z(cap)
        lk.count = wp.zeros(1, dtype=wp.int32, device=d)
        self.links = lk
        self.capacity = cap

        pp = GasParticles()
        if mpm is not None:
            n = mpm.n
            pp.x, pp.v, pp.mass, pp.vol, pp.vol0, pp.rho = mpm.x, mpm.v, mpm.mass, mpm.vol, mpm.vol0, mpm.rho
            pp.ie, pp.pres, pp.q, pp.burn, pp.stress, pp.active = mpm.ie, mpm.p, mpm.q, mpm.burn, mpm.stress, mpm.active
            pp.mass0 = wp.clone(mpm.mass)
        else:
            n = 0
            pp.x, pp.v = z(1, wp.vec2d), z(1, wp.vec2d)
            pp.mass, pp.mass0, pp.vol, pp.vol0, pp.rho, pp.ie, pp.pres, pp.q, pp.burn = (z(1) for _ in range(9))
            pp.stress, pp.active = z(1, wp.mat22d), z(1, wp.int32)
        self.n_particles = n
        pp.out, pp.scale, pp.touched = z(n), wp.ones(max(1, n), dtype=wp.float64, device=d), z(n, wp.int32)
        self.parts = pp

        # a cell open wider than this at both ends hands its gas to the MPM [m] (the particle spacing h/ppc)
        self.particle_size = float(mpm.spec.h / mpm.opts.ppc) if mpm is not None else 0.0
        # the burnt particles' hash (GasHash), in which the mouths and the wide cells find their particle: cells as
        # wide as the larger of the two search radii (the release's), about one per particle
        hsh = GasHash()
        dim = int(min(1024, max(16, np.sqrt(max(n, 1)))))
        hsh.values = z(2 * n, wp.int32)
        hsh.starts, hsh.ends = z(dim * dim, wp.int32), z(dim * dim, wp.int32)
        hsh.cell_inv = 1.0 / (self.mouth_radius + self.particle_size) if n else 0.0
        hsh.dim = dim
        self.hash = hsh
        self._hash_keys = z(2 * n, wp.int32)
        self._released = wp.zeros(1, dtype=wp.int32, device=d)           # cells released by this rebuild
        self._released_total = wp.zeros(1, dtype=wp.int32, device=d)     # ... by the run
        # this step's face loads [N/m] and the nodes that carry them (FaceLoads: the add and the clearing visit those)
        nn = max(1, model.node_count)
        self.loads = FaceLoads()
        self.loads.f, self.loads.mark = wp.zeros(nn, dtype=wp.vec2d, device=d), wp.zeros(nn, dtype=wp.int32, device=d)
        self.loads.nodes, self.loads.count = wp.zeros(nn, dtype=wp.int32, device=d), wp.zeros(1, dtype=wp.int32, device=d)
        self._paths = wp.zeros(1, dtype=wp.int32, device=d)              # cell–cell paths of the last rebuild
        self._mouths = wp.zeros(1, dtype=wp.int32, device=d)             # its mouths (paths to particles)
        self.n_links = 0                      # the two counts as the host last read them (outside a capture)
        self.n_mouths = 0
        self._counts_stale = False            # a captured rebuild has run since they were read
        self.captured = False                 # a graph is capturing the step: launches over the capacity
        self._since = self.rebuild_interval
        self._dt_prev = 0.0

    @property
    def released_cells(self) -> int:
        """Cells handed to the particles so far [-] (read from the device)."""
        return int(self._released_total.numpy()[0])

    # ------------------------------------------------------------------ per step
    def rebuild(self, state) -> None:
        """Wide cells handed to the MPM, then the wet-cell paths and mouths at the present state (their counts on the
        device; the host reads them outside a capture)."""
        d = self.device
        lk = self.links
        if self.n_particles:
            hash_burnt(self.parts, self.hash, self._hash_keys, self.n_particles, d, self._launch)
        if self.n_particles and self.particle_size > 0.0:
            self._released.zero_()
            self._launch(release_wide_cells, dim=self.Q,
                         inputs=[self.cells, self.gas, self.parts, self.hash, state.x, state.v,
                                 wp.float64(self.particle_size), wp.float64(self.mouth_radius + self.particle_size),
                                 wp.float64(self._dt_prev), self._released, self._released_total], device=d)
            refresh = lambda: self._launch(crack_refresh_particles, dim=self.n_particles,
                                           inputs=[self.parts, self.params], device=d)
            if self.captured:
                wp.capture_if(self._released, on_true=refresh)
            elif int(self._released.numpy()[0]):
                refresh()
        lk.count.zero_()
        if self.n_static:
            self._launch(collect_cell_links, dim=self.n_static,
                         inputs=[self.static_pairs, self.static_ends, self.static_dx, self.gas.wet, lk], device=d)
        self._launch(note_paths, dim=1, inputs=[lk.count, self._paths], device=d)
        if self.n_cand:
            self._launch(collect_mouths, dim=self.n_cand,
                         inputs=[self.cand_cell, self.cand_end, self.cells, self.gas.wet, state.x, self.parts,
                                 self.hash, wp.float64(self.mouth_radius), wp.float64(self.particle_floor * 1.01), lk],
                         device=d)
        self._launch(count_paths, dim=1, inputs=[lk.count, self._paths, self._mouths], device=d)
        self._counts_stale = True
        if not self.captured:
            self._read_counts()

    def _read_counts(self) -> None:
        """n_links, n_mouths from the device after a rebuild (a view on a CPU, a synchronisation on a GPU)."""
        if self._counts_stale:
            self.n_links, self.n_mouths = int(self._paths.numpy()[0]), int(self._mouths.numpy()[0])
            self._counts_stale = False

    def host_step(self, dt: float) -> tuple[bool, float]:
        """The host's side of a step (``apply`` calls it; a replayed step, Simulation, calls it alone): the rebuild
        schedule and the last step's length. Returns (rebuild now, Δt of the last step [s])."""
        rebuild = self._since >= self.rebuild_interval
        self._since = 1 if rebuild else self._since + 1
        dt_prev, self._dt_prev = self._dt_prev, dt
        return rebuild, dt_prev

    def graph_key(self) -> tuple:
        """What a captured step holds fixed of this stage: whether it rebuilds the network, the last step's length."""
        return self._since >= self.rebuild_interval, self._dt_prev

    def host_state(self) -> tuple:
        """The host's side of the stage (``host_step`` moves it on), to be put back by ``set_host_state``."""
        return self._since, self._dt_prev

    def set_host_state(self, saved: tuple) -> None:
        self._since, self._dt_prev = saved

    def apply(self, state, dt: float) -> None:
        """Stage between the particle–edge contact and P2G: cell pressures and face forces (into ``loads``;
        ``add_loads`` adds them to state.f), then this step's flow along the network and at the mouths."""
        d = self.device
        if self._since >= self.rebuild_interval:
            self.rebuild(state)                   # (reads _dt_prev: before host_step moves it on)
        _, dt_prev = self.host_step(dt)
        self._launch(clear_face_loads, dim=self._loaded_dim(), inputs=[self.loads], device=d)   # the last step's
        self.loads.count.zero_()
        self._launch(update_crack_cells, dim=self.Q,
                     inputs=[self.cells, self.gas, self.params, state.pair_mode, state.x, state.v,
                             wp.float64(dt_prev), wp.float64(dt), self.loads], device=d)
        if self.captured:
            wp.capture_if(self.links.count, on_true=lambda: self._flow(dt))
            return
        self._read_counts()
        if self.n_links + self.n_mouths:
            self._flow(dt)

    def _flow(self, dt: float) -> None:
        """This step's flow along the paths and through the mouths (there is at least one path)."""
        d = self.device
        n = self.capacity if self.captured else self.n_links + self.n_mouths
        self._launch(crack_link_flux, dim=n, inputs=[self.links, self.gas, self.parts, self.params, wp.float64(dt)],
                     device=d)
        self._launch(crack_donor_scale, dim=n, inputs=[self.links, self.gas, self.params], device=d)
        self._at_mouths(lambda: self._launch(crack_particle_scale, dim=self.n_particles,
                                             inputs=[self.parts, self.params, wp.float64(self.particle_floor)],
                                             device=d))
        self._launch(crack_apply_flux, dim=n, inputs=[self.links, self.gas, self.parts], device=d)
        self._at_mouths(lambda: self._launch(crack_refresh_particles, dim=self.n_particles,
                                             inputs=[self.parts, self.params], device=d))

    def _at_mouths(self, launch) -> None:
        """``launch()`` where the network has mouths: on the device's count in a capture, the host's outside."""
        if self.captured:
            wp.capture_if(self._mouths, on_true=launch)
        elif self.n_mouths:
            launch()

    def add_loads(self, state) -> None:
        """state.f += this step's crack-face loads (at the nodes that carry one)."""
        self._launch(add_face_loads, dim=self._loaded_dim(), inputs=[state.f, self.loads], device=self.device)

    def _loaded_dim(self) -> int:
        """Threads for a pass over the loaded nodes: their count on a CPU outside a capture (a view, nothing waits),
        else every node (the threads beyond the count return)."""
        if self.captured or not wp.get_device(self.device).is_cpu:
            return max(1, self.model.node_count)
        return int(self.loads.count.numpy()[0])

    # ------------------------------------------------------------------ verification hooks
    def set_cell_state(self, cells, mass, energy) -> None:
        """Put gas mass [kg/m] and internal energy [J/m] in the given cells (tests, reservoirs)."""
        for arr, val in ((self.gas.mass, mass), (self.gas.energy, energy)):
            h = arr.numpy().copy()
            h[np.asarray(cells)] = val
            arr.assign(h)

    def set_fixed_pressure(self, cells, p) -> None:
        """Hold the given cells at pressure p [Pa] whatever their gas (the pressurised-crack verification)."""
        h = self.gas.p_fixed.numpy().copy()
        h[np.asarray(cells)] = p
        self.gas.p_fixed.assign(h)

    # ------------------------------------------------------------------ results
    def energies(self) -> dict[str, float]:
        """crack_gas: internal energy of the gas in the cracks [J/m]; crack_gas_mass [kg/m]."""
        return {"crack_gas": float(self.gas.energy.numpy()[: self.Q].sum()),
                "crack_gas_mass": float(self.gas.mass.numpy()[: self.Q].sum())}

    def report(self) -> dict:
        """Counts and extremes for summary.json → crack_gas. A cell is *pressurised* at p ≥ PRESSURISED [Pa]; the
        explicit flow also leaves traces of gas ahead of the front (mass > 0, p ≪ 1 MPa), counted apart."""
        g = self.gas
        mass, p, wet = g.mass.numpy()[: self.Q], g.pres.numpy()[: self.Q], g.wet.numpy()[: self.Q]
        loaded = p >= PRESSURISED
        gap = g.gap.numpy()[: self.Q]
        return {
            "wet_cells": int((wet > 0).sum()), "cells_with_gas": int((mass > 0).sum()),
            "cells_handed_to_particles": int((wet == 2).sum()),
            "pressurised_cells": int(loaded.sum()),
            "mass": float(mass.sum()), "internal_energy": float(g.energy.numpy()[: self.Q].sum()),
            "max_pressure": float(p.max()) if self.Q else 0.0,
            "paths": int(self._paths.numpy()[0]), "mouths": int(self._mouths.numpy()[0]),
            "pressurised_length": float(self.host_length[loaded].sum()),
            "median_opening_pressurised": float(np.median(gap[loaded].max(axis=1))) if loaded.any() else 0.0,
        }
