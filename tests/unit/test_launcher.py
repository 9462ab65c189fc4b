"""_warp.Launcher: recorded launches give what wp.launch gives, and follow every change of their arguments.

A replay must run on the arrays, scalars, struct fields and launch size of the call it replaces: a stale
argument would be a silently wrong step, so each kind of change is checked against a plain wp.launch (on a CPU the
replays run through the Launcher's own argument record, whose fields must follow each change).
"""

import numpy as np
import warp as wp

from blastfrac._warp import Launcher, init_warp

init_warp()


@wp.struct
class Scale:
    a: wp.float64
    w: wp.array(dtype=wp.float64)


@wp.kernel
def axpy(x: wp.array(dtype=wp.float64), y: wp.array(dtype=wp.float64), s: wp.float64, k: wp.int32, sc: Scale,
         out: wp.array(dtype=wp.float64)):
    i = wp.tid()
    out[i] = s * x[i] + y[i] + wp.float64(k) + sc.a * sc.w[i]


def _plain(x, y, s, k, sc, n):
    out = wp.zeros(len(x), dtype=wp.float64)
    wp.launch(axpy, dim=n, inputs=[x, y, s, k, sc], outputs=[out])
    return out.numpy()


def test_replays_follow_every_argument_change():
    rng = np.random.default_rng(0)
    n = 16
    x, y, w, w2 = (wp.array(rng.random(n), dtype=wp.float64) for _ in range(4))
    sc = Scale()
    sc.a, sc.w = 0.5, w
    launch = Launcher()
    out = wp.zeros(n, dtype=wp.float64)

    def run(xx, s, k, dim):
        out.zero_()
        launch(axpy, dim=dim, inputs=[xx, y, s, k, sc], outputs=[out])
        return out.numpy().copy()

    assert np.array_equal(run(x, 2.0, 1, n), _plain(x, y, 2.0, 1, sc, n))
    assert launch.records == 1
    assert np.array_equal(run(x, wp.float64(3.0), 4, n), _plain(x, y, 3.0, 4, sc, n))   # scalars changed
    assert np.array_equal(run(x, 3.0, 4, n // 2), _plain(x, y, 3.0, 4, sc, n // 2))     # launch size changed
    sc.a, sc.w = -1.5, w2                                                               # struct fields changed
    assert np.array_equal(run(x, 3.0, 4, n), _plain(x, y, 3.0, 4, sc, n))
    assert launch.records == 1 and launch.replays == 3
    # on a CPU those replays called the kernel with the Launcher's own argument record (_CpuReplay), not Warp's
    assert all(rec[3] is not None for rec in launch._cmds.values())
    x2 = wp.array(rng.random(n), dtype=wp.float64)                                      # another array object
    assert np.array_equal(run(x2, 3.0, 4, n), _plain(x2, y, 3.0, 4, sc, n))
    assert launch.records == 2
    before = out.numpy().copy()
    launch(axpy, dim=0, inputs=[x, y, 1.0, 0, sc], outputs=[out])                       # empty: nothing runs
    assert np.array_equal(out.numpy(), before)


def test_keys_keep_one_record_per_call_site():
    n = 8
    a, b, y = (wp.array(np.full(n, v), dtype=wp.float64) for v in (1.0, 2.0, 0.0))
    sc = Scale()
    sc.a, sc.w = 0.0, y
    launch = Launcher()
    outs = [wp.zeros(n, dtype=wp.float64) for _ in range(2)]
    for _ in range(5):
        for key, (src, out) in enumerate(zip((a, b), outs)):
            launch(axpy, dim=n, inputs=[src, y, 1.0, 0, sc], outputs=[out], key=key)
    assert launch.records == 2 and launch.replays == 8
    assert np.array_equal(outs[0].numpy(), a.numpy()) and np.array_equal(outs[1].numpy(), b.numpy())
