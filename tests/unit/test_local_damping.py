"""Cundall local damping (cdem/kernels_integrate.local_damping): it scales a force component by 1 − α where it drives
the motion and 1 + α where it opposes it, so it only removes power, and a component at rest keeps its force
(sign(0) = 0: with wp.sign, whose sign(0) is 1, a node at rest had its negative force components scaled by 1 + α)."""

import numpy as np
import warp as wp

from blastfrac._warp import init_warp
from blastfrac.cdem.kernels_integrate import local_damping, np_local_damping


@wp.kernel
def _damp(f: wp.array(dtype=wp.vec2d), v: wp.array(dtype=wp.vec2d), alpha: wp.float64, out: wp.array(dtype=wp.vec2d)):
    i = wp.tid()
    out[i] = local_damping(f[i], v[i], alpha)


def _run(f, v, alpha):
    init_warp()
    out = wp.zeros(len(f), dtype=wp.vec2d, device="cpu")
    wp.launch(_damp, len(f), inputs=[wp.array(f, dtype=wp.vec2d), wp.array(v, dtype=wp.vec2d), wp.float64(alpha)],
              outputs=[out], device="cpu")
    return out.numpy()


def test_local_damping_removes_power_and_leaves_a_node_at_rest_alone():
    rng = np.random.default_rng(3)
    f = rng.normal(size=(400, 2))
    v = rng.normal(size=(400, 2))
    v[::4, 0] = 0.0                                   # components at rest, either force sign
    v[1::4, 1] = -0.0
    alpha = 0.8
    got = _run(f, v, alpha)
    assert np.array_equal(got, np_local_damping(f, v, alpha))
    # a component at rest keeps its force exactly
    rest = v == 0.0
    assert rest.sum() > 150 and np.array_equal(got[rest], f[rest])
    # a moving component: |f'| = (1 ∓ α)|f| as the force drives or opposes the motion, and f'·v = f·v − α|f||v|
    moving = ~rest
    expect = np.where(np.sign(f) == np.sign(v), 1 - alpha, 1 + alpha) * np.abs(f)
    assert np.allclose(np.abs(got[moving]), expect[moving], rtol=1e-14)
    assert np.all(got[moving] * v[moving] <= f[moving] * v[moving] + 1e-15)
