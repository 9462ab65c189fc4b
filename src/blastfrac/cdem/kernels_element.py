"""CST blocks: updated-Lagrangian stress update and internal nodal forces.

Each element owns its three nodes (3e, 3e+1, 3e+2), so it *assigns* their force; the spring,
load and contact stages then add to it.
"""

from __future__ import annotations

import warp as wp

from ..materials.elastic import jaumann_stress_update


@wp.kernel
def eval_element_forces(
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    sigma: wp.array(dtype=wp.vec3d),
    lam: wp.float64,
    mu: wp.float64,
    dt: wp.float64,
    f: wp.array(dtype=wp.vec2d),
):
    """σ_e ← Jaumann update with L = Σ v_i ⊗ ∇N_i; f_i = −A·B_iᵀσ [N/m] (overwrites f of the 3 nodes)."""
    e = wp.tid()
    n0 = 3 * e
    x0 = x[n0]
    x1 = x[n0 + 1]
    x2 = x[n0 + 2]
    # (y_j − y_k, x_k − x_j) for cyclic (i, j, k): 2A·∇N_i
    g0 = wp.vec2d(x1[1] - x2[1], x2[0] - x1[0])
    g1 = wp.vec2d(x2[1] - x0[1], x0[0] - x2[0])
    g2 = wp.vec2d(x0[1] - x1[1], x1[0] - x0[0])
    two_a = (x1[0] - x0[0]) * (x2[1] - x0[1]) - (x1[1] - x0[1]) * (x2[0] - x0[0])
    inv = wp.float64(1.0) / two_a
    grad_v = (wp.outer(v[n0], g0) + wp.outer(v[n0 + 1], g1) + wp.outer(v[n0 + 2], g2)) * inv
    s = jaumann_stress_update(sigma[e], grad_v, dt, lam, mu)
    sigma[e] = s
    h = wp.float64(-0.5)
    f[n0] = h * wp.vec2d(s[0] * g0[0] + s[2] * g0[1], s[2] * g0[0] + s[1] * g0[1])
    f[n0 + 1] = h * wp.vec2d(s[0] * g1[0] + s[2] * g1[1], s[2] * g1[0] + s[1] * g1[1])
    f[n0 + 2] = h * wp.vec2d(s[0] * g2[0] + s[2] * g2[1], s[2] * g2[0] + s[1] * g2[1])


@wp.kernel
def gather_spring_forces(
    node_pairs: wp.array(dtype=wp.vec2i),
    node_pair_sign: wp.array(dtype=wp.vec2d),
    pair_force: wp.array(dtype=wp.vec2d),
    f: wp.array(dtype=wp.vec2d),
):
    """f_n += Σ sign·f_pair over the (at most two) springs of node n (owner-computes, no atomics)."""
    n = wp.tid()
    p = node_pairs[n]
    s = node_pair_sign[n]
    acc = f[n]
    if p[0] >= 0:
        acc = acc + s[0] * pair_force[p[0]]
    if p[1] >= 0:
        acc = acc + s[1] * pair_force[p[1]]
    f[n] = acc


def launch_element_forces(model, state, dt: float) -> None:
    wp.launch(eval_element_forces, dim=model.element_count,
              inputs=[state.x, state.v, state.sigma, wp.float64(model.lam), wp.float64(model.mu), wp.float64(dt)],
              outputs=[state.f], device=model.device)


def launch_gather_springs(model, state) -> None:
    if model.interface_count == 0:
        return
    wp.launch(gather_spring_forces, dim=model.node_count,
              inputs=[model.node_pairs, model.node_pair_sign, state.pair_force],
              outputs=[state.f], device=model.device)
