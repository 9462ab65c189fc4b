"""Small reductions used by the solver (stable time step)."""

from __future__ import annotations

import warp as wp

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


@wp.kernel
def max_signal_speed(
    active: wp.array(dtype=wp.int32),
    v: wp.array(dtype=wp.vec2d),
    cs: wp.array(dtype=wp.float64),
    out: wp.array(dtype=wp.float64),
):
    """out[0] = max over active particles of c_p + |v_p| [m/s] (out zeroed by the launcher)."""
    p = wp.tid()
    if active[p] == 0:
        return
    wp.atomic_max(out, 0, cs[p] + wp.length(v[p]))
