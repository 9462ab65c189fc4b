"""Shared helpers for the test suite."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from blastfrac._warp import init_warp

init_warp()

# Table 2 of Yue et al. (2022)
ROCK = dict(density=2600.0, youngs_modulus=50e9, poisson_ratio=0.2)


def scenario(**sections):
    """A scenario dict with Table 2 rock, unbreakable stiff springs unless overridden."""
    from blastfrac.scenario import scenario_from_dict

    d = {"rock": {**ROCK, "unbreakable": True, "stiffness_mode": "penalty", "spring_penalty": 50.0},
         "simulation": {"progress": False}, "output": {"paraview": False, "figures": False}}
    for k, v in sections.items():
        if isinstance(v, dict) and isinstance(d.get(k), dict):
            d[k] = {**d[k], **copy.deepcopy(v)}
        else:
            d[k] = copy.deepcopy(v)
    return scenario_from_dict(d)


def effective_plane_strain_moduli(E: float, nu: float, ell: float, kn: float, ks: float) -> tuple[float, float]:
    """Spring-compliance corrected (E'_eff, ν'_eff) of METHOD §1.2 (orientation-averaged estimate)."""
    Ep = E / (1 - nu**2)
    nup = nu / (1 - nu)
    Ep_eff = 1.0 / (1.0 / Ep + ell * (3.0 / (8.0 * kn) + 1.0 / (8.0 * ks)))
    nup_eff = Ep_eff * (nup / Ep - ell * (1.0 / kn - 1.0 / ks) / 8.0)
    return Ep_eff, nup_eff


def interior_edge_density(model) -> float:
    """ℓ: interior edge length per unit area [1/m]."""
    return float(model.host["pair_l0"][0::2].sum() / model.host["elem_area0"].sum())


@pytest.fixture
def tmp_out(tmp_path):
    return tmp_path / "out"


__all__ = ["scenario", "effective_plane_strain_moduli", "interior_edge_density", "ROCK", "math", "np"]
