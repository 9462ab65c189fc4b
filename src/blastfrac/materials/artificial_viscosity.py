"""Artificial bulk viscosity (von Neumann–Richtmyer quadratic + Landshoff linear term).

q = ρ·l·(C_q·l·(tr D)² − C_l·c·tr D) [Pa] in compression (tr D < 0), 0 in expansion, with
tr D = ∂v_x/∂x + ∂v_y/∂y [1/s] the volumetric strain rate, l [m] a length of the cell or
element, c [m/s] the material's sound speed, ρ [kg/m³] its density. q acts as an extra
pressure on the momentum equation only (it is not part of the stored elastic stress) and
dissipates q·(−tr D) per unit volume and time.

Why the rock needs it: the springs' strengths are ~1 % of a blast wave's amplitude (7–14 MPa
against GPa), while an undamped discrete lattice rings behind a steep front by several
percent of the amplitude (mesh-scale dispersion). Without a shock viscosity that ringing
breaks springs in tension and low-confinement shear wherever a GPa wave passes, which no
continuum stress state would do (tests/verification/test_rock_viscosity.py). Explicit
hydrocodes switch the same viscosity on for solids by default (LS-DYNA *CONTROL_BULK_VISCOSITY:
Q1 = 1.5, Q2 = 0.06; AUTODYN: 1.0, 0.2); the values here are the scenario's
``rock.bulk_viscosity_quadratic`` / ``rock.bulk_viscosity_linear``.

The MPM explosive uses the same law for the detonation products (mpm/kernels_eos.py).
"""

from __future__ import annotations

import warp as wp


@wp.func
def bulk_viscosity(trD: wp.float64, rho: wp.float64, l: wp.float64, c: wp.float64,
                   c_quad: wp.float64, c_lin: wp.float64):
    """Artificial bulk viscosity q [Pa] (compression only): C_q ρ l² (tr D)² − C_l ρ l c tr D where tr D < 0, else 0.

    Without a branch (tr D clipped at 0 gives q = 0 exactly): in a wave field the sign of tr D is a coin toss to
    the CPU, and a mispredicted branch per block cost more than the arithmetic."""
    t = wp.min(trD, wp.float64(0.0))
    return c_quad * rho * l * l * t * t - c_lin * rho * l * c * t


def np_bulk_viscosity(trD: float, rho: float, l: float, c: float, c_quad: float, c_lin: float) -> float:
    """NumPy twin of :func:`bulk_viscosity`."""
    t = min(trD, 0.0)
    return c_quad * rho * l * l * t * t - c_lin * rho * l * c * t
