"""calibration.json, curve CSV files and figures of one calibration run."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .. import __version__
from .figures import curves_figure, specimens_figure

PLANE_NOTE = ("2D plane strain, unit thickness. The test measures the plane-strain moduli E' = dσ/dε and "
              "ν' = -dε_lat/dε; youngs_modulus and poisson_ratio are the 3D-equivalent values "
              "ν = ν'/(1+ν'), E = E'(1-ν²). Strengths are the 2D peak values (no conversion).")


def rock_micro(rock) -> dict:
    """The micro-parameters of the rock that the tests used (SI)."""
    keys = ("density", "youngs_modulus", "poisson_ratio", "stiffness_mode", "spring_penalty", "kn", "ks",
            "tensile_strength", "cohesion", "friction_angle", "residual_friction_angle",
            "tensile_fracture_energy", "shear_fracture_energy")
    return {k: getattr(rock, k) for k in keys}


def macro_values(ucs=None, braz=None) -> dict:
    """The four calibrated macro properties with units (missing tests give null)."""
    def q(v, unit):
        return {"value": None if v is None or not math.isfinite(v) else float(v), "unit": unit}

    return {
        "youngs_modulus": q(ucs.youngs_modulus if ucs else None, "Pa"),
        "poisson_ratio": q(ucs.poisson_ratio if ucs else None, "-"),
        "tensile_strength": q(braz.tensile_strength if braz else None, "Pa"),
        "ucs": q(ucs.ucs if ucs else None, "Pa"),
    }


def write_curves(out: Path, ucs=None, braz=None) -> list[Path]:
    paths = []
    if ucs is not None:
        h = ucs.run.history.arrays()
        p = out / "ucs_curve.csv"
        np.savetxt(p, np.column_stack([h["time"], h["platen_u"], ucs.strain, ucs.lateral_strain, ucs.stress,
                                       h["tensile"], h["shear"]]), delimiter=",",
                   header="time_s,platen_u_m,axial_strain,lateral_strain,axial_stress_Pa,broken_tensile,broken_shear",
                   comments="")
        paths.append(p)
    if braz is not None:
        h = braz.run.history.arrays()
        p = out / "brazilian_curve.csv"
        np.savetxt(p, np.column_stack([h["time"], braz.closure, braz.load, 2 * braz.load / (math.pi * braz.specimen.width),
                                       h["tensile"], h["shear"]]), delimiter=",",
                   header="time_s,closure_m,load_N_per_m,nominal_tensile_stress_Pa,broken_tensile,broken_shear",
                   comments="")
        paths.append(p)
    return paths


def write_report(out: Path, rock, ucs=None, braz=None, extra: dict | None = None, figures: bool = True,
                 title: str = "") -> dict:
    """Write calibration.json (+ CSV curves and PNG figures) into ``out``; returns the JSON dict."""
    out.mkdir(parents=True, exist_ok=True)
    data = {
        "blastfrac_version": __version__,
        "plane": PLANE_NOTE,
        **macro_values(ucs, braz),
        "micro_parameters": rock_micro(rock),
        "ucs_test": {**ucs.summary(), "settings": ucs.settings.as_dict()} if ucs else None,
        "brazilian_test": {**braz.summary(), "settings": braz.settings.as_dict()} if braz else None,
    }
    if extra:
        data.update(extra)
    (out / "calibration.json").write_text(json.dumps(data, indent=2))
    write_curves(out, ucs, braz)
    if figures:
        curves_figure(out / "stress_strain.png", ucs, braz, title)
        specimens_figure(out / "failed_specimens.png", ucs, braz, title)
    return data
