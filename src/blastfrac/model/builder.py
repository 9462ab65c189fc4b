"""Build the rock Model from a Scenario: mesh → blocks, springs, boundary data, stable Δt."""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from .._warp import init_warp
from ..geometry.mesh import TriMesh, generate_mesh
from ..materials.elastic import lame
from .compliance import elastic_report, spring_compliance_density
from .heterogeneity import interface_factors, rms
from ..materials.interface import band_slopes, softening_slope
from ..scenario.schema import Scenario
from .model import Model
from .topology import build_topology


#: consistent-mass fraction θ of each rock.mass_matrix choice
MASS_THETA = {"lumped": 0.0, "averaged": 0.5, "consistent": 1.0}


class ModelBuilder:
    """Host-side assembly of the rock model; ``finalize(device)`` moves it to a Warp device."""

    def __init__(self, scenario: Scenario, mesh: TriMesh | None = None):
        self.scenario = scenario
        self.mesh = mesh if mesh is not None else generate_mesh(scenario.geometry, scenario.simulation.seed)
        self.topology = build_topology(self.mesh)
        self._assemble()

    # ------------------------------------------------------------------ host assembly
    def _assemble(self) -> None:
        sc, mesh, topo = self.scenario, self.mesh, self.topology
        rock = sc.rock
        tri = mesh.triangles
        X = mesh.vertices[tri].reshape(-1, 2)
        area = 0.5 * _cross(X[1::3] - X[0::3], X[2::3] - X[0::3])
        h = {}
        h["node_X"] = X
        h["node_mass"] = np.repeat(rock.density * area / 3.0, 3)
        # θ of the block mass matrices and the smallest eigen-mass per node, m(1 − 3θ/4), which bounds every
        # stable-step estimate (M_e ≥ m(1 − 3θ/4)·I, cdem/kernels_integrate.py)
        self.mass_theta = MASS_THETA[rock.mass_matrix]
        h["node_mass_dt"] = h["node_mass"] * (1.0 - 0.75 * self.mass_theta)
        h["elem_area0"] = area

        # springs
        s1 = topo.iface_slots[:, 0]
        na, nb = s1, 3 * (s1 // 3) + (s1 % 3 + 1) % 3
        L = np.linalg.norm(X[nb] - X[na], axis=1)
        e1, e2 = topo.iface_elems[:, 0], topo.iface_elems[:, 1]
        hbar = (area[e1] + area[e2]) / L              # mean of the two heights 2A/L [m]
        if rock.stiffness_mode == "per_area":
            kn_a = np.full(len(L), rock.kn)
            ks_a = np.full(len(L), rock.ks)
        else:
            kn_a = rock.spring_penalty * rock.plane_strain_modulus / hbar
            ks_a = kn_a.copy()
        # heterogeneous rock: one unit-mean Weibull factor per interface and property, shared by the
        # interface's two springs (model/heterogeneity.py), times (L_ref/L_q)^(1/m) on the strengths with
        # reference_length (weakest-link size scaling), or sampled at the midpoints from a field correlated
        # over correlation_length; {} for a homogeneous rock
        self.factors = interface_factors(rock.heterogeneity, len(L), sc.simulation.seed, L,
                                           0.5 * (X[na] + X[nb]))
        kn_min_nominal = float(kn_a.min()) if len(kn_a) else 1.0
        ks_min_nominal = float(ks_a.min()) if len(ks_a) else 1.0
        if "stiffness" in self.factors:
            # per-area stiffness of each interface: the compliance compensation, the contact stiffness
            # (mean of pair_kn_area), the platen penalty and the stable step below all see these values
            kn_a = kn_a * self.factors["stiffness"]
            ks_a = ks_a * self.factors["stiffness"]
        # block moduli: compensated for the springs' compliance so that the assembly has the input E, ν
        # (penalty mode by default), or the input itself (model/compliance.py)
        s_n, s_s = spring_compliance_density(L, kn_a, ks_a, float(area.sum()))
        self.elastic = elastic_report(rock.youngs_modulus, rock.poisson_ratio, rock.density, s_n, s_s,
                                      bool(rock.compensate_spring_compliance))
        self.lam, self.mu = lame(self.elastic.block_E, self.elastic.block_nu)
        ac = L / 2.0
        h["pair_ac"] = np.repeat(ac, 2)
        h["pair_l0"] = np.repeat(L, 2)
        h["pair_kn_area"] = np.repeat(kn_a, 2)
        h["pair_kn"] = np.repeat(kn_a * ac, 2)
        h["pair_ks"] = np.repeat(ks_a * ac, 2)
        t_q = np.full(len(L), rock.tensile_strength)
        c_q = np.full(len(L), rock.cohesion)
        if "tensile_strength" in self.factors:
            t_q = t_q * self.factors["tensile_strength"]
        if "cohesion" in self.factors:
            c_q = c_q * self.factors["cohesion"]
        # one softening rate per model (the spring kernels take a scalar): the homogeneous rule at the
        # softest nominal spring, with the area-weighted rms strength of a scattered field. Interface q then
        # dissipates G_f·(T_q/T_rms)², area-weighted mean G_f (docs/heterogeneity.md "Fracture energy")
        t_ref = rms(t_q, L) if "tensile_strength" in self.factors and len(L) else rock.tensile_strength
        c_ref = rms(c_q, L) if "cohesion" in self.factors and len(L) else rock.cohesion
        self.slope_t = softening_slope(t_ref, rock.tensile_fracture_energy, kn_min_nominal)
        self.slope_c = softening_slope(c_ref, rock.shear_fracture_energy, ks_min_nominal)
        # fracture band (rock.fracture_band_width w_c): an interface whose blocks are thinner than w_c carries
        # the share h̄_q/w_c of the fracture energies, so that the energy of fragmenting a volume is the same on
        # any mesh finer than w_c (docs/scenario.md "Fracture band"); a per-interface softening rate
        law, self.band_factor = None, None
        if rock.fracture_band_width is not None:
            self.band_factor = np.minimum(1.0, hbar / rock.fracture_band_width)
            law = np.empty((len(L), 4))
            law[:, 0] = math.tan(math.radians(rock.friction_angle))
            law[:, 1] = math.tan(math.radians(rock.residual_friction))
            for col, gf, s_ref, k_min in ((2, rock.tensile_fracture_energy, t_ref, kn_min_nominal),
                                          (3, rock.shear_fracture_energy, c_ref, ks_min_nominal)):
                law[:, col] = (band_slopes(s_ref, gf * self.band_factor, k_min) if gf is not None else 0.0)
        # pre-existing joints (geometry.joints, docs/joints.md): their interfaces take the joint's strengths,
        # friction and (optional) stiffness. The rock's compliance compensation, softening rates and nominal
        # stiffness above are those of the rock (a joint's own compliance is physical, not compensated).
        jq = self.topology.iface_joint
        h["iface_joint"] = jq
        h["pair_joint"] = np.repeat(jq, 2)
        if np.any(jq >= 0):
            self._joint_properties(h, jq, kn_a, ks_a, ac, t_q, c_q, law)
        elif law is not None:
            h["pair_law"] = np.repeat(law, 2, axis=0)
        h["pair_t0"] = np.repeat(t_q, 2)
        h["pair_c0"] = np.repeat(c_q, 2)
        # the unit normal of each interface, e1 → e2, for the stable-step row sums
        t = (X[nb] - X[na]) / L[:, None]
        h["iface_normal"] = np.stack([t[:, 1], -t[:, 0]], 1)

        self._boundary_data(h, X)
        self.host = h
        self.stable_dt = self._gershgorin_dt(h, X)

    def _joint_properties(self, h: dict, jq: np.ndarray, kn_a, ks_a, ac, t_q, c_q, law=None) -> None:
        """Give the joint interfaces their set's properties (in place on t_q, c_q and the stiffness arrays);
        ``law`` [Q, 4]: the rock's per-interface law (a fracture band), else the rock's scalars."""
        rock = self.scenario.rock
        if law is None:
            law = np.empty((len(jq), 4))
            law[:] = (math.tan(math.radians(rock.friction_angle)), math.tan(math.radians(rock.residual_friction)),
                      self.slope_t, self.slope_c)
        mode0 = np.zeros(len(jq), np.int32)
        for s, js in enumerate(self.scenario.geometry.joints):
            m = jq == s
            if not m.any():
                continue
            if js.kn is not None:
                kn_a[m] = js.kn
            if js.ks is not None:
                ks_a[m] = js.ks
            t_q[m] = js.tensile_strength
            c_q[m] = js.cohesion
            # joints are brittle: at failure they drop to their residual friction (no softening)
            law[m] = (math.tan(math.radians(js.friction_angle)), math.tan(math.radians(js.residual_friction)), 0.0, 0.0)
            if js.open:
                mode0[m] = 1                                    # broken in tension from t = 0
                t_q[m] = 0.0
                c_q[m] = 0.0
        h["pair_kn_area"] = np.repeat(kn_a, 2)
        h["pair_kn"] = np.repeat(kn_a * ac, 2)
        h["pair_ks"] = np.repeat(ks_a * ac, 2)
        h["pair_law"] = np.repeat(law, 2, axis=0)
        if mode0.any():
            h["pair_mode0"] = np.repeat(mode0, 2)

    def _boundary_data(self, h: dict, X: np.ndarray) -> None:
        sc, topo = self.scenario, self.topology
        rock = sc.rock
        n_node = len(X)
        P = np.tile(np.eye(2), (n_node, 1, 1))
        C = np.zeros((n_node, 2, 2))
        constrained = np.zeros(n_node, bool)
        self.pulses = []
        pulse_of_side: dict[str, int] = {}
        for side, cfg in sc.boundaries.items():
            if cfg.type == "pressure":
                pulse_of_side[side] = len(self.pulses)
                self.pulses.append(cfg.pulse)
        for bp in sc.borehole_pressure:
            pulse_of_side[f"hole{bp.borehole}"] = len(self.pulses)
            self.pulses.append(bp.pulse)
        sig0 = np.array([[sc.insitu.sxx, sc.insitu.sxy], [sc.insitu.sxy, sc.insitu.syy]])
        ln0, ln1, lp, lf = [], [], [], []
        cp_eff, cs_eff = self.elastic.assembly_speeds      # the impedance of the assembly the waves travel in
        rho_cp = rock.density * cp_eff
        rho_cs = rock.density * cs_eff
        for slot, tag in zip(topo.boundary_slots, topo.boundary_slot_tags):
            n0 = int(slot)
            n1 = int(3 * (slot // 3) + (slot % 3 + 1) % 3)
            d = X[n1] - X[n0]
            L = float(np.hypot(*d))
            n = np.array([d[1], -d[0]]) / L            # outward normal of the block
            tvec = d / L
            kind = sc.boundary(tag).type
            for node in (n0, n1):
                if kind == "fixed":
                    P[node] = 0.0
                    constrained[node] = True
                elif kind == "roller":
                    P[node] = P[node] @ (np.eye(2) - np.outer(n, n))
                    constrained[node] = True
                elif kind == "viscous":
                    C[node] += 0.5 * L * (rho_cp * np.outer(n, n) + rho_cs * np.outer(tvec, tvec))
                    constrained[node] = True
            f0 = np.zeros(2)
            if sc.insitu.active and not tag.startswith("hole") and kind in ("free", "viscous", "pressure"):
                f0 = 0.5 * L * (sig0 @ n)                 # consistent traction σ⁰·n on each of the two nodes
            pid = pulse_of_side.get(tag, -1)
            if pid >= 0 or np.any(f0 != 0.0):
                ln0.append(n0), ln1.append(n1), lp.append(pid), lf.append(f0)
        idx = np.full(n_node, -1, np.int64)
        cn = np.flatnonzero(constrained)
        idx[cn] = np.arange(len(cn))
        h["node_bc"] = idx
        h["bc_P"] = P[cn] if len(cn) else np.zeros((1, 2, 2))
        h["bc_C"] = C[cn] if len(cn) else np.zeros((1, 2, 2))
        h["ledge_n0"] = np.array(ln0, np.int64)
        h["ledge_n1"] = np.array(ln1, np.int64)
        h["ledge_pulse"] = np.array(lp, np.int64)
        h["ledge_f0"] = np.array(lf).reshape(-1, 2)

    def _gershgorin_dt(self, h: dict, X: np.ndarray) -> float:
        """2/ω_max with ω_max² ≤ max_i R_i/m_i, R_i the absolute row sums of the stiffness: CST, springs and, for a
        breakable rock with block contact, one block contact per node (METHOD §1.7)."""
        row = element_row_sums(X, self.lam, self.mu)              # [N, 2]
        pn = self.topology.pair_nodes
        nrm = np.repeat(h["iface_normal"], 2, axis=0)
        kn, ks = h["pair_kn"], h["pair_ks"]
        nx, ny = nrm[:, 0], nrm[:, 1]
        cross = np.abs(kn - ks) * np.abs(nx * ny)
        rx = 2.0 * (kn * nx**2 + ks * ny**2 + cross)
        ry = 2.0 * (kn * ny**2 + ks * nx**2 + cross)
        for col in (0, 1):
            np.add.at(row[:, 0], pn[:, col], rx)
            np.add.at(row[:, 1], pn[:, col], ry)
        if has_contact_allowance(self.scenario.rock):
            # allowance for one node-to-edge block contact at each node (METHOD §1.5, §1.7): 2·K_c in each row,
            # K_c = k_c·t_n, the contact stiffness per area block contact uses and the node's tributary length
            row += 2.0 * (contact_stiffness_per_area(h) * node_tributary_length(X))[:, None]
        omega2 = np.max(row / h["node_mass_dt"][:, None])
        # a dashpot of ratio ζ on the stiffest mode lowers the central-difference limit to
        # (2/ω)(√(1+ζ²) − ζ) (Belytschko, Liu & Moran, Nonlinear FE, §6.3)
        zeta = self.scenario.rock.spring_damping
        return 2.0 / math.sqrt(omega2) * (math.sqrt(1.0 + zeta**2) - zeta)

    # ------------------------------------------------------------------ device
    def finalize(self, device: str = "cpu") -> Model:
        init_warp()
        h, rock = self.host, self.scenario.rock
        d = device

        def arr(a, dtype):
            return wp.array(np.ascontiguousarray(a), dtype=dtype, device=d)

        m = Model(
            mesh=self.mesh, topology=self.topology, device=d,
            lam=self.lam, mu=self.mu, density=rock.density,
            tan_phi=math.tan(math.radians(rock.friction_angle)),
            tan_phi_r=math.tan(math.radians(rock.residual_friction)),
            slope_t=self.slope_t, slope_c=self.slope_c,
            breakable=0 if rock.unbreakable else 1,
            crush=float(rock.crushing_strength or 0.0),
            q_quad=rock.bulk_viscosity_quadratic, q_lin=rock.bulk_viscosity_linear,
            spring_damping=rock.spring_damping,
            node_mass=arr(h["node_mass"], wp.float64),
            node_X=arr(h["node_X"], wp.vec2d),
            node_pairs=arr(self.topology.node_pairs.astype(np.int32), wp.vec2i),
            node_spring_code=arr(node_spring_code(self.topology), wp.vec2i),
            node_bc=arr(h["node_bc"].astype(np.int32), wp.int32),
            bc_P=arr(h["bc_P"], wp.mat22d),
            bc_C=arr(h["bc_C"], wp.mat22d),
            elem_area0=arr(h["elem_area0"], wp.float64),
            pair_i=arr(self.topology.pair_nodes[:, 0].astype(np.int32), wp.int32),
            pair_j=arr(self.topology.pair_nodes[:, 1].astype(np.int32), wp.int32),
            pair_kn=arr(h["pair_kn"], wp.float64),
            pair_ks=arr(h["pair_ks"], wp.float64),
            pair_ac=arr(h["pair_ac"], wp.float64),
            pair_l0=arr(h["pair_l0"], wp.float64),
            pair_t0=arr(h["pair_t0"], wp.float64),
            pair_c0=arr(h["pair_c0"], wp.float64),
            iface_spring=arr(iface_spring(h), wp.vec4d),
            pair_dashpot=arr(pair_dashpot(h, self.topology.pair_nodes), wp.vec2d),
            # per-interface (tanφ, tanφ_r, softening slopes) only with joints or a fracture band; the scalars otherwise
            iface_law=arr(iface_law(h) if "pair_law" in h else np.zeros((1, 4)), wp.vec4d),
            per_pair_law=1 if "pair_law" in h else 0,
            ledge_n0=arr(h["ledge_n0"].astype(np.int32), wp.int32),
            ledge_n1=arr(h["ledge_n1"].astype(np.int32), wp.int32),
            ledge_pulse=arr(h["ledge_pulse"].astype(np.int32), wp.int32),
            ledge_f0=arr(h["ledge_f0"], wp.vec2d),
            pulses=list(self.pulses),
            stable_dt=self.stable_dt,
            host=h,
            elastic=self.elastic,
            mass_theta=self.mass_theta,
        )
        return m


def pair_dashpot(h: dict, pair_nodes: np.ndarray) -> np.ndarray:
    """(√(m_eff·Kn), √(m_eff·Ks)) per pair [2Q, 2] [kg/s per m], m_eff = m_i m_j/(m_i + m_j) of its two nodes: the
    spring dashpot's coefficients without 2ζ, in the operations of materials.interface.spring_dashpot (so the
    kernel's dashpot is the one that function gives, to the bit)."""
    mi, mj = h["node_mass"][pair_nodes[:, 0]], h["node_mass"][pair_nodes[:, 1]]
    m_eff = mi * mj / (mi + mj)
    return np.stack([np.sqrt(m_eff * h["pair_kn"]), np.sqrt(m_eff * h["pair_ks"])], 1).reshape(-1, 2)


def iface_spring(h: dict) -> np.ndarray:
    """(Kn, Ks, Ac, L0) per interface [Q, 4] from the per-pair host arrays, which give both pairs the same values."""
    cols = [h[k] for k in ("pair_kn", "pair_ks", "pair_ac", "pair_l0")]
    for c in cols:
        if not np.array_equal(c[0::2], c[1::2]):
            raise AssertionError("the two pairs of an interface must share Kn, Ks, Ac and L0")
    return np.stack([c[0::2] for c in cols], 1) if len(cols[0]) else np.zeros((0, 4))


def node_spring_code(topology) -> np.ndarray:
    """2p + (1 if the node is pair p's i node) for each of a node's springs, −1 for none, [N, 2] int32
    (Model.node_spring_code)."""
    p, sign = topology.node_pairs, topology.node_pair_sign
    code = np.where(p >= 0, 2 * p + (sign < 0), -1)
    return code.astype(np.int32)


def iface_law(h: dict) -> np.ndarray:
    """(tanφ, tanφ_r, slope_t, slope_c) per interface [Q, 4] from host["pair_law"], which gives both pairs of an
    interface the same law (the spring kernel reads it once per interface: half the bytes of a per-pair read)."""
    law = h["pair_law"]
    if not np.array_equal(law[0::2], law[1::2]):
        raise AssertionError("the two pairs of an interface must share their friction and softening law")
    return np.ascontiguousarray(law[0::2])


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def cst_stiffness(X: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """Plane-strain CST stiffness matrices A·BᵀDB, shape [E, 6, 6] (dofs x0,y0,x1,y1,x2,y2)."""
    p0, p1, p2 = X[0::3], X[1::3], X[2::3]
    area = 0.5 * _cross(p1 - p0, p2 - p0)
    b = np.stack([p1[:, 1] - p2[:, 1], p2[:, 1] - p0[:, 1], p0[:, 1] - p1[:, 1]], 1) / (2 * area[:, None])
    c = np.stack([p2[:, 0] - p1[:, 0], p0[:, 0] - p2[:, 0], p1[:, 0] - p0[:, 0]], 1) / (2 * area[:, None])
    B = np.zeros((len(area), 3, 6))
    B[:, 0, 0::2] = b
    B[:, 1, 1::2] = c
    B[:, 2, 0::2] = c
    B[:, 2, 1::2] = b
    D = np.array([[lam + 2 * mu, lam, 0], [lam, lam + 2 * mu, 0], [0, 0, mu]])
    return area[:, None, None] * np.einsum("eki,kl,elj->eij", B, D, B)


def has_contact_allowance(rock) -> bool:
    """Whether the stable step of a model of ``rock`` (a RockConfig) allows for one block contact per node: the rock
    can break and block contact is on (METHOD §1.7)."""
    return not rock.unbreakable and rock.block_contact


def contact_stiffness_per_area(h: dict) -> float:
    """Block contact's penalty stiffness per area k_c [Pa/m]: the mean of the springs' k_n per area (cdem/contact.py;
    0 without springs). One value for the whole rock, so on a graded mesh it is below the fine zone's springs."""
    return float(np.mean(h["pair_kn_area"])) if len(h["pair_kn_area"]) else 0.0


def node_tributary_length(X: np.ndarray) -> np.ndarray:
    """Half of each of its element's two edges at each block node [m], shape [N] (X: [N, 2], nodes 3e + k)."""
    L = np.linalg.norm(np.roll(X.reshape(-1, 3, 2), -1, axis=1) - X.reshape(-1, 3, 2), axis=2)   # edge k: k → k+1
    return (0.5 * (L + np.roll(L, 1, axis=1))).reshape(-1)


def element_row_sums(X: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """Absolute row sums of the CST stiffness per node and direction, shape [N, 2]."""
    K = cst_stiffness(X, lam, mu)
    return np.abs(K).sum(axis=2).reshape(-1, 2)
