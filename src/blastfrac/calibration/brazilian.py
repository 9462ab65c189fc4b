"""Simulated Brazilian (splitting) test of a disc loaded across a diameter by two platens.

σ_t = 2P/(π·D·t) at the peak load P [N/m] (t = 1 m: 2D, unit thickness). The jaws are frictionless;
by default conforming (radius = disc radius) and acting on the rim nodes of a loading arc
2α = 15° (the arc-loaded Brazilian test), optionally ISRM curved jaws (radius 1.5 R) or flat.
The initiation check records where the first tensile spring failures occur: a valid test
splits from the centre, not from the loaded points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..scenario.schema import RockConfig
from .curves import first_peak
from .quasistatic import LoadResult, LoadSettings, run_loading, run_start
from .specimens import Specimen, disc_specimen

FIRST_CRACKS = 10   # the first N tensile failures define the initiation point


@dataclass
class BrazilianResult:
    specimen: Specimen
    run: LoadResult
    settings: LoadSettings
    load: np.ndarray              # platen force P [N/m]
    closure: np.ndarray           # platen approach (both platens) [m]
    peak_index: int
    tensile_strength: float       # [Pa]
    first_tensile_xy: np.ndarray  # positions of the first tensile failures [m], [k, 2]

    @property
    def initiation_radius(self) -> float:
        """Median distance of the first tensile failures from the centre / disc radius [-]."""
        if len(self.first_tensile_xy) == 0:
            return float("nan")
        r = np.hypot(self.first_tensile_xy[:, 0], self.first_tensile_xy[:, 1])
        return float(np.median(r) / (self.specimen.width / 2))

    def summary(self) -> dict:
        h = self.run.history
        xy = self.first_tensile_xy
        return {
            "tensile_strength": {"value": self.tensile_strength, "unit": "Pa"},
            "peak_load": {"value": float(self.load[self.peak_index]), "unit": "N/m"},
            "first_tensile_failures_m": xy.tolist(),
            "initiation_radius_over_R": self.initiation_radius,
            "broken_springs_at_peak": {"tensile": int(h.tensile[self.peak_index]),
                                       "shear": int(h.shear[self.peak_index])},
            "broken_springs_at_end": {"tensile": int(h.tensile[-1]), "shear": int(h.shear[-1])},
            "elements": self.specimen.element_count, "springs": self.specimen.model.spring_count,
            "diameter_m": self.specimen.width, "mesh_size_m": self.specimen.scenario.geometry.mesh_size,
            "time_step_s": self.run.dt, "steps": self.run.steps, "wall_s": self.run.wall_s,
            "stopped": self.run.stopped,
        }


def first_failures(spec: Specimen, run: LoadResult, mode: int = 1, count: int = FIRST_CRACKS) -> np.ndarray:
    """Reference positions [m] of the first ``count`` springs that broke in ``mode`` (1 tensile)."""
    sel = np.flatnonzero((run.pair_mode == mode) & (run.pair_tbreak >= 0))
    if len(sel) == 0:
        return np.zeros((0, 2))
    order = sel[np.argsort(run.pair_tbreak[sel], kind="stable")][:count]
    X = spec.model.host["node_X"]
    pn = spec.model.topology.pair_nodes
    return 0.5 * (X[pn[order, 0]] + X[pn[order, 1]])


def analyse_brazilian(spec: Specimen, run: LoadResult, settings: LoadSettings) -> BrazilianResult:
    load = run.history.reaction
    ip = first_peak(load, settings.failure_drop, run_start(run))
    sigma_t = 2.0 * float(load[ip]) / (math.pi * spec.width * 1.0)
    closure = 2.0 * np.asarray(run.history.platen_u)
    return BrazilianResult(spec, run, settings, load, closure, ip, sigma_t, first_failures(spec, run))


def brazilian_settings(settings: LoadSettings | None = None) -> LoadSettings:
    """Defaults of the Brazilian test: conforming jaws on a 15° loading arc, finer sampling (smaller
    strains than the UCS test), and the quasi-static defaults of :class:`LoadSettings`."""
    if settings is not None:
        return settings
    return LoadSettings(jaw_ratio=1.0, loading_arc=15.0, sample_strain=2e-6, max_strain=0.005)


def run_brazilian(rock: RockConfig, settings: LoadSettings | None = None, mesh_size: float | None = None,
                  seed: int = 0, device: str = "cpu", on_sample=None) -> BrazilianResult:
    """Build the 54 mm disc for ``rock``, split it and read σ_t and the initiation point."""
    settings = brazilian_settings(settings)
    spec = disc_specimen(rock, mesh_size, seed, device)
    return analyse_brazilian(spec, run_loading(spec, settings, on_sample), settings)
