"""Central-difference update of the rock blocks with their mass matrix, local damping, constraints and dashpots.

Mass matrix. Each block owns its three nodes, so its mass matrix is a 3×3 block of its own (per direction):

    M_e = (1 − θ)·M_lumped + θ·M_consistent = m·[(1 − 3θ/4)·I + (θ/4)·J],   m = ρA/3,  J = ones(3, 3)

θ = 0 is the lumped (diagonal) mass; θ = 1 the consistent CST mass; θ = ½ the *averaged* mass
(``rock.mass_matrix``). Lumped mass makes the lattice lag short waves (phase error −(kh)²/24 at low
Courant number), consistent mass makes it lead by twice as much; their average cancels the leading
term (Krieg & Key 1973; Belytschko, Liu & Moran, *Nonlinear Finite Elements*, §9.3), which removes
most of the ringing that a steep front leaves behind it (docs/rock_fronts.md). Because M_e couples only
the element's own nodes, its inverse is exact and local: no global solve, one thread per element.

Step (one thread per element, nodes k = 0, 1, 2 with P_k the velocity projection of a constrained node
(0 fixed, I − n̂n̂ᵀ roller, I free) and D_k = C_k·Δt/2 its Lysmer dashpot):

    (M_e ⊗ I₂ + D) v^{n+½} = (M_e ⊗ I₂ − D) v^{n−½} + Δt·f,   v_k^{n+½} ∈ range(P_k),

solved in closed form: with a = m(1 − 3θ/4), b = mθ/4, H_k = P_k (P_k(aI + D_k)P_k + (I − P_k)a)⁻¹ P_k and
s = Σ_k v_k, the node equations are v_k = H_k (r_k − b·s), so (I + b Σ H_k)s = Σ H_k r_k (a 2×2 solve).
With θ = 0 this is the former node-by-node update exactly.
"""

from __future__ import annotations

import numpy as np
import warp as wp

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


@wp.func
def sign0(x: wp.float64):
    """sign(x) with sign(0) = 0 (wp.sign(0) is 1)."""
    s = wp.float64(0.0)
    if x > wp.float64(0.0):
        s = wp.float64(1.0)
    elif x < wp.float64(0.0):
        s = wp.float64(-1.0)
    return s


@wp.func
def local_damping(f: wp.vec2d, v: wp.vec2d, alpha: wp.float64):
    """Cundall local damping f ← f − α|f|·sign(v), per component (YADE NewtonIntegrator), sign(0) = 0: a component
    at rest keeps its force (with wp.sign, whose sign(0) is 1, a node at rest had a negative force component
    scaled by 1 + α and a positive one by 1 − α; until 2026-12-04)."""
    return wp.vec2d(f[0] - alpha * wp.abs(f[0]) * sign0(v[0]), f[1] - alpha * wp.abs(f[1]) * sign0(v[1]))


def np_local_damping(f, v, alpha: float) -> np.ndarray:
    """NumPy twin of :func:`local_damping` (f, v: [..., 2] [N/m], [m/s])."""
    f, v = np.asarray(f, float), np.asarray(v, float)
    return f - alpha * np.abs(f) * np.sign(v)


@wp.func
def constrained_inverse(P: wp.mat22d, D: wp.mat22d, a: wp.float64):
    """H = P·(P(aI + D)P + (I − P)a)⁻¹·P [1/(kg/m)]: the response of a node of eigen-mass a [kg/m] with
    dashpot D [kg/m] to a force-like term, restricted to the velocities its constraint P allows."""
    eye = wp.identity(n=2, dtype=wp.float64)
    A = eye * a + D
    return P @ wp.inverse(P @ A @ P + (eye - P) * a) @ P


@wp.func
def store_block(v: wp.array(dtype=wp.vec2d), x: wp.array(dtype=wp.vec2d), n0: int,
                w0: wp.vec2d, w1: wp.vec2d, w2: wp.vec2d, dt: wp.float64):
    """Write the new velocities w_k [m/s] of block nodes n0 … n0+2 and move them: x += Δt·w [m]."""
    v[n0] = w0
    v[n0 + 1] = w1
    v[n0 + 2] = w2
    x[n0] = x[n0] + w0 * dt
    x[n0 + 1] = x[n0 + 1] + w1 * dt
    x[n0 + 2] = x[n0 + 2] + w2 * dt


@wp.func
def peak_speed(ppv: wp.array(dtype=wp.float64), n0: int, w0: wp.vec2d, w1: wp.vec2d, w2: wp.vec2d):
    """ppv[n] = max(ppv[n], |w|) for the block's nodes n0 … n0+2 [m/s] (the PPV of analysis/ppv.py).

    Written every step without a branch: while a wave spreads, whether a node's speed has grown is a coin toss
    the CPU cannot predict, and the branch that skipped the write cost more than the write (the shipped confined
    P0 at 1500 steps: the integration 5.5 ms with the branch, 2.6 without; 1.8 with no PPV)."""
    ppv[n0] = wp.max(ppv[n0], wp.length(w0))
    ppv[n0 + 1] = wp.max(ppv[n0 + 1], wp.length(w1))
    ppv[n0 + 2] = wp.max(ppv[n0 + 2], wp.length(w2))


@wp.kernel
def integrate_blocks(
    node_mass: wp.array(dtype=wp.float64),
    node_bc: wp.array(dtype=wp.int32),
    bc_P: wp.array(dtype=wp.mat22d),
    bc_C: wp.array(dtype=wp.mat22d),
    f: wp.array(dtype=wp.vec2d),
    theta: wp.float64,
    alpha: wp.float64,
    dt: wp.float64,
    first: wp.int32,
    track_ppv: wp.int32,
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    elem_absorbed: wp.array(dtype=wp.float64),
    elem_damp: wp.array(dtype=wp.float64),
    ppv: wp.array(dtype=wp.float64),
):
    """v^{n+½} of the three nodes of block e with its mass matrix (module doc), then x^{n+1} = x^n + Δt·v^{n+½}.

    node_mass: ρA/3 of each node [kg/m]; theta: consistent-mass fraction θ [-]; alpha: Cundall local damping [-].
    The energy the boundary dashpots absorb and the local damping removes go to the block's own accounts
    elem_absorbed[e] and elem_damp[e] [J/m] (no two threads write one address). Thread i updates block first + i.
    With track_ppv = 1 each node's peak speed max |v^{n+½}| goes to ppv (one pass over v fewer than a PPV kernel).
    """
    e = wp.tid() + first
    n0 = 3 * e
    half = wp.float64(0.5)
    eye = wp.identity(n=2, dtype=wp.float64)
    zero2 = wp.mat22d(wp.float64(0.0), wp.float64(0.0), wp.float64(0.0), wp.float64(0.0))
    m = node_mass[n0]
    a = m * (wp.float64(1.0) - wp.float64(0.75) * theta)
    b = m * wp.float64(0.25) * theta
    s_old = v[n0] + v[n0 + 1] + v[n0 + 2]
    if alpha == wp.float64(0.0) and node_bc[n0] < 0 and node_bc[n0 + 1] < 0 and node_bc[n0 + 2] < 0:
        # a free block (most of them): H_k = I/a, so s = Σ r_k/(a + 3b) and v_k = (r_k − b s)/a
        q0 = v[n0] * a + s_old * b + f[n0] * dt
        q1 = v[n0 + 1] * a + s_old * b + f[n0 + 1] * dt
        q2 = v[n0 + 2] * a + s_old * b + f[n0 + 2] * dt
        sf = (q0 + q1 + q2) * (wp.float64(1.0) / (a + wp.float64(3.0) * b))
        ia = wp.float64(1.0) / a
        u0 = (q0 - sf * b) * ia
        u1 = (q1 - sf * b) * ia
        u2 = (q2 - sf * b) * ia
        store_block(v, x, n0, u0, u1, u2, dt)
        if track_ppv != 0:
            peak_speed(ppv, n0, u0, u1, u2)
        return
    H0 = eye
    H1 = eye
    H2 = eye
    D0 = zero2
    D1 = zero2
    D2 = zero2
    r0 = wp.vec2d()
    r1 = wp.vec2d()
    r2 = wp.vec2d()
    damped = wp.float64(0.0)
    for k in range(3):
        n = n0 + k
        vi = v[n]
        fi = f[n]
        if alpha > wp.float64(0.0):
            fd = local_damping(fi, vi, alpha)
            damped = damped - wp.dot(fd - fi, vi) * dt
            fi = fd
        P = eye
        D = zero2
        ib = node_bc[n]
        if ib >= 0:
            P = bc_P[ib]
            D = bc_C[ib] * (half * dt)
        H = constrained_inverse(P, D, a)
        r = vi * a + s_old * b - D @ vi + fi * dt
        if k == 0:
            H0 = H
            D0 = D
            r0 = r
        elif k == 1:
            H1 = H
            D1 = D
            r1 = r
        else:
            H2 = H
            D2 = D
            r2 = r
    if alpha > wp.float64(0.0):
        elem_damp[e] = elem_damp[e] + damped
    s = wp.inverse(eye + (H0 + H1 + H2) * b) @ (H0 @ r0 + H1 @ r1 + H2 @ r2)
    w0 = H0 @ (r0 - s * b)
    w1 = H1 @ (r1 - s * b)
    w2 = H2 @ (r2 - s * b)
    # dashpot work with the mid-step velocity, as absorbed by the semi-implicit update
    vm0 = half * (v[n0] + w0)
    vm1 = half * (v[n0 + 1] + w1)
    vm2 = half * (v[n0 + 2] + w2)
    absorbed = wp.dot(vm0, D0 @ vm0) + wp.dot(vm1, D1 @ vm1) + wp.dot(vm2, D2 @ vm2)
    if absorbed != wp.float64(0.0):
        elem_absorbed[e] = elem_absorbed[e] + wp.float64(2.0) * absorbed
    store_block(v, x, n0, w0, w1, w2, dt)
    if track_ppv != 0:
        peak_speed(ppv, n0, w0, w1, w2)


def launch_integrate(model, state, dt: float, alpha: float, launch=wp.launch, first: int = 0, count: int | None = None,
                     key=None, ppv: wp.array | None = None) -> None:
    """Blocks first … first + count − 1 (all by default); key: a Launcher's call site (one per range); ppv: the
    running peak speed per node [m/s] to update, or None."""
    count = model.element_count - first if count is None else count
    site = {} if key is None else {"key": key}
    launch(integrate_blocks, dim=count,
           inputs=[model.node_mass, model.node_bc, model.bc_P, model.bc_C, state.f,
                   wp.float64(model.mass_theta), wp.float64(alpha), wp.float64(dt), first, int(ppv is not None)],
           outputs=[state.x, state.v, state.elem_absorbed, state.elem_damp, state.elem_damp if ppv is None else ppv],
           device=model.device, **site)


def block_kinetic_energy(m, v, theta: float) -> float:
    """½ vᵀ M v [J/m] of all blocks with the mass matrix of the module doc (NumPy; m: node masses [N], v [N, 2])."""
    m = np.asarray(m, float)
    v = np.asarray(v, float)
    a = m[0::3] * (1.0 - 0.75 * theta)
    b = m[0::3] * 0.25 * theta
    sq = np.einsum("ij,ij->i", v, v).reshape(-1, 3).sum(axis=1)
    s = v.reshape(-1, 3, 2).sum(axis=1)
    return float(0.5 * np.sum(a * sq + b * np.einsum("ij,ij->i", s, s)))
