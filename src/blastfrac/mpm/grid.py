"""Uniform background grid of the MPM explosive (METHOD §2.1).

Nodes (i, j) sit at x_0 + (i h, j h), 0 <= i < nx, 0 <= j < ny, flattened as
n = j * nx + i.  An axis may be periodic (then it has nx cells and nx nodes, and the
period is nx h); otherwise a particle must keep its 3-node stencil inside the grid or it
is deactivated.  Per-node boundary conditions: ``bc_mask`` bit 1 prescribes the x
velocity, bit 2 the y velocity, to the value in ``bc_vel`` (slip wall: one bit; fixed: both).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import warp as wp

BC_X = 1
BC_Y = 2


@dataclass(frozen=True)
class GridSpec:
    """Geometry of the grid: origin (x0, y0) [m], cell size h [m], node counts, periodic flags."""

    x0: float
    y0: float
    h: float
    nx: int
    ny: int
    periodic_x: bool = False
    periodic_y: bool = False

    @classmethod
    def from_bounds(cls, lo, hi, h: float, pad_cells: int = 2, align: bool = True) -> GridSpec:
        """Grid covering the box lo..hi [m] plus ``pad_cells`` cells each side (stencil room)."""
        x0, y0 = lo[0] - pad_cells * h, lo[1] - pad_cells * h
        if align:
            x0, y0 = math.floor(x0 / h) * h, math.floor(y0 / h) * h
        nx = int(math.ceil((hi[0] + pad_cells * h - x0) / h - 1e-9)) + 1
        ny = int(math.ceil((hi[1] + pad_cells * h - y0) / h - 1e-9)) + 1
        return cls(x0, y0, h, nx, ny)

    @property
    def node_count(self) -> int:
        return self.nx * self.ny

    @property
    def upper(self) -> tuple[float, float]:
        """Upper corner of the covered box [m] (the period end on periodic axes)."""
        lx = self.nx if self.periodic_x else self.nx - 1
        ly = self.ny if self.periodic_y else self.ny - 1
        return (self.x0 + lx * self.h, self.y0 + ly * self.h)

    def node_positions(self) -> np.ndarray:
        """Node coordinates [m], shape [node_count, 2]."""
        i, j = np.meshgrid(np.arange(self.nx), np.arange(self.ny), indexing="xy")
        return np.stack([self.x0 + i.ravel() * self.h, self.y0 + j.ravel() * self.h], axis=1)


class Grid:
    """Preallocated node arrays on ``device`` (float64).

    mass [kg/m], mom [kg/s per m = N s/m], force [N/m], vel and dvel [m/s] (velocity after the
    update and its increment in the step), bc_mask [int32], bc_vel [m/s]; each shape [node_count].
    """

    def __init__(self, spec: GridSpec, device: str):
        n = spec.node_count
        self.spec = spec
        self.mass = wp.zeros(n, dtype=wp.float64, device=device)
        self.mom = wp.zeros(n, dtype=wp.vec2d, device=device)
        self.force = wp.zeros(n, dtype=wp.vec2d, device=device)
        self.vel = wp.zeros(n, dtype=wp.vec2d, device=device)
        self.dvel = wp.zeros(n, dtype=wp.vec2d, device=device)
        self.bc_mask = wp.zeros(n, dtype=wp.int32, device=device)
        self.bc_vel = wp.zeros(n, dtype=wp.vec2d, device=device)

    def set_walls(self, xmin=None, xmax=None, ymin=None, ymax=None, kind: str = "slip") -> None:
        """Walls on the nodes at or beyond the given coordinates [m]; kind 'slip' or 'fixed'."""
        pos = self.spec.node_positions()
        mask = self.bc_mask.numpy().copy()
        tol = 1e-9 * self.spec.h
        both = BC_X | BC_Y
        for val, axis, side in ((xmin, 0, -1), (xmax, 0, 1), (ymin, 1, -1), (ymax, 1, 1)):
            if val is None:
                continue
            sel = (pos[:, axis] <= val + tol) if side < 0 else (pos[:, axis] >= val - tol)
            mask[sel] |= both if kind == "fixed" else (BC_X if axis == 0 else BC_Y)
        self.bc_mask.assign(mask)
