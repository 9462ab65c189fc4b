"""CST blocks: updated-Lagrangian stress update and internal nodal forces.

Each element owns its three nodes (3e, 3e+1, 3e+2), so it *assigns* their force, and adds the forces of their
springs (owner-computes: a node has at most two, ``Model.node_spring_code``) in the same pass; the load and contact stages then
add to it.
"""

from __future__ import annotations

import warp as wp

from ..materials.artificial_viscosity import bulk_viscosity
from ..materials.elastic import jaumann_stress_update

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


@wp.func
def spring_force_sum(acc: wp.vec2d, code: wp.vec2i, pair_force: wp.array(dtype=wp.vec2d)):
    """acc + Σ ±f_pair over the (at most two) springs of a node [N/m], code = Model.node_spring_code (2p + 1: the
    node is pair p's i node, −f_pair; 2p: its j node, +f_pair; −1: none): the owner-computes gather of the spring
    forces, in the block's pass, which then writes each node's force once (a separate gather pass read and wrote
    every node's force again: 2 ms a step of the shipped confined P0's ~27 on one thread). The side is a factor
    ±1.0, not a branch (which side a node is on has no pattern the CPU could predict)."""
    one = wp.float64(1.0)
    two = wp.float64(2.0)
    for k in range(2):
        c = code[k]
        if c >= 0:
            acc = acc + (one - two * wp.float64(c & 1)) * pair_force[c >> 1]
    return acc


@wp.kernel
def eval_element_forces(
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    sigma: wp.array(dtype=wp.vec3d),
    lam: wp.float64,
    mu: wp.float64,
    rho: wp.float64,
    c_p: wp.float64,
    q_quad: wp.float64,
    q_lin: wp.float64,
    dt: wp.float64,
    first: wp.int32,
    springs: wp.int32,
    node_spring_code: wp.array(dtype=wp.vec2i),
    pair_force: wp.array(dtype=wp.vec2d),
    f: wp.array(dtype=wp.vec2d),
    elem_damp: wp.array(dtype=wp.float64),
):
    """σ_e ← Jaumann update with L = Σ v_i ⊗ ∇N_i(x^{n-1/2}); f_i = −A·B_iᵀ(σ − qI) at x^n [N/m] (overwrites f),
    and with springs = 1 f_i += the forces of node i's springs (``spring_force_sum``; the spring kernel must have
    run for every interface first).

    q is the artificial bulk viscosity [Pa] (materials/artificial_viscosity.py) with l = √A; its
    dissipation q·(−tr D)·A·Δt [J/m] goes to the block's own account elem_damp[e]. Thread i updates block first + i.
    """
    e = wp.tid() + first
    n0 = 3 * e
    x0 = x[n0]
    x1 = x[n0 + 1]
    x2 = x[n0 + 2]
    # (y_j − y_k, x_k − x_j) for cyclic (i, j, k): 2A·∇N_i
    g0 = wp.vec2d(x1[1] - x2[1], x2[0] - x1[0])
    g1 = wp.vec2d(x2[1] - x0[1], x0[0] - x2[0])
    g2 = wp.vec2d(x0[1] - x1[1], x1[0] - x0[0])
    two_a = (x1[0] - x0[0]) * (x2[1] - x0[1]) - (x1[1] - x0[1]) * (x2[0] - x0[0])
    # L from the mid-step configuration x^{n-1/2} = x^n − ½Δt·v^{n-1/2}: the area of a triangle is quadratic
    # in its node positions, so the midpoint rule makes tr(L)·Δt the exact relative area change of the step.
    # L taken at x^n instead lets a spinning free block drift in area at zero stress (a fragment in the
    # single-hole example shrank to 4 % of its area in 4500 steps and then went unstable).
    hdt = wp.float64(0.5) * dt
    va = v[n0]
    vb = v[n0 + 1]
    vc = v[n0 + 2]
    ma = x0 - hdt * va
    mb = x1 - hdt * vb
    mc = x2 - hdt * vc
    h0 = wp.vec2d(mb[1] - mc[1], mc[0] - mb[0])
    h1 = wp.vec2d(mc[1] - ma[1], ma[0] - mc[0])
    h2 = wp.vec2d(ma[1] - mb[1], mb[0] - ma[0])
    two_am = (mb[0] - ma[0]) * (mc[1] - ma[1]) - (mb[1] - ma[1]) * (mc[0] - ma[0])
    grad_v = (wp.outer(va, h0) + wp.outer(vb, h1) + wp.outer(vc, h2)) * (wp.float64(1.0) / two_am)
    s = jaumann_stress_update(sigma[e], grad_v, dt, lam, mu)
    sigma[e] = s
    area = wp.float64(0.5) * wp.abs(two_a)
    trD = grad_v[0, 0] + grad_v[1, 1]
    q = bulk_viscosity(trD, rho, wp.sqrt(area), c_p, q_quad, q_lin)
    # with q = 0 (expansion, or no viscosity) both lines leave their values as they are, bit for bit; written
    # without a branch on q > 0, which the CPU mispredicts in a wave field (materials/artificial_viscosity.py)
    s = wp.vec3d(s[0] - q, s[1] - q, s[2])
    elem_damp[e] = elem_damp[e] - q * trD * area * dt
    h = wp.float64(-0.5)
    f0 = h * wp.vec2d(s[0] * g0[0] + s[2] * g0[1], s[2] * g0[0] + s[1] * g0[1])
    f1 = h * wp.vec2d(s[0] * g1[0] + s[2] * g1[1], s[2] * g1[0] + s[1] * g1[1])
    f2 = h * wp.vec2d(s[0] * g2[0] + s[2] * g2[1], s[2] * g2[0] + s[1] * g2[1])
    if springs != 0:
        f0 = spring_force_sum(f0, node_spring_code[n0], pair_force)
        f1 = spring_force_sum(f1, node_spring_code[n0 + 1], pair_force)
        f2 = spring_force_sum(f2, node_spring_code[n0 + 2], pair_force)
    f[n0] = f0
    f[n0 + 1] = f1
    f[n0 + 2] = f2


def launch_element_forces(model, state, dt: float, launch=wp.launch, first: int = 0, count: int | None = None,
                          key=None) -> None:
    """Blocks first … first + count − 1 (all by default), with their nodes' spring forces (the springs of every
    interface must have been evaluated this step); key: a Launcher's call site (one per range)."""
    count = model.element_count - first if count is None else count
    site = {} if key is None else {"key": key}
    launch(eval_element_forces, dim=count,
           inputs=[state.x, state.v, state.sigma, wp.float64(model.lam), wp.float64(model.mu),
                   wp.float64(model.density), wp.float64(model.c_p), wp.float64(model.q_quad),
                   wp.float64(model.q_lin), wp.float64(dt), first, int(model.interface_count > 0),
                   model.node_spring_code, state.pair_force],
           outputs=[state.f, state.elem_damp], device=model.device, **site)
