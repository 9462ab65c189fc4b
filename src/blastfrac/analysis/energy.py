"""Energy budget of the rock: stored, kinetic, dissipated and exchanged terms [J/m]."""

from __future__ import annotations

import numpy as np

from ..model.builder import _cross
from ..cdem.kernels_integrate import block_kinetic_energy
from ..model.model import CONTACT_DISSIPATED, DAMPING_DISSIPATED, EXTERNAL_WORK, VISCOUS_ABSORBED


def strain_energy_density(sig: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """½σ:C⁻¹:σ [J/m³] for an array of plane-strain stresses [M, 3] (vectorised twin of the wp.func)."""
    s = lam + mu
    exx = ((lam + 2 * mu) * sig[:, 0] - lam * sig[:, 1]) / (4 * mu * s)
    eyy = ((lam + 2 * mu) * sig[:, 1] - lam * sig[:, 0]) / (4 * mu * s)
    return 0.5 * (sig[:, 0] * exx + sig[:, 1] * eyy) + sig[:, 2] * sig[:, 2] / (2 * mu)


def rock_energies(model, state) -> dict[str, float]:
    """All energy terms of the rock at the current step.

    kinetic: ½vᵀMv with the half-step velocities and the blocks' mass matrices (cdem/kernels_integrate.py); strain: blocks (current area);
    springs: ½Fn²/Kn + ½Fs²/Ks of every spring still carrying force;
    fracture: energy dissipated by broken springs at failure plus softening in progress;
    friction: other dissipation in broken springs (sliding) and block contact;
    external_work, viscous_absorbed, damping: accumulated since the stage began.
    """
    x = state.x.numpy()
    v = state.v.numpy()
    m = model.node_mass.numpy()
    sig = state.sigma.numpy()
    area = 0.5 * _cross(x[1::3] - x[0::3], x[2::3] - x[0::3])
    F = state.pair_F.numpy()
    kn, ks = model.host["pair_kn"], model.host["pair_ks"]
    stored = 0.5 * F[:, 0] ** 2 / kn + 0.5 * F[:, 1] ** 2 / ks
    mode = state.pair_mode.numpy()
    inelastic = state.pair_inelastic.numpy()            # work done on each spring beyond its stored energy
    efrac = state.pair_efrac.numpy()
    broken = mode > 0
    acc = state.energy_acc.numpy()
    fracture = float(efrac[broken].sum() + np.sum(inelastic[~broken]))
    friction = float(np.sum((inelastic - efrac)[broken])) + float(acc[CONTACT_DISSIPATED])
    with np.errstate(over="ignore", invalid="ignore"):   # a blown-up state: the NaN guard reports where
        strain = float(np.sum(strain_energy_density(sig, model.lam, model.mu) * area))
    return {
        "kinetic": block_kinetic_energy(m, v, model.mass_theta),
        "strain": strain,
        "springs": float(stored.sum()),
        "fracture": fracture,
        "friction": friction,
        "viscous_absorbed": float(acc[VISCOUS_ABSORBED]) + float(np.sum(state.elem_absorbed.numpy())),
        "damping": float(acc[DAMPING_DISSIPATED]) + float(np.sum(state.pair_damp.numpy()))
                   + float(np.sum(state.elem_damp.numpy())),
        "external_work": float(acc[EXTERNAL_WORK]),
    }


def gas_energies(gas) -> dict[str, float]:
    """Energy terms of the MPM points over *all* of them [J/m]: the detonation products and the elastic bodies.

    Particles that left the grid keep their last state, so their energy stays in the books.
    explosive_released: Σ F·E0·V0 (chemical energy liberated by the burn so far);
    gas_internal: Σ ie − Σ (1 − F)·E0·V0 (internal energy of the burnt products), V0 the seeded volumes;
    gas_kinetic: Σ ½ m v², plus with APIC transfer the affine part Σ ½ m tr(B D⁻¹ Bᵀ) of the active particles
    (mpm/apic.py; a particle that left the grid has no affine field).
    With elastic bodies (mpm/bodies.py) the sums above run over the gas points, and
    body_kinetic: Σ ½ m v² of the body points (with APIC plus their affine part);
    body_strain: Σ ie of the body points, the work done on them by their stresses (their stored strain energy);
    body_initial: the bodies' kinetic energy at seeding, an energy supplied to the run (:func:`budget_error`).
    """
    ie = gas.ie.numpy()
    burn = gas.burn.numpy()
    chem0 = gas.chem0       # E0·V0 at seeding: V0 follows the mass of a particle that feeds a crack
    v = gas.v.numpy()
    mass = gas.mass.numpy()
    if getattr(gas, "n_solid", 0):
        return _gas_and_body_energies(gas, ie, burn, chem0, v, mass)
    ke = float(0.5 * (mass * np.einsum("ij,ij->i", v, v)).sum())
    if getattr(gas, "apic", False):
        ke += gas.energies()["kinetic_affine"]
    return {
        "explosive_released": float((burn * chem0).sum()),
        "gas_internal": float(ie.sum() - ((1.0 - burn) * chem0).sum()),
        "gas_kinetic": ke,
    }


def _gas_and_body_energies(gas, ie, burn, chem0, v, mass) -> dict[str, float]:
    """:func:`gas_energies` of a solver with elastic bodies: the gas terms over the gas points, the body terms apart."""
    g = gas.body_id < 0
    b = ~g
    ke2 = mass * np.einsum("ij,ij->i", v, v)
    ke_g, ke_b = float(0.5 * ke2[g].sum()), float(0.5 * ke2[b].sum())
    if getattr(gas, "apic", False):
        e = gas.energies()
        ke_g += e["kinetic_affine"]
        ke_b += e["body_kinetic_affine"]
    return {
        "explosive_released": float((burn[g] * chem0[g]).sum()),
        "gas_internal": float(ie[g].sum() - ((1.0 - burn[g]) * chem0[g]).sum()),
        "gas_kinetic": ke_g,
        "body_kinetic": ke_b,
        "body_strain": float(ie[b].sum()),
        "body_initial": float(gas.body_energy0),
    }


# the terms that hold or have taken energy; the supplied side is initial stored + external work + explosive
# + the elastic bodies' initial kinetic energy (body_initial)
HELD_TERMS = ("kinetic", "strain", "springs", "fracture", "friction", "viscous_absorbed", "damping",
              "gas_kinetic", "gas_internal", "contact_energy", "crack_gas", "body_kinetic", "body_strain")


def budget_error(e: dict[str, float], initial_stored: float) -> tuple[float, float]:
    """(absolute, relative) closing error: held terms (stored, kinetic, losses) − (initial stored + input).

    The relative error divides by the energy put in (external work plus explosive energy released plus the elastic
    bodies' initial kinetic energy), or by the rock's mechanical energy when that is larger.
    """
    have = sum(e.get(k, 0.0) for k in HELD_TERMS)
    supplied = initial_stored + e["external_work"] + e.get("explosive_released", 0.0)
    put_in = abs(e["external_work"]) + abs(e.get("explosive_released", 0.0))
    if "body_initial" in e:
        supplied += e["body_initial"]
        put_in += abs(e["body_initial"])
    err = have - supplied
    scale = max(put_in, e["kinetic"] + e["strain"] + e["springs"], 1e-300)
    return err, err / scale
