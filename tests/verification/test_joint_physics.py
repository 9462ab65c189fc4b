"""Pre-existing joints (docs/joints.md): Coulomb sliding on a frictional joint, and plane waves crossing an open
and a bonded joint. References are computed in the tests: the Coulomb strength c_j + σ_n·tanφ_j and its residual
σ_n·tanφ_r,j, and the transmitted amplitude of the same strip without a joint.
"""

import math

import numpy as np
import pytest

from blastfrac.cdem.solver import CDEMSolver
from blastfrac.model.builder import ModelBuilder
from blastfrac.scenario import scenario_from_dict

QUIET = {"simulation": {"progress": False}, "output": {"paraview": False, "figures": False}}


# ----------------------------------------------------------------------------- (1) Coulomb sliding
def _direct_shear(c_j: float, phi: float, phi_r: float, sigma_n: float, k_joint: float = 2e9,
                  W: float = 0.2, H: float = 0.1, h: float = 0.02) -> dict:
    """A W × H block split by a horizontal joint at y = 0 (T = 0, cohesion c_j, friction φ, φ_r): bottom fixed, top
    on rollers, σ_n initialised in the blocks and springs (the in-situ initial state), then a shear force on the
    top edge that grows linearly. The joint is much softer than the blocks (k_joint ≪ G/H), so the shear along it
    is uniform; the top rollers stop the block from rocking, so σ_n stays uniform too.

    Returns the history of the mean joint tractions: τ = |Σ Fs|/W and σ = Σ Fn/W [Pa], and the broken fraction."""
    sc = scenario_from_dict({**QUIET,
        "rock": {"stiffness_mode": "per_area", "kn": 1e12, "ks": 1e12, "tensile_strength": 20e6, "cohesion": 50e6,
                 "friction_angle": 40.0, "residual_friction_angle": 35.0},
        "geometry": {"domain": {"type": "rectangle", "width": W, "height": H}, "mesh_size": h,
                     "joints": [{"segments": [[[-W, 0.0], [W, 0.0]]], "tensile_strength": 0.0, "cohesion": c_j,
                                 "friction_angle": phi, "residual_friction_angle": phi_r,
                                 "kn": k_joint, "ks": k_joint}]},
        "boundaries": {"bottom": {"type": "fixed"}, "top": {"type": "roller"}}})
    m = ModelBuilder(sc).finalize("cpu")
    st, solver = m.state(), CDEMSolver(m, block_contact=True)
    solver.initialise_stress(st, 0.0, -sigma_n, 0.0)
    X, topo = m.host["node_X"], m.topology
    slots = topo.boundary_slots[[i for i, t in enumerate(topo.boundary_slot_tags) if t == "top"]]
    n0, n1 = slots, 3 * (slots // 3) + (slots % 3 + 1) % 3
    L = np.linalg.norm(X[n1] - X[n0], axis=1)
    nodes, share = np.concatenate([n0, n1]), np.concatenate([L, L]) / (2 * L.sum())
    pj = np.flatnonzero(m.host["pair_joint"] >= 0)
    assert m.host["pair_ac"][pj].sum() == pytest.approx(W, rel=1e-12)      # the joint runs across the block
    strength = c_j + sigma_n * math.tan(math.radians(phi))
    rate = 1.4 * strength / 15e-3                                          # reaches the strength after ~11 ms
    dt = 0.8 * m.stable_dt
    t, out, after = 0.0, [], None
    for k in range(int(20e-3 / dt)):
        solver.forces(st, dt, t)
        f = st.f.numpy()                                                   # a view of the CPU array
        np.add.at(f[:, 0], nodes, rate * t * W * share)
        solver.integrate(st, dt)
        t += dt
        if k % 10 == 0:
            F, mode = st.pair_F.numpy()[pj], st.pair_mode.numpy()[pj]
            out.append((rate * t, abs(F[:, 1].sum()) / W, F[:, 0].sum() / W, float(np.mean(mode == 2))))
            if after is None and out[-1][3] == 1.0:
                after = len(out)
            if after is not None and len(out) > after + 20:
                break
    h_ = np.array(out)
    return {"applied": h_[:, 0], "tau": h_[:, 1], "sigma": h_[:, 2], "broken": h_[:, 3], "all_broken": after,
            "rock_broken": int((st.pair_mode.numpy()[m.host["pair_joint"] < 0] > 0).sum())}


@pytest.mark.parametrize("c_j, phi, phi_r, sigma_n", [(1e6, 30.0, 20.0, 2e6), (0.5e6, 35.0, 25.0, 5e6)])
def test_frictional_joint_slides_at_the_coulomb_load(c_j, phi, phi_r, sigma_n):
    """Peak joint shear = c_j + σ_n tanφ_j (sliding onset) and then σ_n tanφ_r,j (residual), within 2 %; the joint's
    friction is its own (the rock's φ = 40°, φ_r = 35° would give other values); σ_n stays uniform."""
    r = _direct_shear(c_j, phi, phi_r, sigma_n)
    peak_ref = c_j + sigma_n * math.tan(math.radians(phi))
    resid_ref = sigma_n * math.tan(math.radians(phi_r))
    i = int(np.argmax(r["tau"]))
    assert r["all_broken"] is not None, "the joint never slid"
    resid = float(np.median(r["tau"][r["all_broken"]:r["all_broken"] + 10]))
    print(f"σn {sigma_n / 1e6:.1f} MPa: peak τ {r['tau'][i] / 1e6:.4f} MPa vs c + σn tanφ {peak_ref / 1e6:.4f} "
          f"({r['tau'][i] / peak_ref - 1:+.2%}), residual {resid / 1e6:.4f} vs σn tanφr {resid_ref / 1e6:.4f} "
          f"({resid / resid_ref - 1:+.2%}); σ at the peak {r['sigma'][i] / 1e6:.4f} MPa")
    assert r["tau"][i] == pytest.approx(peak_ref, rel=0.02)
    assert resid == pytest.approx(resid_ref, rel=0.02)
    assert r["sigma"][i] == pytest.approx(sigma_n, rel=0.01)
    assert r["broken"][max(i - 20, 0)] < 0.5                       # the joint failed as a whole at the peak
    assert r["rock_broken"] == 0


# ----------------------------------------------------------------------------- (2) waves across a joint
STRIP_L, STRIP_H, X_JOINT = 0.2, 0.004, 0.1


def _transmission(joint: dict | None, sign: float, amp: float = 2e6) -> tuple[float, float]:
    """Strip between rollers, a 10 µs triangular pressure pulse of sign `sign` (+1 compression, −1 tension) on the
    left end, viscous right end, and (optionally) a joint across it at x = 0.1 m. Returns the incident amplitude (the
    peak band-mean σxx of the pulse's sign over 0.04–0.06 m, before the reflection comes back) and the transmitted
    one (peak |band-mean σxx| over 0.14–0.16 m) [Pa]."""
    h = STRIP_H
    geom = {"domain": {"type": "rectangle", "width": STRIP_L, "height": 6 * h, "center": [STRIP_L / 2, 0.0]},
            "mesh_size": h}
    if joint is not None:
        geom["joints"] = [{"segments": [[[X_JOINT, -1.0], [X_JOINT, 1.0]]], **joint}]
    pulse = {"type": "table", "times": [0.0, 5e-6, 10e-6], "values": [0.0, sign * amp, 0.0]}
    sc = scenario_from_dict({**QUIET, "geometry": geom,
                             "boundaries": {"left": {"type": "pressure", "pulse": pulse}, "right": {"type": "viscous"},
                                            "top": {"type": "roller"}, "bottom": {"type": "roller"}}})
    m = ModelBuilder(sc).finalize("cpu")
    st, solver = m.state(), CDEMSolver(m)
    X = m.host["node_X"]
    c = (X[0::3] + X[1::3] + X[2::3]) / 3
    inc = np.flatnonzero((c[:, 0] > 0.04) & (c[:, 0] < 0.06))
    tra = np.flatnonzero((c[:, 0] > 0.14) & (c[:, 0] < 0.16))
    t_end, dt, t = 0.16 / sc.rock.p_wave_speed + 12e-6, 0.8 * m.stable_dt, 0.0
    a_i = a_t = 0.0
    while t < t_end:
        solver.forces(st, dt, t)
        solver.integrate(st, dt)
        t += dt
        s = st.sigma.numpy()[:, 0]
        a_i = max(a_i, -sign * s[inc].mean())           # compression is σxx < 0
        a_t = max(a_t, abs(s[tra].mean()))
    return a_i, a_t


def test_waves_across_open_and_bonded_joints():
    """An open joint reflects a tensile pulse (transmitted < 5 % of the incident) and passes a compressive one by
    contact; a joint with the rock's properties is invisible. Both within 3 % of the strip without a joint."""
    rock_like = {"tensile_strength": 10e6, "cohesion": 40e6, "friction_angle": 40.0}     # the default rock's
    ratio = {}
    for name, joint in (("none", None), ("bonded", rock_like), ("open", {"open": True})):
        for sign in (1.0, -1.0):
            a_i, a_t = _transmission(joint, sign)
            ratio[name, sign] = a_t / a_i
    print({f"{k[0]} {'compression' if k[1] > 0 else 'tension'}": round(v, 4) for k, v in ratio.items()})
    assert ratio["none", 1.0] == pytest.approx(1.0, abs=0.03)
    assert ratio["open", -1.0] < 0.05
    for sign in (1.0, -1.0):
        assert ratio["bonded", sign] == pytest.approx(ratio["none", sign], rel=0.03)
    assert ratio["open", 1.0] == pytest.approx(ratio["none", 1.0], rel=0.03)
