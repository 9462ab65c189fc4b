"""Gas in cracks (coupling/crack_gas.py) against the classical solutions (docs/validation.md §6):

* a Griffith crack of half-length a under internal pressure p opens as w(x) = 4p(1 − ν²)/E·√(a² − x²) (plane
  strain): the crack-cell face loads on the block–spring rock, three meshes, the error falling with h;
* the flow through a straight channel of fixed aperture between two reservoirs follows the cubic law
  ṁ = ρ w³ Δp/(12 μ ℓ), and doubling the aperture multiplies it by 8;
* one intact interface in the channel stops the flow;
* a coupled blast with crack gas conserves the gas mass to round-off and closes the energy budget within 1 %,
  and every crack cell holding gas is joined to a mouth at the borehole wall through broken interfaces.
"""

import math

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from blastfrac.calibration.elastic import stiffness_matrix
from blastfrac.coupling.crack_gas import CrackGas
from blastfrac.materials.jwl import jwl_a_np
from blastfrac.model.builder import ModelBuilder
from conftest import ROCK, scenario
from verification.crack_helpers import break_interfaces, emulsion, interfaces_on_segment, plate_with_crack

E, NU = ROCK["youngs_modulus"], ROCK["poisson_ratio"]


def _model(mesh, width):
    sc = scenario(rock={"spring_penalty": 20.0},
                  geometry={"domain": {"type": "rectangle", "width": width, "height": width}, "mesh_size": width / 20})
    m = ModelBuilder(sc, mesh).finalize("cpu")
    return m, m.state()


# ----------------------------------------------------------------------------- Griffith crack
def _griffith_opening(n_per_a: int, a=0.01, width=0.2, p=10e6):
    """Static opening of the pressurised crack at its vertices: (x, w, w_exact, Σ upward face force / (2ap))."""
    m, st = _model(plate_with_crack(width, a, a / n_per_a, width / 20), width)
    q = interfaces_on_segment(m, -a, a)
    break_interfaces(st, q)
    cg = CrackGas(m, None, viscosity=1e-4, min_aperture=1e-12, mouth_radius=0.0, material=emulsion(), p_max=1e15)
    cg.set_fixed_pressure(q, p)
    st.f.zero_()
    cg.apply(st, 0.0)                                       # face loads of the cells at the reference positions
    cg.add_loads(st)
    f = st.f.numpy()
    lift = f[f[:, 1] > 0, 1].sum() / (2 * a * p)
    h = m.host
    kn, ks = h["pair_kn"].copy(), h["pair_ks"].copy()
    cut = np.r_[2 * q, 2 * q + 1]
    h["pair_kn"][cut] = h["pair_ks"][cut] = 0.0              # the broken springs carry no tension
    K = stiffness_matrix(m).tocsr()
    h["pair_kn"][:], h["pair_ks"][:] = kn, ks
    X = h["node_X"]
    b = width / 2
    i0 = np.argmin(np.hypot(X[:, 0] - b, X[:, 1] - b))
    i1 = np.argmin(np.hypot(X[:, 0] + b, X[:, 1] - b))
    free = np.setdiff1d(np.arange(2 * len(X)), [2 * i0, 2 * i0 + 1, 2 * i1 + 1])   # rigid modes; load self-balanced
    u = np.zeros(2 * len(X))
    u[free] = spla.spsolve(K[free][:, free].tocsc(), f.ravel()[free])
    u = u.reshape(-1, 2)
    upper = np.repeat(((X[0::3] + X[1::3] + X[2::3]) / 3)[:, 1] > 0, 3)
    on = (np.abs(X[:, 1]) < 1e-12) & (np.abs(X[:, 0]) < a * (1 - 1e-9))
    xs = np.unique(np.round(X[on, 0], 12))
    w = np.array([u[on & upper & (np.abs(X[:, 0] - x) < 1e-11), 1].mean()
                  - u[on & ~upper & (np.abs(X[:, 0] - x) < 1e-11), 1].mean() for x in xs])
    w_exact = 4 * p * (1 - NU**2) / E * np.sqrt(a * a - xs**2)
    return xs, w, w_exact, lift, 4 * p * (1 - NU**2) / E * a


def test_griffith_crack_opening_converges():
    """Crack faces loaded by the cells' p·∂V/∂x: the load is p per unit face length (Σ lift = 2ap exactly), and
    the opening converges to Sneddon's ellipse, the rms error at first order in h (a/8, a/16, a/32). Reference:
    infinite plate; the 2a/W = 0.1 plate opens ≈ 0.5 % more (secant correction), below the finest error."""
    errs, centre = [], []
    for n in (8, 16, 32):
        xs, w, we, lift, w0 = _griffith_opening(n)
        assert lift == pytest.approx(1.0, rel=1e-12)
        rms = math.sqrt(np.mean((w - we) ** 2)) / w0
        c = np.argmin(np.abs(xs))
        errs.append(rms)
        centre.append(w[c] / we[c] - 1)
        print(f"Griffith h = a/{n}: w(0) {centre[-1]:+.2%}, rms error {rms:.2%} of w(0), "
              f"max {np.abs(w - we).max() / w0:.2%} (at the tips)")
    assert errs[1] < 0.65 * errs[0] and errs[2] < 0.65 * errs[1]
    assert errs[2] < 0.015
    assert abs(centre[2]) < 0.01


# ----------------------------------------------------------------------------- channel flow
def _gas_state(P, rho: float, p: float, vol: float):
    """(mass [kg/m], internal energy [J/m]) of products at density ρ and pressure p filling vol [m²] (JWL)."""
    m = rho * vol
    V = P.rho0 / rho
    E_v = (p - jwl_a_np(V, P.A, P.B, P.R1, P.R2, P.omega)) * V / P.omega     # per unit initial volume
    return m, E_v * m / P.rho0


def _channel(w: float, blocked: bool = False, steps: int = 2000, mu=1e-2, rho=20.0, p1=10.0e6, dp=0.1e6):
    """A 12-cell straight crack opened to aperture w [m], its end cells held at p1 and p1 − dp (the inside starts
    on the linear profile): mass flux through the middle path after ``steps`` [kg/(m·s)], its cubic-law value,
    and the gas mass in the second half. With ``blocked`` the middle interface stays intact and the second half
    starts empty."""
    a, width = 0.006, 0.06
    m, st = _model(plate_with_crack(width, a, 1e-3, 0.01), width)
    q = interfaces_on_segment(m, -a, a)
    mid = len(q) // 2
    break_interfaces(st, np.delete(q, mid) if blocked else q)
    X = m.host["node_X"]
    upper = np.repeat(((X[0::3] + X[1::3] + X[2::3]) / 3)[:, 1] > 0, 3)
    x = X.copy()
    x[upper, 1] += w                                       # the upper half lifted: every cell opens by w
    st.x.assign(x)
    P = emulsion()
    cg = CrackGas(m, None, viscosity=mu, min_aperture=1e-9, mouth_radius=0.0, rebuild_interval=5, material=P,
                  p_max=1e12)
    L = cg.host_length
    centres = 0.5 * (X[m.topology.pair_nodes[0::2, 0]] + X[m.topology.pair_nodes[1::2, 0]])
    ell = centres[q[-1], 0] - centres[q[0], 0]
    gamma = 1.3                                            # ≈ ρc²/p of these products; only sets the start
    for c in q:
        s = (centres[c, 0] - centres[q[0], 0]) / ell
        pc = p1 - s * dp
        cg.set_cell_state([c], *_gas_state(P, rho * (pc / p1) ** (1 / gamma), pc, w * L[c]))
    if blocked:
        cg.set_cell_state(q[mid:], 0.0, 0.0)
    ends = [q[0], q[-1]]
    held = [(cg.gas.mass.numpy()[c], cg.gas.energy.numpy()[c]) for c in ends]
    D = w**2 * p1 * gamma / (12 * mu)                      # diffusivity of the linearised cubic-law flow [m²/s]
    dt = 0.04 * np.min(L[q]) ** 2 / D
    for _ in range(steps):
        mass, energy = cg.gas.mass.numpy(), cg.gas.energy.numpy()
        for c, (mc, ec) in zip(ends, held):
            mass[c], energy[c] = mc, ec
        cg.gas.mass.assign(mass)
        cg.gas.energy.assign(energy)
        cg.apply(st, dt)
    lk = cg.links
    n = int(lk.count.numpy()[0])
    a_, b_, dm = lk.a.numpy()[:n], lk.b.numpy()[:n], lk.dm.numpy()[:n]
    sel = ((a_ == q[mid - 1]) & (b_ == q[mid])) | ((a_ == q[mid]) & (b_ == q[mid - 1]))
    flux = abs(dm[sel].sum()) / dt if sel.any() else 0.0
    p = cg.gas.pres.numpy()
    rho_mean = np.mean(cg.gas.mass.numpy()[q] / (w * L[q]))
    cubic = rho_mean * w**3 * (p[ends[0]] - p[ends[1]]) / (12 * mu * ell)
    far = cg.gas.mass.numpy()[q[mid:-1]].sum()
    return flux, cubic, far


def test_channel_flow_follows_the_cubic_law():
    """Steady viscous flow between two held reservoirs through a 12 mm crack of aperture w = 20 and 40 µm: the
    mass flux matches ρ̄w³Δp/(12μℓ) (Δp/p = 1 %: the gas is nearly incompressible along the channel), and the
    ratio of the two fluxes is 2³."""
    f1, c1, _ = _channel(20e-6)
    f2, c2, _ = _channel(40e-6)
    print(f"channel: w = 20 µm flux {f1:.4e} vs cubic law {c1:.4e} ({f1 / c1 - 1:+.2%}); "
          f"w = 40 µm {f2:.4e} vs {c2:.4e} ({f2 / c2 - 1:+.2%}); ratio {f2 / f1:.3f} (8)")
    assert f1 == pytest.approx(c1, rel=0.02)
    assert f2 == pytest.approx(c2, rel=0.02)
    assert f2 / f1 == pytest.approx(8.0, rel=0.03)


def test_no_flow_through_an_intact_interface():
    """The same channel with its middle interface intact: no gas reaches the far half."""
    flux, _, far = _channel(20e-6, blocked=True, steps=500)
    assert far == 0.0 and flux == 0.0


# ----------------------------------------------------------------------------- coupled blast
@pytest.fixture(scope="module")
def blast_with_crack_gas(tmp_path_factory):
    from verification.test_coupled_blast import R_B, ROCK as BLAST_ROCK
    from blastfrac.scenario import scenario_from_dict
    from blastfrac.simulation import Simulation

    h = R_B / 5
    sc = scenario_from_dict({
        "title": "small coupled blast with crack gas",
        "simulation": {"end_time": 12e-6, "progress": False},
        "output": {"paraview": False, "figures": False},
        "rock": {**BLAST_ROCK, "bulk_viscosity_linear": 0.02, "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.15,
                 "tensile_fracture_energy": 50.0, "shear_fracture_energy": 500.0},
        "geometry": {"domain": {"type": "rectangle", "width": 0.06, "height": 0.06}, "mesh_size": 6 * h,
                     "mesh_size_near": h, "refinement_distance": 0.02,
                     "boreholes": [{"center": [0.0, 0.0], "radius": R_B}]},
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
        "explosive": {"name": "emulsion", "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": R_B}],
                      "grid": {"cell_size": h, "points_per_cell": 2,
                               "bounds": [[-6 * R_B, -6 * R_B], [6 * R_B, 6 * R_B]]}},
        "crack_gas": {"enabled": True},
    })
    sim = Simulation(sc, out_dir=tmp_path_factory.mktemp("crack_gas_blast"))
    m0 = float(sim.gas.mass.numpy().sum())
    summary = sim.run()
    return sim, summary, m0


def test_blast_crack_gas_conserves_mass_and_energy(blast_with_crack_gas):
    """Gas mass: particles + cracks = the charge's mass to round-off; the energy budget (which now holds the crack
    gas's internal energy, and the rock the work it did) closes within 1 %; gas did enter the cracks."""
    sim, summary, m0 = blast_with_crack_gas
    cg = sim.crack_gas.report()
    m_now = float(sim.gas.mass.numpy().sum()) + cg["mass"]
    rel = summary["energy"]["budget_error_relative"]
    print(f"crack gas: {cg['pressurised_cells']} cells at ≥ 1 MPa ({cg['cells_with_gas']} with gas), {cg['mass'] / m0:.2%} of the charge mass, "
          f"{cg['internal_energy']:.1f} J/m, p_max {cg['max_pressure'] / 1e6:.0f} MPa; budget error {rel:+.3%}")
    assert cg["pressurised_cells"] > 0 and cg["mass"] > 1e-3 * m0
    assert m_now == pytest.approx(m0, rel=1e-12)
    assert abs(rel) < 0.01
    assert summary["energy"]["crack_gas"] == pytest.approx(cg["internal_energy"])


def test_blast_crack_gas_only_in_cracks_joined_to_the_hole(blast_with_crack_gas):
    """Every cell holding gas is a broken interface joined to a borehole-wall vertex through broken interfaces
    (graph search over the mesh's vertices, independent of the stage's own path lists): intact rock passes none."""
    sim, _, _ = blast_with_crack_gas
    m = sim.model
    pn, nv = m.topology.pair_nodes, m.topology.node_vertex
    mode = sim.state.pair_mode.numpy()
    broken = (mode[0::2] > 0) & (mode[1::2] > 0)
    mass = sim.crack_gas.gas.mass.numpy()[: len(broken)]
    assert np.all(broken[mass > 0])
    va, vb = nv[pn[0::2, 0]], nv[pn[1::2, 0]]
    X = m.mesh.vertices
    wall = set(np.flatnonzero(np.hypot(X[:, 0], X[:, 1]) < 1.01 * 0.003).tolist())
    adj: dict[int, list[int]] = {}
    for q in np.flatnonzero(broken):
        adj.setdefault(int(va[q]), []).append(int(vb[q]))
        adj.setdefault(int(vb[q]), []).append(int(va[q]))
    seen, stack = set(wall & set(adj)), list(wall & set(adj))
    while stack:
        for u in adj[stack.pop()]:
            if u not in seen:
                seen.add(u)
                stack.append(u)
    filled = np.flatnonzero(mass > 0)
    assert all(int(va[q]) in seen for q in filled)
