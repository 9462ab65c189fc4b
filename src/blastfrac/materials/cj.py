"""Chapman–Jouguet state of a JWL set, from its own Hugoniot (VALIDATION.md §1).

On the products' Hugoniot centred on the unreacted state (V=1, p=0, E=E0),
E = E0 + p (1 - V) / 2; inserting it in p = a(V) + w E / V gives

    p_H(V) = (a(V) + w E0 / V) / (1 - w (1 - V) / (2 V)).

The Rayleigh line through the initial state has slope rho0 D^2, so
D^2(V) = p_H(V) / (rho0 (1 - V)); the CJ point is the minimum of D^2 over V in (0, 1)
(the tangency of the Rayleigh line with the Hugoniot).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from blastfrac.materials.jwl import JWLParams, jwl_a_np


@dataclass(frozen=True)
class CJState:
    """CJ state: D [m/s], p [Pa], V [-] (relative volume), u [m/s] particle velocity, E [J/m^3]."""

    D: float
    p: float
    V: float
    u: float
    E: float


def hugoniot_pressure(V, P: JWLParams):
    """Products' Hugoniot pressure p_H(V) [Pa] centred on (1, 0, E0)."""
    V = np.asarray(V, dtype=np.float64)
    return (jwl_a_np(V, P.A, P.B, P.R1, P.R2, P.omega) + P.omega * P.E0 / V) / (1.0 - P.omega * (1.0 - V) / (2.0 * V))


def cj_state(P: JWLParams) -> CJState:
    """Minimise D^2 = p_H/(rho0 (1-V)) over V; returns the CJ state of the JWL set."""

    def d2(V: float) -> float:
        return float(hugoniot_pressure(V, P) / (P.rho0 * (1.0 - V)))

    # the Hugoniot denominator vanishes at V = w/(2+w); stay to the right of it
    v_lo = P.omega / (2.0 + P.omega) + 1e-6
    grid = np.linspace(v_lo + 1e-4, 1.0 - 1e-4, 2001)
    vals = np.array([d2(v) for v in grid])
    vals[~np.isfinite(vals) | (vals <= 0)] = np.inf
    k = int(np.argmin(vals))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    res = minimize_scalar(d2, bounds=(lo, hi), method="bounded", options={"xatol": 1e-13})
    V = float(res.x)
    D = float(np.sqrt(res.fun))
    p = float(hugoniot_pressure(V, P))
    return CJState(D=D, p=p, V=V, u=D * (1.0 - V), E=P.E0 + 0.5 * p * (1.0 - V))
