"""Library of JWL explosive sets, with their sources, and the CJ consistency report.

Every set carries the detonation velocity ``D`` used by programmed burn.  Units SI:
rho0 [kg/m^3], D [m/s], A and B [Pa], R1, R2, omega [-], E0 [J/m^3].

Sources
-------
``emulsion``  Yue, Zhou, Feng, Wang, Peng & Cong, Computers and Geotechnics (2022) 104629
              (doi 10.1016/j.compgeo.2021.104629), Table 1 ("parameters selected for emulsion
              explosive"), which in turn cites An, Suorineni, Xu, Li & Wang, Int. J. Rock Mech.
              Min. Sci. 112 (2018) 84-94 (doi 10.1016/j.ijrmms.2018.10.010).  Its own CJ state
              (D ~ 5.5 km/s, P_CJ ~ 9.9 GPa) does not match the quoted D = 4000 m/s; see
              VALIDATION.md §0.  Kept as published.
``petn``      PETN at 1.77 g/cc: B.M. Dobratz and P.C. Crawford, "LLNL Explosives Handbook:
              Properties of Chemical Explosives and Explosive Simulants", UCRL-52997 Change 2,
              Lawrence Livermore National Laboratory, January 1985, table of JWL parameters of
              the detonation products (A = 6.170 Mbar, B = 0.16926 Mbar, R1 = 4.4, R2 = 1.2,
              omega = 0.25, E0 = 0.101 Mbar cc/cc; D = 0.830 cm/us, P_CJ = 0.335 Mbar).  The
              table number was not checked against the handbook itself.
``tnt``       TNT at 1.63 g/cc, same handbook (Dobratz & Crawford 1985): A = 3.712 Mbar,
              B = 0.03231 Mbar, R1 = 4.15, R2 = 0.95, omega = 0.30, E0 = 0.070 Mbar cc/cc,
              D = 0.693 cm/us, P_CJ = 0.21 Mbar.  The same numbers are the TNT example of the
              Altair Radioss /MAT/JWL documentation (2017.help.altair.com, hwsolvers/matjwl.htm);
              MPM3D-F90 ``Data/Deto1k.mpm`` uses B = 3.21 GPa, E0 = 6.993 GPa, within rounding.
``anfo``      ANFO at 0.931 g/cc, D = 4160 m/s: the JWL set of the ANFO entry of the ANSYS
              AUTODYN material library (A = 49.46 GPa, B = 1.891 GPa, R1 = 3.907, R2 = 1.118,
              omega = 0.333, E0 = 2.484 GPa), which rock-blasting studies run in AUTODYN and
              LS-DYNA widely reuse.  No primary publication (a cylinder-test fit) for this set
              could be located; it is self-consistent (its own CJ point is D_CJ = 4159 m/s,
              P_CJ = 5.15 GPa).  ANFO is non-ideal (D depends strongly on charge diameter and
              confinement): treat this set as indicative, and prefer a cylinder-test fit for the
              product at hand (e.g. the ANFO and emulsion JWL sets of Castedo, Sanchidrian,
              Lopez, Segarra & Santos, "Jones-Wilkins-Lee parameters for civil explosives").
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
