"""Gas-driven piston: MPM products push a free CDEM block along a channel (METHOD §3 coupling check).

Closed form (Lagrange's ballistic approximation): an ideal gas (JWL with A = B = 0, p = ωE/V, γ = 1 + ω)
of length L0 and areal mass m_g at pressure p0 expands isentropically behind a piston of areal mass M:

    (M + m_g/3)·ẍ = p0·(L0/(L0 + x))^γ,      x(0) = ẋ(0) = 0,

where m_g/3 is the kinetic-energy-equivalent mass of a gas column with a linear velocity profile.
Valid while the piston is slow compared with the gas sound speed (ẋ/c0 ≲ 0.1 here) and M ≫ m_g, so that
the gas stays near uniform; 1D flow (slip walls). The ODE is integrated with scipy in the test.
"""

import numpy as np
from scipy.integrate import solve_ivp

from blastfrac.cdem.solver import CDEMSolver
from blastfrac.coupling import GasRockCoupler
from blastfrac.materials.jwl import JWLParams
from blastfrac.model.builder import ModelBuilder
from blastfrac.mpm.grid import GridSpec
from blastfrac.mpm.solver import MPMOptions, MPMSolver
from conftest import scenario
from coupling_helpers import lattice_points, structured_rectangle


def test_gas_piston_follows_lagrange_ballistics():
    L0, H, Lp = 0.02, 0.004, 0.01               # gas length, channel height, piston length [m]
    p0, omega, rho_g = 20e6, 0.4, 50.0          # initial pressure [Pa], ω, gas density [kg/m³]
    gamma = 1.0 + omega
    gas = JWLParams(rho0=rho_g, D=1000.0, A=0.0, B=0.0, R1=4.0, R2=1.0, omega=omega, E0=p0 / omega)
    h, ppc = 0.0005, 2
    spec = GridSpec.from_bounds((0.0, 0.0), (L0 + Lp + 0.01, H), h)
    xg, vol = lattice_points((0.0, 0.0), (L0, H), h / ppc)
    mpm = MPMSolver.from_arrays(xg, vol, spec, gas, MPMOptions(ppc=ppc, burn_mode="instant"), burn=np.ones(len(xg)))
    mpm.grid.set_walls(xmin=0.0, ymin=0.0, ymax=H)

    mesh = structured_rectangle(L0, 0.0, Lp, H, 10, 4)
    sc = scenario(geometry={"domain": {"type": "rectangle", "width": 1.0, "height": 1.0}, "mesh_size": 0.001})
    model = ModelBuilder(sc, mesh=mesh).finalize("cpu")
    st, rock = model.state(), CDEMSolver(model)
    coupler = GasRockCoupler(model, mpm, kc=200 * p0)

    m_node = model.host["node_mass"]
    M = m_node.sum() / H                          # piston mass per unit channel area [kg/m²]
    m_g = rho_g * L0
    t_end = 100e-6
    dt = 0.5 * min(model.stable_dt, coupler.stable_dt(), mpm.stable_dt())
    n = int(t_end / dt)
    x0_cm = (m_node[:, None] * st.x.numpy()).sum(0) / m_node.sum()
    for k in range(n):
        rock.forces(st, dt, k * dt)
        coupler.apply(st, dt)
        coupler.add_reactions(st)
        mpm.to_grid(dt)
        mpm.update_grid(dt)
        rock.integrate(st, dt)
        mpm.to_particles(dt)
        mpm.update_eos(dt, k * dt)
    x_cm = (m_node[:, None] * st.x.numpy()).sum(0) / m_node.sum() - x0_cm
    v_cm = (m_node[:, None] * st.v.numpy()).sum(0) / m_node.sum()

    sol = solve_ivp(lambda t, y: [y[1], p0 * (L0 / (L0 + y[0])) ** gamma / (M + m_g / 3)],
                    (0, n * dt), [0.0, 0.0], rtol=1e-10, atol=1e-14)
    x_ref, v_ref = sol.y[0, -1], sol.y[1, -1]
    c0 = np.sqrt(gamma * p0 / rho_g)
    print(f"piston: x {x_cm[0] * 1e3:.4f} mm vs {x_ref * 1e3:.4f} mm, v {v_cm[0]:.3f} vs {v_ref:.3f} m/s "
          f"(v/c0 = {v_ref / c0:.3f}, expansion x/L0 = {x_ref / L0:.3f}); leaked {mpm.deactivated_count}")
    assert x_ref / L0 > 0.1, "the test must expand the gas noticeably"
    assert abs(x_cm[0] / x_ref - 1) < 0.03
    assert abs(v_cm[0] / v_ref - 1) < 0.03
    assert abs(x_cm[1]) < 1e-3 * x_ref, "1D flow: no sideways drift"
    xp = mpm.x.numpy()
    face = st.x.numpy()[:, 0].min()
    assert xp[:, 0].max() < face + 1e-9, "no gas particle passes the piston face"
