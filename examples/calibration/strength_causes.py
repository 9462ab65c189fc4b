"""Why the Table 3 strengths differ from Table 4: cheap, decisive experiments (examples/calibration/README.md).

    .venv/bin/python examples/calibration/strength_causes.py arc rule ucs stiff ucs1

Groups (each prints one JSON line per run, then a Markdown table):
- ``arc``:  Brazilian loading geometry on the paper disc (2144 triangles): conforming jaws with loading
  arcs 2α = 5…45°, conforming jaw without an arc limit, ISRM jaws (1.5 R) and flat platens.
- ``rule``: which spring criterion sets σt (paper disc, 15° arc): Table 3, tension only (c = 10 GPa,
  so Mohr–Coulomb never fires), Mohr–Coulomb only (T = 10 GPa), and T and c sweeps.
- ``ucs``:  the same switches for the UCS on the ×2 prism (888 triangles; ×2 and ×1 UCS agree within
  1.3 %, mesh study), φ sweep at c = 26 MPa, bonded platens.
- ``stiff``: the stiffness definition: kn, ks ×½ and ×2 (disc and ×2 prism).
- ``ucs1``: Table 3, Mohr–Coulomb only and bonded platens on the paper prism (3498 triangles).

Continuum references printed with each row (spring criteria applied to the *continuum* stress of the
test, every interface orientation present):
- Brazilian centre (σ_x = +σt, σ_y = −3σt): tension breaks the vertical interfaces at σt = T;
  Mohr–Coulomb breaks interfaces at 15° to the loaded diameter at σt = c·cosφ/(2 − sinφ)
  (11.46 MPa for c = 26 MPa, φ = 60°). The smaller one governs.
- Uniaxial compression: no interface is in tension; Mohr–Coulomb at UCS = 2c·cosφ/(1 − sinφ) (194.1 MPa).
Same runs as ``blastfrac calibrate examples/calibration/scenario.toml --only brazilian|ucs`` with
``--loading-arc``, ``--jaw-ratio``, ``--platens``, ``--mesh-size`` and ``--set rock.KEY=VALUE``.
"""

from __future__ import annotations

import json
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from blastfrac.calibration import LoadSettings, run_brazilian, run_ucs
from blastfrac.calibration.brazilian import brazilian_settings
from blastfrac.calibration.specimens import default_ucs_mesh_size
from blastfrac.scenario import load_scenario

OFF = 10e9   # Pa: a strength this large never fires (switches a criterion off)


def sigma_t_mc(c: float, phi: float) -> float:
    """Brazilian centre stress at which Mohr–Coulomb first breaks an interface [Pa]."""
    p = math.radians(phi)
    return c * math.cos(p) / (2.0 - math.sin(p))


def ucs_mc(c: float, phi: float) -> float:
    p = math.radians(phi)
    return 2.0 * c * math.cos(p) / (1.0 - math.sin(p))


def hondros_factor(arc_deg: float) -> float:
    """Centre stress / (2P/πD) for a uniform radial pressure on two arcs 2α (Hondros 1959), with the
    resultant P = 2pR·sinα of that pressure. 1 for point loads."""
    a = math.radians(arc_deg / 2.0)
    return 1.0 if a == 0 else (math.sin(2 * a) - a) / math.sin(a)


def first_modes(run, count: int = 20) -> dict:
    """Modes of the first ``count`` springs to break (1 tensile, 2 Mohr–Coulomb)."""
    sel = np.flatnonzero(run.pair_tbreak >= 0)
    order = sel[np.argsort(run.pair_tbreak[sel], kind="stable")][:count]
    m = run.pair_mode[order]
    return {"tensile": int(np.sum(m == 1)), "mohr_coulomb": int(np.sum(m == 2))}


def braz(rock, label, **kw):
    s = replace(brazilian_settings(), **kw)
    t0 = time.perf_counter()
    r = run_brazilian(rock, s)
    h = r.run.history
    row = {"group": "brazilian", "case": label, "jaw_ratio": s.jaw_ratio, "loading_arc_deg": s.loading_arc,
           "T_MPa": rock.tensile_strength / 1e6, "c_MPa": rock.cohesion / 1e6, "phi": rock.friction_angle,
           "elements": r.specimen.element_count, "sigma_t_MPa": r.tensile_strength / 1e6,
           "r_over_R_first_tensile": r.initiation_radius,
           "broken_at_peak": {"tensile": int(h.tensile[r.peak_index]), "mohr_coulomb": int(h.shear[r.peak_index])},
           "first_20_breaks": first_modes(r.run),
           "continuum_T_MPa": rock.tensile_strength / 1e6,
           "continuum_MC_MPa": sigma_t_mc(rock.cohesion, rock.friction_angle) / 1e6,
           "hondros_factor": hondros_factor(s.loading_arc) if s.jaw_ratio == 1.0 else None,
           "wall_s": time.perf_counter() - t0}
    print(json.dumps(row), flush=True)
    return row


def ucs(rock, label, mesh, **kw):
    s = replace(LoadSettings(), **kw)
    t0 = time.perf_counter()
    r = run_ucs(rock, s, mesh)
    h = r.run.history
    row = {"group": "ucs", "case": label, "bonded": s.bonded, "T_MPa": rock.tensile_strength / 1e6,
           "c_MPa": rock.cohesion / 1e6, "phi": rock.friction_angle, "elements": r.specimen.element_count,
           "ucs_MPa": r.ucs / 1e6, "E_GPa": r.youngs_modulus / 1e9,
           "broken_at_peak": {"tensile": int(h.tensile[r.peak_index]), "mohr_coulomb": int(h.shear[r.peak_index])},
           "first_20_breaks": first_modes(r.run),
           "continuum_MC_MPa": ucs_mc(rock.cohesion, rock.friction_angle) / 1e6,
           "wall_s": time.perf_counter() - t0}
    print(json.dumps(row), flush=True)
    return row


def braz_table(rows):
    print("| case | jaw R/R_disc | arc 2α [°] | T [MPa] | c [MPa] | σt [MPa] | σt / min(T, MC bound) | first tensile r/R "
          "| first 20 breaks T/MC | broken at peak T/MC |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        ref = min(r["continuum_T_MPa"], r["continuum_MC_MPa"])
        print(f"| {r['case']} | {r['jaw_ratio']:g} | {r['loading_arc_deg']:g} | {r['T_MPa']:g} | {r['c_MPa']:g} | "
              f"{r['sigma_t_MPa']:.2f} | {r['sigma_t_MPa'] / ref:.2f} | {r['r_over_R_first_tensile']:.2f} | "
              f"{r['first_20_breaks']['tensile']}/{r['first_20_breaks']['mohr_coulomb']} | "
              f"{r['broken_at_peak']['tensile']}/{r['broken_at_peak']['mohr_coulomb']} |")


def ucs_table(rows):
    print("| case | elements | T [MPa] | c [MPa] | φ [°] | UCS [MPa] | MC bound [MPa] | UCS / bound "
          "| first 20 breaks T/MC | broken at peak T/MC |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['case']} | {r['elements']} | {r['T_MPa']:g} | {r['c_MPa']:g} | {r['phi']:g} | {r['ucs_MPa']:.1f} | "
              f"{r['continuum_MC_MPa']:.1f} | {r['ucs_MPa'] / r['continuum_MC_MPa']:.2f} | "
              f"{r['first_20_breaks']['tensile']}/{r['first_20_breaks']['mohr_coulomb']} | "
              f"{r['broken_at_peak']['tensile']}/{r['broken_at_peak']['mohr_coulomb']} |")


def main(groups: list[str]) -> None:
    rock = load_scenario(Path(__file__).with_name("scenario.toml")).rock
    w = rock.model_copy
    if "arc" in groups:
        rows = [braz(rock, f"arc {a:g}°", loading_arc=a) for a in (5.0, 10.0, 15.0, 20.0, 30.0, 45.0)]
        rows.append(braz(rock, "conforming, no arc limit", loading_arc=0.0))
        rows.append(braz(rock, "ISRM jaws", loading_arc=0.0, jaw_ratio=1.5))
        rows.append(braz(rock, "flat platens", loading_arc=0.0, jaw_ratio=0.0))
        braz_table(rows)
    if "rule" in groups:
        rows = [braz(rock, "Table 3"),
                braz(w(update={"cohesion": OFF}), "tension only"),
                braz(w(update={"tensile_strength": OFF}), "Mohr–Coulomb only")]
        rows += [braz(w(update={"tensile_strength": T}), f"T = {T / 1e6:g} MPa") for T in (7e6, 10e6, 12e6, 20e6)]
        rows += [braz(w(update={"cohesion": OFF, "tensile_strength": T}), f"tension only, T = {T / 1e6:g} MPa")
                 for T in (7.4e6, 10e6)]
        rows += [braz(w(update={"cohesion": c}), f"c = {c / 1e6:g} MPa") for c in (20e6, 32e6)]
        braz_table(rows)
    if "ucs" in groups:
        h = 2.0 * default_ucs_mesh_size()
        rows = [ucs(rock, "Table 3", h), ucs(w(update={"cohesion": OFF}), "tension only", h),
                ucs(w(update={"tensile_strength": OFF}), "Mohr–Coulomb only", h)]
        rows += [ucs(w(update={"friction_angle": p}), f"φ = {p:g}°", h) for p in (45.0, 50.0, 55.0, 65.0)]
        rows += [ucs(w(update={"tensile_strength": OFF, "friction_angle": p}), f"MC only, φ = {p:g}°", h)
                 for p in (50.0,)]
        rows.append(ucs(rock, "bonded platens", h, bonded=True))
        ucs_table(rows)
    if "stiff" in groups:    # stiffness definition: kn, ks ×2 (tributary length L instead of L/2) and ×½
        rows = [braz(w(update={"kn": f * rock.kn, "ks": f * rock.ks}), f"kn, ks ×{f:g}") for f in (0.5, 2.0)]
        braz_table(rows)
        h = 2.0 * default_ucs_mesh_size()
        rows = [ucs(w(update={"kn": f * rock.kn, "ks": f * rock.ks}), f"kn, ks ×{f:g}", h) for f in (0.5, 2.0)]
        ucs_table(rows)
    if "ucs1" in groups:     # tension only is left out here: on the ×2 prism it never fails (UCS > 1 GPa)
        rows = [ucs(rock, "Table 3", None), ucs(w(update={"tensile_strength": OFF}), "Mohr–Coulomb only", None),
                ucs(rock, "bonded platens", None, bonded=True)]
        ucs_table(rows)


if __name__ == "__main__":
    main(sys.argv[1:] or ["arc", "rule", "ucs"])
