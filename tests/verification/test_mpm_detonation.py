"""T1.2: planar 1D detonation of PETN 1.77 along a slab (periodic strip one cell wide).

Front speed from the position of the p = P_CJ/2 crossing at two times; peak pressure
approaches P_CJ from below under grid refinement (the convergence is printed).
"""

import numpy as np
import pytest

from blastfrac.explosives.library import get_explosive
from blastfrac.materials.cj import cj_state
from blastfrac.mpm import MPMOptions, MPMSolver
from blastfrac.mpm.seeding import slab_1d

P = get_explosive("petn")
CJ = cj_state(P)
L = 0.1  # slab length [m]


def _front(solver, level):
    f = solver.particle_fields()
    o = np.argsort(f["position"][:, 0])
    x, p = f["position"][o, 0], f["pressure"][o]
    k = np.nonzero(p > level)[0].max()
    return x[k] + (p[k] - level) / (p[k] - p[k + 1]) * (x[k + 1] - x[k]), p.max()


def run_slab(ncell):
    spec, x, vol = slab_1d(L, ncell)
    s = MPMSolver.from_arrays(x, vol, spec, P, MPMOptions(), light_time=x[:, 0] / P.D)
    s.grid.set_walls(xmin=0.0, kind="slip")
    t, rec = 0.0, []
    for t_stop in (0.4 * L / P.D, 0.8 * L / P.D):
        while t < t_stop - 1e-15:
            dt = min(s.stable_dt(), t_stop - t)
            s.step(dt, t)
            t += dt
        rec.append((t, *_front(s, 0.5 * CJ.p)))
    (t1, x1, _), (t2, x2, peak) = rec
    return (x2 - x1) / (t2 - t1), peak, s


def test_front_speed_and_peak_convergence():
    rows = []
    for n in (100, 200, 400):
        speed, peak, s = run_slab(n)
        rows.append((n, speed, peak))
        assert s.deactivated_count == 0
    print("\n  cells  front speed/D - 1   peak/P_CJ")
    for n, sp, pk in rows:
        print(f"  {n:5d}  {sp / P.D - 1:+.2e}          {pk / CJ.p:.4f}")
    assert all(abs(sp / P.D - 1) < 0.01 for _, sp, _ in rows)
    peaks = [pk / CJ.p for *_, pk in rows]
    assert all(pk < 1.02 for pk in peaks)  # approached from below (no overshoot)
    assert peaks[0] < peaks[1] < peaks[2]  # converging under refinement
    assert 1 - peaks[-1] < 0.08  # within 8 % of P_CJ at h = L/400 (VALIDATION T1.2: 5-10 %)
    errs = [1 - pk for pk in peaks]
    assert errs[2] / errs[1] < 0.8 and errs[1] / errs[0] < 0.8


@pytest.mark.slow
def test_peak_converges_fine():
    _, peak, _ = run_slab(1600)
    print(f"\n  1600 cells: peak/P_CJ = {peak / CJ.p:.4f}")
    assert 1 - peak / CJ.p < 0.02
