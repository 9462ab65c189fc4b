"""Affine particle-in-cell transfer (APIC; Jiang, Schroeder, Selle, Teran & Stomakhin 2015).

Each particle carries, besides its velocity v_p [m/s], the affine moment B_p [m²/s] (mat22d) of
its velocity field v_p + C_p (x − x_p), C_p = B_p D_p⁻¹ [1/s].  With x_I − x_p the offset of node I
from the particle [m], N_I = N_I(x_p) and D_p = Σ_I N_I (x_I − x_p) ⊗ (x_I − x_p) [m²]:

* G2P (METHOD §2.2 step 4): v_p = Σ_I N_I v_I,  B_p = Σ_I N_I v_I ⊗ (x_I − x_p);
* P2G (steps 1 and 5): p_I = Σ_p N_I m_p (v_p + B_p D_p⁻¹ (x_I − x_p)), D_p at the particle's
  position at that moment.

Why B D⁻¹ and not C = Σ v_I ⊗ ∇N_I.  Both give the exact gradient of an affine grid velocity
field, but only B D⁻¹ makes the transfers conserve angular momentum for any grid field.  Take the
particle's angular momentum as m_p (x_p × v_p) + m_p ε:B_p (2D: m_p [(B_p)_yx − (B_p)_xy]).  With the
partition of unity and linear reproduction (Σ N_I = 1, Σ N_I (x_I − x_p) = 0, true for both shapes
of :mod:`blastfrac.mpm.shape`):

* after G2P, Σ_p m_p [x_p × v_p + ε:B_p] = Σ_I m_I x_I × v_I  (the definitions of v_p, B_p);
* after P2G, Σ_I x_I × p_I = Σ_p m_p [x_p × v_p + ε:(C_p D_p)], which is ε:B_p only if C_p = B_p D_p⁻¹
  with D_p from the same weights;
* the motion x_p += Δt v_p between the two changes no x_p × v_p (v_p is the grid velocity the
  particle moves with) and does not touch B_p.

For the quadratic B-spline (the default shape) D_p = h²/4 I wherever the particle sits in its
cell, and ∇N_I ≠ (4/h²) N_I (x_I − x_p) (1D, |r| < ½: −2r/h against −4r(¾ − r²)/h), so the gradient
form would not conserve it.  For uGIMP D_p is diagonal (linear reproduction kills the
off-diagonal) but depends on where the particle sits in its cell; that is why B_p, not C_p, is
carried: D_p is taken at P2G from the weights used there, which is exact for both shapes.
Linear momentum is conserved by both transfers (Σ N_I (x_I − x_p) = 0), mass is untouched.

The kinetic energy that goes with this field is ½ m_p (|v_p|² + tr(B_p D_p⁻¹ B_pᵀ)); neither
transfer can increase it (Cauchy–Schwarz on the node sums), unlike FLIP's.  What they take away is lost:
in a shock it should have become heat (measured in docs/explosive.md, "Velocity transfer").

A point alone on its nodes gets its own affine field back from them, so its C_p never decays and its
volume grows as exp(tr C_p t); the G2P kernel therefore drops B_p of points beyond ``v_max`` (whose
pressure is frozen anyway), at the cost of their affine spin.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from blastfrac.mpm.shape import stencil_1d_np

F64 = wp.float64

#: velocity transfers: FLIP/PIC blend (``MPMOptions.flip``) or APIC
TRANSFERS = ("flip", "apic")


@wp.func
def affine_inertia(wx: wp.vec3d, wy: wp.vec3d, ox: wp.float64, oy: wp.float64, h: wp.float64):
    """D_p = Σ N_I (x_I − x_p) ⊗ (x_I − x_p) [m²] of a tensor-product stencil with 1D weights wx, wy on the
    nodes at offsets (ox + k) h, (oy + k) h, k = 0, 1, 2, from the particle (ox = base − f)."""
    mx = F64(0.0)
    my = F64(0.0)
    sx = F64(0.0)
    sy = F64(0.0)
    for k in range(3):
        dx = (ox + F64(k)) * h
        dy = (oy + F64(k)) * h
        mx += wx[k] * dx
        my += wy[k] * dy
        sx += wx[k] * dx * dx
        sy += wy[k] * dy * dy
    return wp.mat22d(sx, mx * my, mx * my, sy)


@wp.func
def affine_from_moments(Bm: wp.mat22d, Dm: wp.mat22d):
    """APIC affine velocity C_p = B_p D_p⁻¹ [1/s] from B_p [m²/s] and D_p [m²] (2x2, D symmetric positive)."""
    det = Dm[0, 0] * Dm[1, 1] - Dm[0, 1] * Dm[1, 0]
    inv = wp.mat22d(Dm[1, 1], -Dm[0, 1], -Dm[1, 0], Dm[0, 0]) / det
    return Bm * inv


# ----------------------------------------------------------------------------- numpy twins
def affine_from_moments_np(B: np.ndarray, D: np.ndarray) -> np.ndarray:
    """NumPy twin of :func:`affine_from_moments`; B, D [..., 2, 2]."""
    return np.asarray(B, np.float64) @ np.linalg.inv(np.asarray(D, np.float64))


def affine_inertia_np(x: np.ndarray, spec, kind: str = "bspline2", l: float = 0.25) -> np.ndarray:
    """D_p = Σ_I N_I (x_I − x_p) ⊗ (x_I − x_p) [m²] for particles at x [n, 2] on the grid ``spec``; [n, 2, 2]."""
    x = np.atleast_2d(np.asarray(x, np.float64))
    out = np.zeros((len(x), 2, 2))
    mom = []
    for ax, o in enumerate((spec.x0, spec.y0)):
        f = (x[:, ax] - o) / spec.h
        base, w, _ = stencil_1d_np(f, kind, l)
        d = (base[:, None] + np.arange(3)[None, :] - f[:, None]) * spec.h
        out[:, ax, ax] = (w * d * d).sum(axis=1)
        mom.append((w * d).sum(axis=1))
    out[:, 0, 1] = out[:, 1, 0] = mom[0] * mom[1]
    return out


def affine_kinetic_energy_np(mass: np.ndarray, B: np.ndarray, D: np.ndarray) -> np.ndarray:
    """½ m_p tr(B_p D_p⁻¹ B_pᵀ) [J/m] per particle: the kinetic energy of the affine part of the velocity field."""
    C = affine_from_moments_np(B, D)
    return 0.5 * np.asarray(mass, np.float64) * np.einsum("nij,nij->n", C, np.asarray(B, np.float64))


def affine_angular_momentum_np(mass: np.ndarray, B: np.ndarray) -> np.ndarray:
    """m_p [(B_p)_yx − (B_p)_xy] [kg m²/s per m]: the spin the affine field adds to m_p x_p × v_p."""
    B = np.asarray(B, np.float64)
    return np.asarray(mass, np.float64) * (B[:, 1, 0] - B[:, 0, 1])
