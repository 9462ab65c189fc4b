"""Central-difference update of the rock nodes with local damping, constraints and dashpots."""

from __future__ import annotations

import warp as wp


@wp.func
def local_damping(f: wp.vec2d, v: wp.vec2d, alpha: wp.float64):
    """Cundall local damping f ← f − α|f|·sign(v), per component (YADE NewtonIntegrator)."""
    return wp.vec2d(f[0] - alpha * wp.abs(f[0]) * wp.sign(v[0]), f[1] - alpha * wp.abs(f[1]) * wp.sign(v[1]))


@wp.kernel
def integrate_nodes(
    node_mass: wp.array(dtype=wp.float64),
    node_bc: wp.array(dtype=wp.int32),
    bc_P: wp.array(dtype=wp.mat22d),
    bc_C: wp.array(dtype=wp.mat22d),
    f: wp.array(dtype=wp.vec2d),
    alpha: wp.float64,
    dt: wp.float64,
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    energy_acc: wp.array(dtype=wp.float64),
):
    """v^{n+½} = v^{n−½} + Δt·f/m, x^{n+1} = x^n + Δt·v^{n+½}.

    Dashpot nodes (Lysmer–Kuhlemeyer, matrix C) use the semi-implicit update
    (m + CΔt/2)v^{n+½} = (m − CΔt/2)v^{n−½} + Δt·f; constrained nodes project v with P.
    Energy absorbed by dashpots and removed by local damping is accumulated in energy_acc[1], [2].
    """
    n = wp.tid()
    m = node_mass[n]
    vi = v[n]
    fi = f[n]
    half = wp.float64(0.5)
    if alpha > wp.float64(0.0):
        fd = local_damping(fi, vi, alpha)
        wp.atomic_add(energy_acc, 2, -wp.dot(fd - fi, vi) * dt)
        fi = fd
    k = node_bc[n]
    vn = vi + fi * (dt / m)
    if k >= 0:
        c = bc_C[k] * (half * dt)
        eye = wp.identity(n=2, dtype=wp.float64)
        lhs = eye * m + c
        rhs = (eye * m - c) @ vi + fi * dt
        vn = bc_P[k] @ (wp.inverse(lhs) @ rhs)
        vm = half * (vi + vn)
        wp.atomic_add(energy_acc, 1, wp.float64(2.0) * wp.dot(vm, c @ vm))
    v[n] = vn
    x[n] = x[n] + vn * dt


def launch_integrate(model, state, dt: float, alpha: float) -> None:
    wp.launch(integrate_nodes, dim=model.node_count,
              inputs=[model.node_mass, model.node_bc, model.bc_P, model.bc_C, state.f,
                      wp.float64(alpha), wp.float64(dt)],
              outputs=[state.x, state.v, state.energy_acc], device=model.device)
