"""What went wrong when a run blew up: the first non-finite rock node, element and gas particle, and the likely
cause, for the message and the failed summary.json that Simulation writes (its NaN guard, ``Simulation._guard``)."""

from __future__ import annotations

import math

import numpy as np


def diagnose_nonfinite(sim, e: dict) -> tuple[str, dict]:
    """Where the run ``sim`` (a Simulation) blew up, given its energy terms ``e`` [J/m] with a non-finite value: the
    first non-finite rock node, element and gas particle, and the likely causes. Returns (message, details for
    summary.json)."""
    st, X = sim.state, sim.model.host["node_X"]
    bad_terms = [k for k, v in e.items() if not math.isfinite(v)]
    details: dict = {"step": sim.steps, "time": sim.time, "time_step": sim.dt,
                     "stable_time_step": sim.model.stable_dt, "non_finite_energy_terms": bad_terms}
    where: list[str] = []
    x, v, sig = st.x.numpy(), st.v.numpy(), st.sigma.numpy()
    bad_n = np.flatnonzero(~(np.isfinite(x).all(1) & np.isfinite(v).all(1)))
    if len(bad_n):
        n = int(bad_n[0])
        pos = [float(c) for c in X[n]]
        details["node"] = {"index": n, "reference_position": pos, "count": int(len(bad_n))}
        where.append(f"rock node {n} at (x, y) = ({pos[0]:.4g}, {pos[1]:.4g}) m ({len(bad_n)} nodes non-finite)")
    bad_e = np.flatnonzero(~np.isfinite(sig).all(1))
    if len(bad_e):
        k = int(bad_e[0])
        c = X[3 * k:3 * k + 3].mean(axis=0)       # elements own their 3 nodes (blocks: nodes 3k, 3k+1, 3k+2)
        details["element"] = {"index": k, "reference_centroid": [float(c[0]), float(c[1])], "count": int(len(bad_e))}
        where.append(f"element {k} centred at ({c[0]:.4g}, {c[1]:.4g}) m ({len(bad_e)} elements non-finite)")
    if not len(bad_n) and len(v):
        # the state is still finite but its energy sums overflowed: point at the fastest node
        with np.errstate(over="ignore", invalid="ignore"):
            speed = np.hypot(v[:, 0], v[:, 1])
        n = int(np.nanargmax(np.where(np.isfinite(speed), speed, -1.0)))
        pos = [float(c) for c in X[n]]
        details["node"] = {"index": n, "reference_position": pos, "speed": float(speed[n]), "count": 0}
        bad_n = np.array([n])
        where.append(f"no non-finite value in the state yet (the energy sums overflowed); fastest rock node {n} "
                     f"at (x, y) = ({pos[0]:.4g}, {pos[1]:.4g}) m, |v| = {speed[n]:.3g} m/s")
    gas_bad = False
    if sim.gas is not None:
        f = sim.gas.particle_fields()
        ok = np.isfinite(f["position"]).all(1) & np.isfinite(f["velocity"]).all(1) & np.isfinite(f["pressure"]) \
            & np.isfinite(f["internal_energy"])
        bad_p = np.flatnonzero(~ok)
        if len(bad_p):
            gas_bad = True
            i = int(bad_p[0])
            p = f["position"][i]
            details["particle"] = {"index": i, "position": [float(c) for c in p], "count": int(len(bad_p))}
            at = f"at ({p[0]:.4g}, {p[1]:.4g}) m" if np.isfinite(p).all() else "(position non-finite)"
            where.append(f"gas particle {i} {at} ({len(bad_p)} particles non-finite)")
    # likely cause
    causes: list[str] = []
    near_load = False
    if "node" in details:
        loaded = np.unique(np.r_[sim.model.host.get("ledge_n0", []), sim.model.host.get("ledge_n1", [])])
        near_load = bool(len(loaded)) and bool(np.isin(bad_n, loaded.astype(np.int64)).any())
    if gas_bad or "contact_energy" in bad_terms:
        causes.append("the gas-rock contact (lower coupling.stiffness_factor / coupling.contact_stiffness, or "
                      "simulation.dt_safety)")
    if near_load:
        causes.append("a pressure pulse on a loaded boundary or borehole (check its peak [Pa] and rise time)")
    dt_cause = (f"the time step (dt = {sim.dt:.3e} s = {sim.dt / sim.model.stable_dt:.2f} x the stable "
                "rock step; reduce simulation.dt_safety)")
    if sim.dt > sim.model.stable_dt * (1 + 1e-9):
        causes.insert(0, dt_cause)                 # above the stability limit: certainly the time step
    else:
        causes.append(dt_cause)
    details["likely_causes"] = causes
    details["where"] = where
    msg = (f"non-finite energy ({', '.join(bad_terms)}) at step {sim.steps} (t = {sim.time:.4e} s); "
           f"first non-finite: {'; '.join(where) if where else 'no node, element or particle (energy sums only)'}. "
           f"Likely cause: {causes[0]}" + (f"; else {'; '.join(causes[1:])}" if len(causes) > 1 else "")
           + f". The histories up to here and summary.json (status 'failed') are in {sim.out_dir}")
    return msg, details
