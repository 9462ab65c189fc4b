"""Elastic material-point bodies beside the explosive (``[[explosive.bodies]]``: an impactor, a flyer plate).

Every material point has a material kind (``MPMSolver.mat_kind``, int32):

* ``MAT_GAS`` (0): detonation products (JWL, programmed burn; :mod:`blastfrac.mpm.kernels_eos`);
* ``MAT_ELASTIC`` (1): a linear-elastic solid, the hypoelastic Jaumann-rate law of
  :mod:`blastfrac.materials.linear_elastic_mp` (:mod:`blastfrac.mpm.kernels_solid`).

and its own Lamé constants λ, μ [Pa] (0 for gas points) and reference density ρ0 [kg/m³] (mass = ρ0·V at
seeding). The burn and JWL kernels skip elastic points and the elastic kernel skips gas points, so a run with
charges and bodies still makes one launch per stage. All points move on one grid with one velocity field: where a
body and the gas share grid nodes they share the velocity (no slip between them, the usual single-field MPM
contact). Bodies touch the rock through the particle–edge contact (:mod:`blastfrac.coupling.particle_edge`) as the
gas does. A body's stored energy is the work done on it (``ie``), its strain energy in the budget.

This module holds the host side: the kinds and the per-point constants of a seeded set of points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

from blastfrac.materials.linear_elastic_mp import LinearElasticMP

MAT_GAS_NP = 0
MAT_ELASTIC_NP = 1
MAT_GAS = wp.constant(MAT_GAS_NP)
MAT_ELASTIC = wp.constant(MAT_ELASTIC_NP)


def body_material(body) -> LinearElasticMP:
    """The :class:`LinearElasticMP` of a scenario body (``explosive.bodies[k]``)."""
    return LinearElasticMP(E=float(body.youngs_modulus), nu=float(body.poisson_ratio), rho0=float(body.density))


def plane_strain_modulus(m: LinearElasticMP) -> float:
    """E' = E/(1 − ν²) [Pa]."""
    return m.E / (1.0 - m.nu**2)


def body_contact_stiffness(bodies, factor: float = 20.0) -> float:
    """Default particle–edge contact stiffness k_c [Pa] of a run without charges: (factor/20)·E' of the stiffest
    body, i.e. E' at the default factor 20 (METHOD §3.5: k_c ≈ 1–10·E'); the overlap at a contact stress σ is then
    about 2σ/E'·r_p, a strain's worth of the particle radius. With charges k_c = factor·P_CJ (coupling.coupler)."""
    return factor / 20.0 * max(plane_strain_modulus(b) for b in bodies)


@dataclass(frozen=True)
class PointMaterials:
    """Per-point material data [n] on the host: kind (int32), lam, mu [Pa], rho0 [kg/m³], E [Pa], nu [-] (0 for gas
    points; rho0 of gas points the explosive's), cs0 [m/s] (the elastic points' P-wave speed sqrt((λ+2μ)/ρ0), 0 for
    gas points)."""

    kind: np.ndarray
    lam: np.ndarray
    mu: np.ndarray
    rho0: np.ndarray
    E: np.ndarray
    nu: np.ndarray
    cs0: np.ndarray


def point_materials(body_id: np.ndarray, bodies, gas_rho0: float | None) -> PointMaterials:
    """Per-point data of points with body index ``body_id`` [n] (−1: gas) for ``bodies`` (LinearElasticMP list)."""
    body_id = np.asarray(body_id, np.int64).reshape(-1)
    n = len(body_id)
    solid = body_id >= 0
    if (~solid).any() and gas_rho0 is None:
        raise ValueError("gas points need an explosive (JWL) density")
    out = {k: np.zeros(n) for k in ("lam", "mu", "E", "nu", "cs0")}
    out["rho0"] = np.full(n, float(gas_rho0) if gas_rho0 is not None else 0.0)
    for k, b in enumerate(bodies):
        sel = body_id == k
        for key, val in (("lam", b.lam), ("mu", b.mu), ("rho0", b.rho0), ("E", b.E), ("nu", b.nu),
                         ("cs0", b.p_wave_speed)):
            out[key][sel] = val
    kind = np.where(solid, MAT_ELASTIC_NP, MAT_GAS_NP).astype(np.int32)
    return PointMaterials(kind=kind, **out)
