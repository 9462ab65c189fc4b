"""GasRockCoupler: the particle–edge contact stage between the MPM explosive and the CDEM rock (METHOD §3).

Per step (``apply``): the forces on the gas particles are written to ``mpm.f_ext_p`` (they enter the grid in
the next P2G) and the reactions are added to the rock node forces. Candidate elements are those with an
exposed edge; their centroids are hashed (``wp.HashGrid``) and each particle queries the hash, so the cost is
linear in the number of particles. The list is rebuilt every ``rebuild_interval`` steps; between rebuilds the
exposure of every listed edge is re-tested, and a newly cracked element joins at the next rebuild.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from .particle_edge import CONTACT_HISTORY
from .kernels_contact import ACC_ABSORBED, ACC_CONTACTS, ACC_STORED, collect_exposed_elements, eval_particle_edge_contact


def default_contact_stiffness(p_cj: float, factor: float = 20.0) -> float:
    """k_c = factor·P_CJ [Pa]: the overlap at pressure p is about 2p/k_c·r_p (r_p/10 at P_CJ for factor 20)."""
    return factor * p_cj


class GasRockCoupler:
    """Particle–edge contact between ``mpm`` (an MPMSolver) and the rock ``model``; buffers allocated once.

    kc: contact stiffness [Pa = N/m per m of overlap, per unit thickness]; zeta: dashpot damping ratio [-];
    mu: friction coefficient [-]; r_max: cap on the particle radius r_p = ½√V_p [m]; force_cap: κ of the
    pressure-based cap on the normal force (0: none), see :func:`particle_edge.normal_force_cap`.
    """

    def __init__(self, model, mpm, kc: float, zeta: float = 0.0, mu: float = 0.0, rebuild_interval: int = 5,
                 r_max: float | None = None, force_cap: float = 0.0):
        self.model, self.mpm = model, mpm
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
        self.reach_max = wp.zeros(1, dtype=wp.float64, device=d)
        self.elems = wp.zeros(E, dtype=wp.int32, device=d)
        self.points = wp.zeros(E, dtype=wp.vec3d, device=d)
        self.acc = wp.zeros(3, dtype=wp.float64, device=d)
        # (particle, element) contact histories, read from one pair and written to the other each step
        nh = max(1, mpm.n) * CONTACT_HISTORY
        self._hist = [(wp.full(nh, -1, dtype=wp.int32, device=d), wp.zeros(nh, dtype=wp.float64, device=d))
                      for _ in range(2)]
        dim = int(min(1024, max(16, math.sqrt(E))))
        self.grid = wp.HashGrid(dim, dim, 1, device=d, dtype=wp.float64)
        self.query_radius = 0.0
        self.n_exposed = 0
        self._since = self.rebuild_interval
        self._dt: float | None = None

    # ------------------------------------------------------------------ stable step
    def stable_dt(self) -> float:
        """2/ω of the stiffest contact [s], computed once (masses and k_c do not change); see ``_contact_dt``."""
        if self._dt is None:
            self._dt = self._contact_dt()
        return self._dt

    def _contact_dt(self) -> float:
        """2/ω of the stiffest contact [s]: a particle held by two edges (2k_c/m_p) and a rock node loaded by
        the particles along its two element edges (k_c·(L₁ + L₂)/(2r_p)/m_node); METHOD §3.6."""
        m_p = float(self.mpm.mass.numpy().min()) if self.mpm.n else math.inf
        om2_p = 2.0 * self.kc / m_p
        L = self.model.mesh.edge_lengths()                              # [E, 3], edge k runs k → k+1
        adj = np.stack([L[:, 0] + L[:, 2], L[:, 1] + L[:, 0], L[:, 2] + L[:, 1]], 1).reshape(-1)
        r_p = max(self.r_p0, 1e-12)
        om2_r = float(np.max(self.kc * np.maximum(adj / (2.0 * r_p), 1.0) / self.model.host["node_mass"]))
        return 2.0 / math.sqrt(max(om2_p, om2_r))

    # ------------------------------------------------------------------ per step
    def _rebuild(self, state) -> None:
        m = self.model
        self.count.zero_()
        self.reach_max.zero_()
        wp.launch(collect_exposed_elements, dim=m.element_count,
                  inputs=[self.slot_iface, state.pair_mode, state.x, self.elem_reach],
                  outputs=[self.count, self.elems, self.points, self.reach_max], device=m.device)
        self.n_exposed = int(self.count.numpy()[0])
        reach = float(self.reach_max.numpy()[0])
        self.query_radius = reach + self.r_max
        if self.n_exposed:
            self.grid.build(self.points[: self.n_exposed], self.query_radius)
        self._since = 0

    def apply(self, state, dt: float) -> None:
        """Contact forces at the current positions: f_ext_p of the gas (assigned) and rock reactions (added)."""
        if self._since >= self.rebuild_interval:
            self._rebuild(state)
        self._since += 1
        mpm, m = self.mpm, self.model
        wp.launch(_reset_step_acc, dim=1, inputs=[], outputs=[self.acc], device=m.device)
        if self.n_exposed == 0:
            mpm.f_ext_p.zero_()
            self._hist[0][0].fill_(-1)
            return
        wp.launch(eval_particle_edge_contact, dim=mpm.n,
                  inputs=[self.grid.id, self.elems, self.slot_iface, state.pair_mode, state.x, state.v, m.node_mass,
                          mpm.x, mpm.v_pic, mpm.mass, mpm.vol, mpm.p, mpm.rho, mpm.active,
                          wp.float64(self.kc), wp.float64(self.force_cap), wp.float64(self.zeta), wp.float64(self.mu), wp.float64(self.r_max),
                          wp.float64(self.query_radius), wp.float64(dt), self._hist[0][0], self._hist[0][1]],
                  outputs=[mpm.f_ext_p, state.f, self.acc, self._hist[1][0], self._hist[1][1]], device=m.device)
        self._hist.reverse()

    def energies(self) -> dict[str, float]:
        """contact_energy: work absorbed by the contacts so far, ∫ −f·(v_p − v_c) dt [J/m] (penalty energy held
        now plus dashpot, friction and force-cap losses); contact_penalty: ½k_c·δ² now (uncapped, for reference)
        [J/m]; contacts: particle–element contacts now [-]."""
        a = self.acc.numpy()
        return {"contact_energy": float(a[ACC_ABSORBED]), "contact_penalty": float(a[ACC_STORED]),
                "contacts": int(a[ACC_CONTACTS])}


@wp.kernel
def _reset_step_acc(acc: wp.array(dtype=wp.float64)):
    acc[ACC_STORED] = wp.float64(0.0)
    acc[ACC_CONTACTS] = wp.float64(0.0)
