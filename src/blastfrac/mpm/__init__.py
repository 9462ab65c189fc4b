"""MPM detonation products: grid, shape functions, kernels, programmed burn, solver."""

from blastfrac.mpm.grid import Grid, GridSpec
from blastfrac.mpm.solver import MPMOptions, MPMSolver

__all__ = ["Grid", "GridSpec", "MPMOptions", "MPMSolver"]
