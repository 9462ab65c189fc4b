"""Quasi-static relaxation helper for the static verification cases."""

import numpy as np

from blastfrac.analysis.energy import rock_energies


def relax(model, state, solver, alpha=0.2, tol=1e-9, max_steps=60_000, check_every=500):
    """Run damped steps until kinetic/stored energy < tol; returns the number of steps."""
    dt = 0.8 * model.stable_dt
    for step in range(1, max_steps + 1):
        solver.forces(state, dt, 1.0)
        solver.integrate(state, dt, alpha)
        if step % check_every == 0:
            e = rock_energies(model, state)
            if e["kinetic"] < tol * (e["strain"] + e["springs"]):
                return step
    raise AssertionError(f"not relaxed after {max_steps} steps")


def element_polar(model, state, center=(0.0, 0.0)):
    """Element centroids in polar form and their stresses rotated to (σrr, σθθ, σrθ)."""
    X = model.host["node_X"]
    c = (X[0::3] + X[1::3] + X[2::3]) / 3 - np.asarray(center)
    r = np.hypot(c[:, 0], c[:, 1])
    th = np.arctan2(c[:, 1], c[:, 0])
    s = state.sigma.numpy()
    cs, sn = np.cos(th), np.sin(th)
    srr = s[:, 0] * cs**2 + s[:, 1] * sn**2 + 2 * s[:, 2] * sn * cs
    stt = s[:, 0] * sn**2 + s[:, 1] * cs**2 - 2 * s[:, 2] * sn * cs
    return r, th, srr, stt


def static_pressurised_hole(model, a: float, p: float) -> np.ndarray:
    """Nodal displacements [N, 2] [m] of the intact block–spring model's linear stiffness (one sparse solve)
    under an inner pressure p [Pa] on the hole wall r = a [m] centred at the origin, the outer surface free.

    The pressure acts as p·L/2 per node of each wall edge along the block's outward normal (as the pressure
    boundary does, cdem/boundary.py); three dofs of two far nodes on the x axis hold the rigid modes, and the
    load is self-equilibrated, so their reactions vanish.
    """
    import scipy.sparse.linalg as spla

    from blastfrac.calibration.elastic import stiffness_matrix

    X = model.host["node_X"]
    K = stiffness_matrix(model).tocsr()
    s0 = model.topology.boundary_slots
    s1 = 3 * (s0 // 3) + (s0 % 3 + 1) % 3                  # next node of the same block: edge s0 → s1
    r = np.hypot(X[:, 0], X[:, 1])
    on = (r[s0] < a * (1 + 1e-3)) & (r[s1] < a * (1 + 1e-3))
    s0, s1 = s0[on], s1[on]
    d = X[s1] - X[s0]
    nL = np.stack([d[:, 1], -d[:, 0]], 1)                   # L × outward normal of the block (into the hole)
    assert np.all(np.einsum("ij,ij->i", nL, X[s0] + X[s1]) < 0)
    f = np.zeros_like(X)
    np.add.at(f, s0, -0.5 * p * nL)
    np.add.at(f, s1, -0.5 * p * nL)
    assert np.abs(f.sum(0)).max() < 1e-9 * p * a
    b = r.max()
    i0 = np.argmin(np.hypot(X[:, 0] - b, X[:, 1]))
    i1 = np.argmin(np.hypot(X[:, 0] + b, X[:, 1]))
    free = np.setdiff1d(np.arange(2 * len(X)), [2 * i0, 2 * i0 + 1, 2 * i1 + 1])
    u = np.zeros(2 * len(X))
    u[free] = spla.spsolve(K[free][:, free].tocsc(), f.ravel()[free])
    assert np.abs(K @ u - f.ravel()).max() < 1e-6 * np.abs(f).max()
    return u.reshape(-1, 2)
