"""Simulated uniaxial compression (UCS) test of a rectangular prism between frictionless platens.

Outputs (2D plane strain, unit thickness):
- axial stress σ = platen reaction / width [Pa] (mean of the two platens);
- axial strain ε = shortening between the specimen's loaded faces / height (face nodes, so the
  platen penalty does not enter); lateral strain = widening between the side faces / width;
- plane-strain moduli E' = dσ/dε and ν' = −dε_lat/dε over 10–40 % of the peak, converted to the
  3D-equivalent E = E'(1−ν²), ν = ν'/(1+ν') (the 3D material whose plane-strain response it is);
- UCS = first peak of σ (see :func:`.curves.first_peak`), the plane-strain peak axial stress,
  taken no later than the onset of dilatant collapse (:func:`dilation_onset`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..scenario.schema import RockConfig
from .curves import elastic_window, first_peak, plane_strain_to_3d, slope
from .quasistatic import LoadResult, LoadSettings, run_loading, run_start
from .specimens import Specimen, ucs_specimen


@dataclass
class UCSResult:
    specimen: Specimen
    run: LoadResult
    settings: LoadSettings
    strain: np.ndarray            # axial strain, compression positive [-]
    lateral_strain: np.ndarray    # lateral strain, extension positive [-]
    stress: np.ndarray            # axial stress, compression positive [Pa]
    peak_index: int
    youngs_modulus_ps: float      # plane-strain E' [Pa]
    poisson_ratio_ps: float       # plane-strain ν' [-]
    youngs_modulus: float         # 3D-equivalent E [Pa]
    poisson_ratio: float          # 3D-equivalent ν [-]
    ucs: float                    # [Pa]
    reference: dict = field(default_factory=dict)   # elastic references of the same prism, see elastic_reference

    @property
    def max_stress(self) -> float:
        """Largest stress of the whole run [Pa] (can exceed the UCS after failure, see docs)."""
        return float(self.stress.max())

    def summary(self) -> dict:
        h = self.run.history
        return {
            "youngs_modulus": {"value": self.youngs_modulus, "unit": "Pa"},
            "poisson_ratio": {"value": self.poisson_ratio, "unit": "-"},
            "youngs_modulus_plane_strain": {"value": self.youngs_modulus_ps, "unit": "Pa"},
            "poisson_ratio_plane_strain": {"value": self.poisson_ratio_ps, "unit": "-"},
            "ucs": {"value": self.ucs, "unit": "Pa"},
            "strain_at_peak": float(self.strain[self.peak_index]),
            "max_stress_of_run": {"value": self.max_stress, "unit": "Pa"},
            "broken_springs_at_peak": {"tensile": int(h.tensile[self.peak_index]),
                                       "shear": int(h.shear[self.peak_index])},
            "broken_springs_at_end": {"tensile": int(h.tensile[-1]), "shear": int(h.shear[-1])},
            "elements": self.specimen.element_count, "springs": self.specimen.model.spring_count,
            "width_m": self.specimen.width, "height_m": self.specimen.height,
            "mesh_size_m": self.specimen.scenario.geometry.mesh_size,
            "time_step_s": self.run.dt, "steps": self.run.steps, "wall_s": self.run.wall_s,
            "stopped": self.run.stopped,
            "elastic_reference": self.reference,
        }


def analyse_ucs(spec: Specimen, run: LoadResult, settings: LoadSettings) -> UCSResult:
    h = run.history.arrays()
    stress = run.history.reaction / spec.width
    strain = h["axial_u"] / spec.height
    lateral = h["lateral_u"] / spec.width
    i0 = run_start(run)
    ip = first_peak(stress, settings.failure_drop, i0)
    k = dilation_onset(strain, lateral, i0)
    if k is not None and k < ip:
        ip = i0 + int(np.argmax(stress[i0:k + 1]))
    win = elastic_window(stress, ip, start=i0)
    Ep = slope(strain[win], stress[win])
    nup = slope(strain[win], lateral[win])
    E, nu = plane_strain_to_3d(Ep, nup)
    return UCSResult(spec, run, settings, strain, lateral, stress, ip, Ep, nup, E, nu, float(stress[ip]))


DILATION_RATIO = 1.0   # incremental lateral/axial strain ratio that marks a collapsing (splitting) prism


def dilation_onset(strain: np.ndarray, lateral: np.ndarray, start: int = 0, window: int = 3) -> int | None:
    """First sample where the incremental ratio Δε_lat/Δε over ``window`` samples exceeds
    DILATION_RATIO (elastic value ν' ≈ 0.25): the prism is splitting into columns. A spring
    lattice can keep gaining axial load after that (columns wedge, and separated blocks have no
    contact in this version), so the UCS is taken before it. None if it never happens."""
    for k in range(max(start, window), len(strain)):
        de = strain[k] - strain[k - window]
        if de > 0 and (lateral[k] - lateral[k - window]) / de > DILATION_RATIO:
            return k
    return None


def elastic_reference(spec: Specimen) -> dict:
    """Plane-strain E' [Pa], ν' of the prism: blocks alone, the analytic estimate of METHOD §1.2 and the
    exact linear static solve of this mesh (the zero-speed limit of the test's elastic part)."""
    from .curves import three_d_to_plane_strain
    from .elastic import edge_density, effective_moduli, static_moduli

    rock = spec.scenario.rock
    out = {"blocks": dict(zip(("youngs_modulus_ps", "poisson_ratio_ps"),
                              three_d_to_plane_strain(rock.youngs_modulus, rock.poisson_ratio))),
           "unit": "Pa, -"}
    if rock.stiffness_mode == "per_area":
        ell = edge_density(spec.model)
        Ep, nup = three_d_to_plane_strain(*effective_moduli(rock.youngs_modulus, rock.poisson_ratio, ell,
                                                            rock.kn, rock.ks))
        out["analytic"] = {"youngs_modulus_ps": Ep, "poisson_ratio_ps": nup, "edge_density_per_m": ell}
    Ep, nup = static_moduli(spec)
    out["static"] = {"youngs_modulus_ps": Ep, "poisson_ratio_ps": nup}
    return out


def run_ucs(rock: RockConfig, settings: LoadSettings | None = None, mesh_size: float | None = None,
            seed: int = 0, device: str = "cpu", on_sample=None, reference: bool = False) -> UCSResult:
    """Build the 54 × 108 mm prism for ``rock``, load it to failure and read the curve.
    ``reference``: also compute :func:`elastic_reference` (one sparse solve, about 1 s)."""
    settings = settings or LoadSettings()
    spec = ucs_specimen(rock, mesh_size, seed, device)
    res = analyse_ucs(spec, run_loading(spec, settings, on_sample), settings)
    if reference:
        res.reference = elastic_reference(spec)
    return res
