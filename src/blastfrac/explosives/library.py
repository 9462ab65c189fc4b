"""Library of JWL explosive sets, with their sources, and the CJ consistency report.

Every set carries the detonation velocity ``D`` used by programmed burn.  Units SI:
rho0 [kg/m^3], D [m/s], A and B [Pa], R1, R2, omega [-], E0 [J/m^3].

Sources
-------
``emulsion``  Yue, Zhou, Feng et al., Computers and Geotechnics 2022, 104629, Table 1
              (who quote An et al., 2018).  Its own CJ state (D ~ 5.5 km/s) does not
              match the quoted D = 4000 m/s; see VALIDATION.md §0.  Kept as published.
``petn``      PETN at 1.77 g/cc, LLNL Explosives Handbook: B.M. Dobratz and
              P.C. Crawford, UCRL-52997 Change 2 (1985), JWL table.  Handbook
              D = 8300 m/s, P_CJ = 33.5 GPa.
``tnt``       TNT at 1.63 g/cc, same handbook (Dobratz & Crawford 1985); D = 6930 m/s,
              P_CJ = 21.0 GPa.  (MPM3D-F90 ``Data/Deto1k.mpm`` uses B = 3.21 GPa,
              E0 = 6.993 GPa, within rounding of these.)
``anfo``      ANFO at 0.931 g/cc, the ANSYS AUTODYN material-library set widely quoted in
              rock-blasting studies (D = 4160 m/s, P_CJ ~ 5.15 GPa).  ANFO is non-ideal:
              treat this set as indicative.
"""

from __future__ import annotations

from typing import Any

from blastfrac.materials.cj import cj_state
from blastfrac.materials.jwl import JWLParams, jwl_pressure_np

GPA = 1.0e9

EXPLOSIVES: dict[str, JWLParams] = {
    "emulsion": JWLParams(rho0=1300.0, D=4000.0, A=214.4 * GPA, B=0.182 * GPA, R1=4.2, R2=0.9, omega=0.15, E0=4.2 * GPA),
    "petn": JWLParams(rho0=1770.0, D=8300.0, A=617.0 * GPA, B=16.926 * GPA, R1=4.4, R2=1.2, omega=0.25, E0=10.1 * GPA),
    "tnt": JWLParams(rho0=1630.0, D=6930.0, A=371.2 * GPA, B=3.231 * GPA, R1=4.15, R2=0.95, omega=0.30, E0=7.0 * GPA),
    "anfo": JWLParams(rho0=931.0, D=4160.0, A=49.46 * GPA, B=1.891 * GPA, R1=3.907, R2=1.118, omega=0.333, E0=2.484 * GPA),
}

ALIASES = {"emulsion_yue2022": "emulsion", "petn_1.77": "petn", "petn177": "petn", "tnt_1.63": "tnt"}

#: relative mismatch between the given D and the JWL set's own D_CJ above which we warn
CJ_WARN_FRACTION = 0.05


def get_explosive(name: str) -> JWLParams:
    """Return the library set ``name`` (case-insensitive; aliases allowed); KeyError if unknown."""
    key = name.strip().lower()
    key = ALIASES.get(key, key)
    if key not in EXPLOSIVES:
        raise KeyError(f"unknown explosive '{name}'; known: {', '.join(sorted(EXPLOSIVES))}")
    return EXPLOSIVES[key]


def cj_report(params: JWLParams, name: str = "custom") -> dict[str, Any]:
    """CJ consistency check of a JWL set, as a plain dict (SI units).

    Keys: name, rho0, D, A, B, R1, R2, omega, E0, p_V1_E0 (pressure at V=1, E=E0),
    D_cj, p_cj, V_cj, u_cj, D_mismatch (D_cj/D - 1), warn (bool), message.
    """
    cj = cj_state(params)
    mismatch = cj.D / params.D - 1.0
    warn = abs(mismatch) > CJ_WARN_FRACTION
    msg = (
        f"JWL set '{name}': own CJ detonation velocity {cj.D:.0f} m/s differs from the given D = "
        f"{params.D:.0f} m/s by {100 * mismatch:+.1f} % (> {100 * CJ_WARN_FRACTION:.0f} %); programmed burn "
        "uses the given D for lighting times only"
        if warn
        else f"JWL set '{name}' is consistent with D = {params.D:.0f} m/s ({100 * mismatch:+.2f} %)"
    )
    return {
        "name": name,
        **{k: getattr(params, k) for k in ("rho0", "D", "A", "B", "R1", "R2", "omega", "E0")},
        "p_V1_E0": float(jwl_pressure_np(1.0, params.E0, params.A, params.B, params.R1, params.R2, params.omega)),
        "D_cj": cj.D,
        "p_cj": cj.p,
        "V_cj": cj.V,
        "u_cj": cj.u,
        "D_mismatch": mismatch,
        "warn": warn,
        "message": msg,
    }
