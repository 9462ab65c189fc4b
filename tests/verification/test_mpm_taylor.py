"""T1.3: Taylor wave behind a wall-initiated planar detonation of a gamma = 3 explosive.

JWL with A = B = 0, omega = 2 is the polytropic gas p = 2 rho e; with E0 = rho0 D^2/16 its
CJ state is P_CJ = rho0 D^2/4.  Exact solution at time t: for x <= Dt/2, u = 0 and
p = 8/27 P_CJ; for Dt/2 <= x <= Dt, p/P_CJ = ((1 + 2x/(Dt))/3)^3.
"""

import numpy as np

from blastfrac.materials.cj import cj_state
from blastfrac.materials.jwl import JWLParams
from blastfrac.mpm import MPMOptions, MPMSolver
from blastfrac.mpm.seeding import slab_1d

RHO0, D, L = 1600.0, 8000.0, 0.1
P = JWLParams(rho0=RHO0, D=D, A=0.0, B=0.0, R1=1.0, R2=1.0, omega=2.0, E0=RHO0 * D * D / 16)
PCJ = RHO0 * D * D / 4


def test_polytrope_cj_state():
    cj = cj_state(P)
    assert abs(cj.D / D - 1) < 1e-6 and abs(cj.p / PCJ - 1) < 1e-6 and abs(cj.V - 0.75) < 1e-6


def test_taylor_wave_plateau_and_profile():
    spec, x, vol = slab_1d(L, 200)
    s = MPMSolver.from_arrays(x, vol, spec, P, MPMOptions(), light_time=x[:, 0] / D)
    s.grid.set_walls(xmin=0.0, kind="slip")
    t, t_end = 0.0, 0.8 * L / D
    while t < t_end - 1e-15:
        dt = min(s.stable_dt(), t_end - t)
        s.step(dt, t)
        t += dt
    f = s.particle_fields()
    xi = f["position"][:, 0] / (D * t)
    p = f["pressure"] / PCJ
    plateau = p[xi < 0.4].mean()
    ref = np.where(xi <= 0.5, 8 / 27, np.where(xi <= 1.0, ((1 + 2 * xi) / 3) ** 3, 0.0))
    l1 = np.abs(p - ref)[xi < 0.9].mean()
    u_plateau = np.sqrt(np.mean(f["velocity"][xi < 0.4, 0] ** 2))  # rms
    print(f"\n  plateau p/P_CJ = {plateau:.4f} (exact {8 / 27:.4f}, error {plateau / (8 / 27) - 1:+.2%}); L1 behind front = {l1:.4f} P_CJ")
    assert abs(plateau / (8 / 27) - 1) < 0.03
    assert l1 < 0.03
    print(f"  rms u in the plateau = {u_plateau:.1f} m/s (u_CJ = {D / 4:.0f} m/s)")
    assert u_plateau < 0.05 * D / 4  # u ~ 0 in the plateau (u_CJ = D/4); FLIP particle noise ~3 %
