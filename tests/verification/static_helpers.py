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
