"""A particle that leaves the grid, or blows up, is deactivated and counted (mpm/kernels_g2p.py,
update_particle_kinematics), whatever the device does with a float that does not fit an int.

The out-of-grid test used to convert the stencil's base coordinate to an int first. On a CPU a NaN or huge
coordinate converts to INT_MIN, so such a particle was deactivated; on a GPU the conversion saturates (NaN to 0,
+huge to INT_MAX), the particle would stay active and scatter out of the grid. The test is now done in floating
point; these cases pin what it must give, on a periodic axis too (where there is no edge to leave by).
"""

import numpy as np
import warp as wp

from blastfrac.explosives.library import get_explosive
from blastfrac.mpm import MPMOptions, MPMSolver
from blastfrac.mpm.kernels_g2p import update_particle_kinematics
from blastfrac.mpm.seeding import slab_1d

F64 = wp.float64


def _kinematics(solver, v_pic, dt):
    """One update_particle_kinematics launch with the grid's velocities at rest and the particles' v_pic [m/s]."""
    s, g = solver, solver.grid
    g.vel.zero_()
    s.v_pic.assign(v_pic)
    s._deactivated.zero_()
    wp.launch(update_particle_kinematics, dim=s.n,
              inputs=[s.active, s.mass, g.vel, s.v_pic, s.geo, F64(dt)],
              outputs=[s.x, s.vol, s.vol_prev, s.rho, s.grad_v, s._deactivated, g.extent], device=s.device)
    return s.active.numpy(), s.deactivated_count


def test_leaving_or_blown_up_particles_are_deactivated_and_counted():
    spec, x, vol = slab_1d(0.01, 10)                   # h = 1 mm, nx = 17 nodes along x, periodic in y
    s = MPMSolver.from_arrays(x, vol, spec, get_explosive("petn"), MPMOptions(), light_time=np.zeros(len(x)))
    n, h, dt = s.n, spec.h, 1e-7
    x0 = s.x.numpy().copy()
    v = np.zeros((n, 2))
    # one step of dt moves a particle by v·dt: to the first valid base cell (f = 1/2 exactly) and past the last
    # one (f = nx − 3/2), by a NaN, by a huge value, along the periodic y axis by NaN, by a finite jump and by
    # a huge one
    fx = (x0[:, 0] - spec.x0) / h
    k_lo, k_hi = int(np.argmin(fx)), int(np.argmax(fx))
    v[k_lo, 0] = (0.5 - fx[k_lo]) * h / dt             # lands on f = 1/2: still inside
    v[k_hi, 0] = (spec.nx - 1.5 - fx[k_hi]) * h / dt   # lands on f = nx − 3/2: base nx − 2, out
    v[3] = (np.nan, 0.0)
    v[5] = (1e300, 0.0)
    v[7] = (0.0, np.nan)
    v[9] = (0.0, 3.7 * h / dt)                         # wraps around the periodic axis: inside
    v[11] = (0.0, 1e300)                               # wraps to a huge remainder: out
    active, count = _kinematics(s, v, dt)
    out = {k_hi, 3, 5, 7, 11}
    assert count == len(out)
    assert sorted(np.flatnonzero(active == 0)) == sorted(out)
    xs = s.x.numpy()
    assert np.isclose((xs[k_lo, 0] - spec.x0) / h, 0.5) and 0.0 <= xs[9, 1] < spec.ny * h
