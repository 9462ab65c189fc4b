"""VALIDATION §5: vibrating bar (Bardenhagen 2002) — MPM core with a linear-elastic solid.

L = 25 m, E = 100 Pa, rho = 1 kg/m^3, nu = 0 (1D in plane strain), fixed at x = 0, free at
x = L, v(x, 0) = 0.1 sin(pi x / 2L).  First mode: omega = (pi/2L) sqrt(E/rho), T = 4 L / c.
Period from zero crossings of the bar's momentum; energy drift over 10 periods.
"""

import numpy as np

from blastfrac.materials.linear_elastic_mp import LinearElasticMP
from blastfrac.mpm import MPMOptions, MPMSolver
from blastfrac.mpm.seeding import slab_1d

L, E, RHO = 25.0, 100.0, 1.0


def run_bar(ncell, periods=10):
    c = np.sqrt(E / RHO)
    T = 2 * np.pi / (np.pi / (2 * L) * c)
    spec, x, vol = slab_1d(L, ncell)
    v = np.zeros_like(x)
    v[:, 0] = 0.1 * np.sin(np.pi * x[:, 0] / (2 * L))
    s = MPMSolver.from_arrays(x, vol, spec, LinearElasticMP(E, 0.0, RHO), MPMOptions(), v=v)
    s.grid.set_walls(xmin=0.0, kind="fixed")
    dt = 0.2 * spec.h / c
    n = int(round(periods * T / dt))
    e0 = s.energies()["total"]
    ts, ps, es = np.arange(1, n + 1) * dt, np.empty(n), []
    for i in range(n):
        s.step(dt, ts[i] - dt)
        ps[i] = s.total_momentum()[0]
        if i % 200 == 0:
            es.append(s.energies()["total"] / e0 - 1)
    zc = [ts[i] - ps[i] * dt / (ps[i + 1] - ps[i]) for i in range(n - 1) if ps[i] * ps[i + 1] < 0]
    return 2 * np.mean(np.diff(zc)), T, s.energies()["total"] / e0 - 1, np.abs(es).max()


def test_vibrating_bar_period_and_energy():
    rows = [(nc, *run_bar(nc)) for nc in (25, 50, 100)]
    print("\n  cells  period/T - 1   energy drift (10 periods)")
    for nc, Tn, T, drift, _ in rows:
        print(f"  {nc:5d}  {Tn / T - 1:+.4f}       {drift:+.4f}")
    errs = [abs(r[1] / r[2] - 1) for r in rows]
    assert errs[0] > errs[1] > errs[2]  # converges
    assert errs[2] < 0.005  # 0.5 % at 100 cells
    assert abs(rows[2][3]) < 0.01 and rows[2][4] < 0.01  # energy drift < 1 %
