"""Vibration: peak particle velocity (PPV) per rock node, its attenuation law and the damage radius (issue 15).

* **PPV** [m/s]: max over the steps of |v| at each block node, on the half-step velocities, updated by the rock's
  integration kernel as it writes them (cdem/kernels_integrate.peak_speed), written to the ParaView frames as
  ``ppv``.
* **Attenuation.** Nodes are binned by their distance R from the nearest borehole centre (log-spaced rings);
  the median PPV of each ring is fitted with PPV = K·(R/√Q)^(−β) by least squares in log–log, over the rings
  outside ``fit_from`` borehole radii. Q [kg/m] is the charge mass per unit thickness of that hole
  (Σ ρ0·area of the charges in it): in plane strain a hole is a line charge, and the scaled distance of a long
  cylindrical charge is R/√Q (square-root scaling), so K is in m/s·(m/√(kg/m))^β.
* **Damage radius.** PPV_crit = σ_t·c_p/E: the particle velocity of a plane P wave whose strain reaches the
  tensile failure strain σ_t/E (σ_t the rock's tensile strength, c_p its P-wave speed). The damage radius is
  the outermost ring whose median PPV still exceeds PPV_crit [m]; ``damage_beyond_model`` says when that is the
  last ring (the criterion is exceeded up to the model's edge, the radius is then only a lower bound).
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp


class PeakVelocity:
    """The running PPV of every rock node (device array ``ppv`` [N], m/s), which the rock's integration kernel
    updates (CDEMSolver.ppv_out)."""

    def __init__(self, n_nodes: int, device: str):
        self.ppv = wp.zeros(max(1, n_nodes), dtype=wp.float64, device=device)
        self.n, self.device = n_nodes, device

    def values(self) -> np.ndarray:
        return self.ppv.numpy()[: self.n]


def ppv_critical(tensile_strength: float, youngs_modulus: float, p_wave_speed: float) -> float:
    """PPV_crit = σ_t·c_p/E [m/s]."""
    return tensile_strength * p_wave_speed / youngs_modulus


def ring_profile(X: np.ndarray, ppv: np.ndarray, centres: list, r_b: float, n_rings: int = 30) -> dict:
    """Median and max PPV in log-spaced rings of distance R to the nearest centre (from r_b to the farthest node)."""
    c = np.asarray([cc for cc, _ in centres], float).reshape(-1, 2)
    R = np.min(np.linalg.norm(X[:, None, :] - c[None], axis=2), axis=1)
    edges = np.geomspace(r_b, max(R.max(), r_b * 1.01), n_rings + 1)
    idx = np.digitize(R, edges) - 1
    mid, med, mx, cnt = [], [], [], []
    for k in range(n_rings):
        sel = idx == k
        if sel.sum() < 3:
            continue
        mid.append(math.sqrt(edges[k] * edges[k + 1]))
        med.append(float(np.median(ppv[sel])))
        mx.append(float(ppv[sel].max()))
        cnt.append(int(sel.sum()))
    return {"radius": np.array(mid), "median": np.array(med), "max": np.array(mx), "nodes": np.array(cnt)}


def fit_attenuation(R: np.ndarray, ppv: np.ndarray, Q: float) -> dict:
    """PPV = K·(R/√Q)^(−β) by least squares in log–log: {K, beta, r2, points}."""
    ok = (R > 0) & (ppv > 0)
    if ok.sum() < 3 or not Q > 0:
        return {"K": math.nan, "beta": math.nan, "r2": math.nan, "points": int(ok.sum())}
    xs = np.log(R[ok] / math.sqrt(Q))
    ys = np.log(ppv[ok])
    slope, icpt = np.polyfit(xs, ys, 1)
    pred = icpt + slope * xs
    ss = float(np.sum((ys - ys.mean()) ** 2))
    r2 = 1.0 - float(np.sum((ys - pred) ** 2)) / ss if ss > 0 else math.nan
    return {"K": float(math.exp(icpt)), "beta": float(-slope), "r2": r2, "points": int(ok.sum())}


def damage_radius(profile: dict, crit: float) -> tuple[float, bool]:
    """(outermost ring radius whose median PPV exceeds crit [m], whether the outermost ring does too: the damage
    then reaches the model's edge and the radius is a lower bound). NaN if no ring exceeds crit."""
    above = np.flatnonzero(profile["median"] > crit)
    if not len(above):
        return math.nan, False
    return float(profile["radius"][above[-1]]), bool(above[-1] == len(profile["median"]) - 1)


def vibration_report(X: np.ndarray, ppv: np.ndarray, centres: list, charge_per_hole: float, rock,
                     fit_from: float = 3.0) -> tuple[dict, dict]:
    """(summary.json → vibration, the ring profile) for node positions X and their PPV."""
    r_b = min(r for _, r in centres)
    prof = ring_profile(X, ppv, centres, r_b)
    far = prof["radius"] > fit_from * r_b
    fit = fit_attenuation(prof["radius"][far], prof["median"][far], charge_per_hole)
    crit = ppv_critical(rock.tensile_strength, rock.youngs_modulus, rock.p_wave_speed)
    rep = {"ppv_max": float(ppv.max()) if len(ppv) else 0.0, "charge_per_hole": charge_per_hole,
           "attenuation": {**fit, "fit_from_radius": fit_from * r_b,
                           "law": "PPV = K (R/sqrt(Q))^-beta, R [m], Q [kg/m] (line charge, square-root scaling)"},
           "ppv_critical": crit}
    rep["damage_radius"], rep["damage_beyond_model"] = damage_radius(prof, crit)
    return rep, prof
