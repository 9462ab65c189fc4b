"""Analytic effective elasticity of the block–spring system (METHOD §1.2), used as the model
inside the elastic fit and as its first guess.

Orientation-averaged estimate for CST blocks (E, ν) joined by springs kn, ks [Pa/m] on an
interior-edge density ℓ [1/m] (edge length per unit area):
    1/E'_eff = 1/E' + ℓ·(3/(8kn) + 1/(8ks)),   ν'_eff/E'_eff = ν'/E' − ℓ·(1/kn − 1/ks)/8,
with the plane-strain moduli E' = E/(1−ν²), ν' = ν/(1−ν).
"""

from __future__ import annotations

import numpy as np

from .curves import plane_strain_to_3d, three_d_to_plane_strain


def edge_density(model) -> float:
    """ℓ: interior edge length per unit area of a built model [1/m]."""
    return float(model.host["pair_l0"][0::2].sum() / model.host["elem_area0"].sum())


def effective_moduli(E: float, nu: float, ell: float, kn: float, ks: float) -> tuple[float, float]:
    """3D-equivalent (E_eff [Pa], ν_eff) of blocks (E, ν) with springs kn, ks [Pa/m] at density ℓ [1/m]."""
    Ep, nup = three_d_to_plane_strain(E, nu)
    Ep_eff = 1.0 / (1.0 / Ep + ell * (3.0 / (8.0 * kn) + 1.0 / (8.0 * ks)))
    nup_eff = Ep_eff * (nup / Ep - ell * (1.0 / kn - 1.0 / ks) / 8.0)
    return plane_strain_to_3d(Ep_eff, nup_eff)


def effective_moduli_np(E, nu, ell, kn, ks) -> np.ndarray:
    """Vectorised :func:`effective_moduli`, returns [..., 2]."""
    return np.stack(np.broadcast_arrays(*effective_moduli(E, nu, ell, np.asarray(kn, float), np.asarray(ks, float))), -1)
