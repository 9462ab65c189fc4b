"""Model (static arrays) and State (time-varying arrays) of the rock block system.

Shapes use E elements, N = 3E nodes, Q interfaces, P = 2Q springs (node pairs),
L loaded boundary edges, C constrained/damped nodes. Units SI, forces per unit thickness.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import warp as wp

from ..geometry.mesh import TriMesh
from .topology import Topology


@dataclass
class Model:
    """Static description of the rock on one device.

    node_mass: lumped mass ρA/3 [kg/m], [N]
    node_X: reference (initial) position [m], [N] vec2d
    node_pairs: the (at most two) springs of each node, −1 if none, [N] vec2i
    node_spring_code: the same springs with the node's side, 2p + 1 where the node is the pair's i node (it takes
        −f_pair) and 2p where it is the j node (+f_pair), −1 if none, [N] vec2i: what the block pass reads to add
        the spring forces (8 bytes a node, where node_pairs and a sign vec2d took 24; topology.node_pair_sign)
    node_bc: index into the bc_* arrays or −1, [N] int32
    bc_P: velocity projection of a constrained node (0 fixed, I−nnᵀ roller, I free), [C] mat22d
    bc_C: dashpot matrix of a viscous node [N·s/m per m], [C] mat22d
    elem_area0: initial element area [m²], [E]
    pair_i, pair_j: node indices, [P] int32
    pair_kn, pair_ks: spring stiffness K = k·Ac [N/m per m], [P]
    pair_ac: tributary area Ac (edge length/2, unit thickness) [m], [P]
    iface_spring: (Kn, Ks, Ac, L0) per interface, shared by its two pairs, [Q] vec4d (what the spring kernel reads)
    pair_dashpot: (√(m_eff·Kn), √(m_eff·Ks)) per pair [kg/s per m], m_eff = m_i m_j/(m_i + m_j): the dashpot
        coefficients 2ζ√(m_eff K) without 2ζ (materials.interface.spring_dashpot), [2Q] vec2d
    pair_l0: length of the edge the spring belongs to [m], [P]
    pair_t0, pair_c0: initial tensile strength and cohesion [Pa], [P]
    iface_law: per-interface (tanφ, tanφ_r, slope_t, slope_c), shared by its two pairs, [Q] vec4d, read only when
        per_pair_law = 1 (a model with joints, geometry.joints, or a fracture band, rock.fracture_band_width);
        otherwise a 1-element placeholder and the scalars tan_phi.. slope_c apply. host["pair_law"] holds it per pair
    host["pair_joint"]: joint set of each spring (−1 rock), [P]; host["pair_mode0"]: initial pair_mode (open joints)
    crush: compressive cap of the springs σ_cr [Pa] (rock.crushing_strength), 0 for none; one scalar for all springs
    spring_damping: dashpot ratio ζ beside every loaded spring [-] (materials.interface.spring_dashpot)
    q_quad, q_lin: coefficients of the blocks' artificial bulk viscosity [-] (materials/artificial_viscosity.py)
    ledge_n0, ledge_n1: nodes of loaded boundary edges (n0→n1 runs counter-clockwise around the element), [L]
    ledge_pulse: pulse index or −1, [L]; ledge_f0: constant force on each of its nodes [N/m], [L] vec2d
    """

    mesh: TriMesh
    topology: Topology
    device: str
    lam: float
    mu: float
    density: float
    tan_phi: float
    tan_phi_r: float
    slope_t: float
    slope_c: float
    breakable: int
    crush: float  # compressive cap σ_cr of the springs [Pa], 0: none (rock.crushing_strength)
    node_mass: wp.array
    node_X: wp.array
    node_pairs: wp.array
    node_spring_code: wp.array
    node_bc: wp.array
    bc_P: wp.array
    bc_C: wp.array
    elem_area0: wp.array
    pair_i: wp.array
    pair_j: wp.array
    pair_kn: wp.array
    pair_ks: wp.array
    pair_ac: wp.array
    pair_l0: wp.array
    pair_t0: wp.array
    pair_c0: wp.array
    iface_spring: wp.array
    pair_dashpot: wp.array
    ledge_n0: wp.array
    ledge_n1: wp.array
    ledge_pulse: wp.array
    ledge_f0: wp.array
    pulses: list = field(default_factory=list)
    stable_dt: float = 0.0
    q_quad: float = 0.0
    q_lin: float = 0.0
    spring_damping: float = 0.0
    host: dict = field(default_factory=dict)
    mass_theta: float = 0.0   # consistent-mass fraction θ of the block mass matrices (cdem/kernels_integrate.py)
    elastic: object = None    # model.compliance.ElasticReport: input, block and assembly moduli
    iface_law: wp.array = None  # per-interface friction and softening (joints, fracture band); see the class docstring
    per_pair_law: int = 0

    @property
    def c_p(self) -> float:
        """Plane-strain P-wave speed of the blocks √((λ+2G)/ρ) [m/s]."""
        return ((self.lam + 2.0 * self.mu) / self.density) ** 0.5

    @property
    def element_count(self) -> int:
        return self.mesh.element_count

    @property
    def node_count(self) -> int:
        return 3 * self.mesh.element_count

    @property
    def interface_count(self) -> int:
        return len(self.topology.iface_elems)

    @property
    def spring_count(self) -> int:
        return 2 * self.interface_count

    @property
    def loaded_edge_count(self) -> int:
        return self.ledge_n0.shape[0]

    def state(self) -> "State":
        """A fresh State at rest in the reference configuration."""
        d = self.device
        n, e, p = self.node_count, self.element_count, self.spring_count
        st = State(
            x=wp.clone(self.node_X),
            v=wp.zeros(n, dtype=wp.vec2d, device=d),
            f=wp.zeros(n, dtype=wp.vec2d, device=d),
            sigma=wp.zeros(e, dtype=wp.vec3d, device=d),
            pair_F=wp.zeros(p, dtype=wp.vec2d, device=d),
            pair_force=wp.zeros(p, dtype=wp.vec2d, device=d),
            pair_str=wp.array(np.stack([self.host["pair_t0"], self.host["pair_c0"]], 1), dtype=wp.vec2d, device=d),
            pair_mode=wp.zeros(p, dtype=wp.int32, device=d),
            pair_dropped=wp.zeros(p, dtype=wp.int32, device=d),
            pair_g0=wp.zeros(p, dtype=wp.float64, device=d),
            pair_tbreak=wp.full(p, -1.0, dtype=wp.float64, device=d),
            pair_inelastic=wp.zeros(p, dtype=wp.float64, device=d),
            pair_efrac=wp.zeros(p, dtype=wp.float64, device=d),
            pair_damp=wp.zeros(p, dtype=wp.float64, device=d),
            elem_damp=wp.zeros(e, dtype=wp.float64, device=d),
            elem_absorbed=wp.zeros(e, dtype=wp.float64, device=d),
            ledge_fprev=wp.zeros(2 * self.loaded_edge_count, dtype=wp.vec2d, device=d),
            pulse_values=wp.zeros(max(1, len(self.pulses)), dtype=wp.float64, device=d),
            energy_acc=wp.zeros(4, dtype=wp.float64, device=d),
        )
        mode0 = self.host.get("pair_mode0")
        if mode0 is not None:
            # open joints: broken in tension from t = 0 (their faces interact by contact only)
            st.pair_mode.assign(mode0.astype(np.int32))
            st.pair_tbreak.assign(np.where(mode0 > 0, 0.0, -1.0))
        return st


# energy_acc slots
EXTERNAL_WORK = 0
VISCOUS_ABSORBED = 1
DAMPING_DISSIPATED = 2
CONTACT_DISSIPATED = 3


@dataclass
class State:
    """Time-varying arrays of the rock.

    x: current node position [m], v: node velocity at the last half step [m/s], f: node force [N/m]
    sigma: element Cauchy stress (σxx, σyy, σxy) [Pa]
    pair_F: spring (Fn, Fs) in the local frame [N/m], Fn > 0 compression
    pair_force: force of the spring on its j node in global axes [N/m]
    pair_str: current (T, c) strengths [Pa] (soften when fracture energies are given)
    pair_mode: 0 intact, 1 broken in tension, 2 broken in shear; pair_dropped: 1 once fully separated
    pair_g0: gap at which the broken spring carries no normal force [m]
    pair_tbreak: time of failure [s] (−1 while intact)
    pair_inelastic: work done on the spring so far beyond its stored energy, W − ½Fn²/Kn − ½Fs²/Ks [J/m]: 0 while
    it has stayed elastic (the spring kernel then skips it), its failure's dissipation once broken, plus friction
    after; pair_efrac: energy dissipated by its failure [J/m] (pair_inelastic at the step it broke)
    pair_damp: work its dashpot has dissipated so far [J/m]; elem_damp: work the block's bulk viscosity and the
    local damping of its nodes have dissipated so far [J/m]; elem_absorbed: work its nodes' boundary dashpots have
    absorbed so far [J/m] (one entry per item, written by its own thread only, so no two threads add to one address:
    the sums are taken when the energies are read, analysis/energy.py)
    ledge_fprev: force applied to each loaded-edge node in the previous step (for exact external work)
    pulse_values: current value of each pressure pulse [Pa]
    energy_acc: accumulated external work and contact losses [J/m] (its slots VISCOUS_ABSORBED and
    DAMPING_DISSIPATED stay 0: those terms are in elem_absorbed, pair_damp and elem_damp)
    """

    x: wp.array
    v: wp.array
    f: wp.array
    sigma: wp.array
    pair_F: wp.array
    pair_force: wp.array
    pair_str: wp.array
    pair_mode: wp.array
    pair_dropped: wp.array
    pair_g0: wp.array
    pair_tbreak: wp.array
    pair_inelastic: wp.array
    pair_efrac: wp.array
    pair_damp: wp.array
    elem_damp: wp.array
    elem_absorbed: wp.array
    ledge_fprev: wp.array
    pulse_values: wp.array
    energy_acc: wp.array
