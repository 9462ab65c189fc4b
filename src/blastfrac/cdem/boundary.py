"""Boundary loads: pressure pulses and constant (in-situ) tractions on boundary edges."""

from __future__ import annotations

import warp as wp

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


@wp.kernel
def apply_edge_loads(
    ledge_n0: wp.array(dtype=wp.int32),
    ledge_n1: wp.array(dtype=wp.int32),
    ledge_pulse: wp.array(dtype=wp.int32),
    ledge_f0: wp.array(dtype=wp.vec2d),
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    pulse_values: wp.array(dtype=wp.float64),
    dt_prev: wp.float64,
    ledge_fprev: wp.array(dtype=wp.vec2d),
    f: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
):
    """Add p(t)·L on the current outward normal (half per node) plus the constant force f0 [N/m].

    Also accumulates the external work of the previous step's loads, f^{n-1}·v^{n-1/2}·Δt,
    which is exact for the central-difference update x^n = x^{n-1} + Δt·v^{n-1/2}.
    """
    l = wp.tid()
    a = ledge_n0[l]
    b = ledge_n1[l]
    work = (wp.dot(ledge_fprev[2 * l], v[a]) + wp.dot(ledge_fprev[2 * l + 1], v[b])) * dt_prev
    wp.atomic_add(energy_acc, 0, work)
    d = x[b] - x[a]
    force = ledge_f0[l]
    pid = ledge_pulse[l]
    if pid >= 0:
        # outward normal times length of a counter-clockwise block edge is (dy, −dx)
        force = force - wp.float64(0.5) * pulse_values[pid] * wp.vec2d(d[1], -d[0])
    ledge_fprev[2 * l] = force
    ledge_fprev[2 * l + 1] = force
    wp.atomic_add(f, a, force)
    wp.atomic_add(f, b, force)


def launch_edge_loads(model, state, dt_prev: float, launch=wp.launch) -> None:
    if model.loaded_edge_count == 0:
        return
    launch(apply_edge_loads, dim=model.loaded_edge_count,
              inputs=[model.ledge_n0, model.ledge_n1, model.ledge_pulse, model.ledge_f0,
                      state.x, state.v, state.pulse_values, wp.float64(dt_prev), state.ledge_fprev],
              outputs=[state.f, state.energy_acc], device=model.device)
