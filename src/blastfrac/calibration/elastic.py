"""Elasticity of the block–spring system: the analytic estimate of METHOD §1.2 and the exact static
response of a meshed UCS prism.

Analytic (orientation-averaged) estimate for CST blocks (E, ν) joined by springs kn, ks [Pa/m] on an
interior-edge density ℓ [1/m] (edge length per unit area):
    1/E'_eff = 1/E' + ℓ·(3/(8kn) + 1/(8ks)),   ν'_eff/E'_eff = ν'/E' − ℓ·(1/kn − 1/ks)/8,
with the plane-strain moduli E' = E/(1−ν²), ν' = ν/(1−ν).

Static (:func:`static_moduli`): the linear stiffness matrix of the prism (plane-strain CST blocks plus
every intact spring pair, K = kn·Ac n̂n̂ᵀ + ks·Ac t̂t̂ᵀ) solved once with the loaded faces displaced
by rigid frictionless platens. It is the zero-speed limit of the elastic part of the simulated UCS
test on the same mesh: the undamped quasi-static test reproduces it to ~0.1 % (docs/calibration.md),
and the analytic estimate agrees with it to ~0.2 % on the prisms used here. Springs only add
compliance, so E'_eff ≤ E' of the blocks, always.
"""

from __future__ import annotations

import numpy as np

from .curves import plane_strain_to_3d, three_d_to_plane_strain


def edge_density(model) -> float:
    """ℓ: interior edge length per unit area of a built model [1/m]."""
    return float(model.host["pair_l0"][0::2].sum() / model.host["elem_area0"].sum())


def effective_moduli(E: float, nu: float, ell: float, kn: float, ks: float) -> tuple[float, float]:
    """3D-equivalent (E_eff [Pa], ν_eff) of blocks (E, ν) with springs kn, ks [Pa/m] at density ℓ [1/m]."""
    Ep, nup = three_d_to_plane_strain(E, nu)
    Ep_eff = 1.0 / (1.0 / Ep + ell * (3.0 / (8.0 * kn) + 1.0 / (8.0 * ks)))
    nup_eff = Ep_eff * (nup / Ep - ell * (1.0 / kn - 1.0 / ks) / 8.0)
    return plane_strain_to_3d(Ep_eff, nup_eff)


def effective_moduli_np(E, nu, ell, kn, ks) -> np.ndarray:
    """Vectorised :func:`effective_moduli`, returns [..., 2]."""
    return np.stack(np.broadcast_arrays(*effective_moduli(E, nu, ell, np.asarray(kn, float), np.asarray(ks, float))), -1)


def stiffness_matrix(model):
    """Global linear stiffness [N/m per m of thickness] of the intact block–spring model (scipy CSR,
    dofs 2n, 2n+1 = x, y of node n), in the reference configuration."""
    import scipy.sparse as sp

    from ..model.builder import cst_stiffness

    h = model.host
    X = h["node_X"]
    n_node = len(X)
    Ke = cst_stiffness(X, model.lam, model.mu)                  # [E, 6, 6]
    ne = len(Ke)
    nodes = np.arange(3 * ne).reshape(ne, 3)
    dofs = np.stack([2 * nodes, 2 * nodes + 1], 2).reshape(ne, 6)
    rows, cols, vals = [np.repeat(dofs, 6, 1).ravel()], [np.tile(dofs, (1, 6)).ravel()], [Ke.ravel()]
    pn = model.topology.pair_nodes
    nrm = np.repeat(h["iface_normal"], 2, axis=0)
    tan = np.stack([-nrm[:, 1], nrm[:, 0]], 1)
    kl = (h["pair_kn"][:, None, None] * np.einsum("pi,pj->pij", nrm, nrm)
          + h["pair_ks"][:, None, None] * np.einsum("pi,pj->pij", tan, tan))
    K4 = np.zeros((len(pn), 4, 4))
    K4[:, :2, :2] = K4[:, 2:, 2:] = kl
    K4[:, :2, 2:] = K4[:, 2:, :2] = -kl
    d = np.stack([2 * pn[:, 0], 2 * pn[:, 0] + 1, 2 * pn[:, 1], 2 * pn[:, 1] + 1], 1)
    rows.append(np.repeat(d, 4, 1).ravel())
    cols.append(np.tile(d, (1, 4)).ravel())
    vals.append(K4.ravel())
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(2 * n_node, 2 * n_node))


def static_moduli(spec, strain: float = 1e-5) -> tuple[float, float]:
    """Plane-strain (E' [Pa], ν') of a UCS prism :class:`~.specimens.Specimen` from one linear static solve.

    Rigid frictionless platens: the top/bottom face nodes get uy = ∓strain·H/2, x is free (one bottom
    node is held in x against rigid translation). σ = reaction/width, ε = strain, ν' = widening of the
    side faces (mean node displacement, as in the dynamic test) / width / ε.
    """
    import scipy.sparse.linalg as spla

    if spec.kind != "ucs":
        raise ValueError("static_moduli needs the UCS prism")
    X = spec.model.host["node_X"]
    K = stiffness_matrix(spec.model)
    n = K.shape[0]
    u = np.zeros(n)
    fixed = np.zeros(n, bool)
    d = 0.5 * strain * spec.height
    fixed[2 * spec.top + 1], u[2 * spec.top + 1] = True, -d
    fixed[2 * spec.bottom + 1], u[2 * spec.bottom + 1] = True, d
    fixed[2 * spec.bottom[np.argmin(np.abs(X[spec.bottom, 0]))]] = True
    free = ~fixed
    Kf = K[free]
    u[free] = spla.spsolve(Kf[:, free].tocsc(), -(Kf[:, fixed] @ u[fixed]))
    f = K @ u
    sigma = -float(f[2 * spec.top + 1].sum()) / spec.width
    ux = u[0::2]
    lateral = float(ux[spec.right].mean() - ux[spec.left].mean()) / spec.width
    return sigma / strain, lateral / strain
