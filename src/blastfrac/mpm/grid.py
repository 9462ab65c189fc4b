"""Uniform background grid of the MPM explosive (METHOD §2.1).

Nodes (i, j) sit at x_0 + (i h, j h), 0 <= i < nx, 0 <= j < ny, flattened as
n = j * nx + i.  An axis may be periodic (then it has nx cells and nx nodes, and the
period is nx h); otherwise a particle must keep its 3-node stencil inside the grid or it
is deactivated.  Per-node boundary conditions: ``bc_mask`` bit 1 prescribes the x
velocity, bit 2 the y velocity, to the value in ``bc_vel`` (slip wall: one bit; fixed: both).

Walls (``Grid.set_walls``) are image walls.  A quadratic B-spline reaches 1.5 h, so a
particle next to a wall also weights the node *behind* it.  Holding every node at or behind
the wall at rest (the plain nodal condition) leaves the interpolated velocity at the wall
non-zero and the nodes near it short of mass and force: an elastic bar behaves as if
clamped a fraction of a cell behind the wall, a first-order error (the vibrating bar's
period comes out 1.35 % long at 25 cells, 0.31 % at 100), and gas at rest at uniform
pressure in a closed box is pushed towards the walls.  Instead the grid solves the problem
on the domain extended by reflection in the walls, one axis at a time (x walls, then y walls):

* after each P2G, a node behind a wall (a *ghost*) adds its mass, momentum and force to its
  image node inside, with a sign per component (-1: odd, +1: even); a node on the wall is
  its own image (its odd components cancel, its mass doubles);
* after each node update, a ghost takes its image's velocity and increment, signed.

Doing the axes in turn makes corners right (a corner ghost ends with the image through both
walls).  A slip wall is odd in the normal component and even in the tangential one (an
exact plane of symmetry); a fixed wall is odd in both (the usual no-slip image).  Nodes on
the wall also keep the nodal condition in ``bc_mask``.  The interpolated velocity then
meets the wall condition exactly, a uniform state is an exact equilibrium, and the
vibrating bar's period error converges at second order.  ``mirror[a]`` holds each node's
image across the walls normal to axis a (-1: none; the node itself: on the wall) and
``mirror_sign[a]`` the signs.  A wall that lies neither on a node nor half-way between two
nodes, or a ghost whose image is not strictly inside, falls back to the plain condition.

Active box.  The node loops (clearing, the momentum update, the remap velocity, the wall fold
and ghosts) run over a box of nodes that holds the particles, not over the whole grid, so that a
fine grid over a large rock costs what the gas touches.  ``Grid.box`` is (i0, j0, i1, j1), node
indices inclusive; ``box_node`` maps a launch index to a node.  The box is the particles' stencil
extent plus ``BOX_MARGIN`` cells and is renewed every ``BOX_STEPS`` steps from the extent that the
particle update accumulates in ``extent`` (min i, min j, max i, max j of the stencil base cells
since the last renewal).  A particle moves less than a cell per step (the CFL condition holds it
to alpha h with alpha <= 0.5), so in ``BOX_STEPS`` steps it cannot leave a box with that margin;
the renewal checks this on the accumulated extent, and a particle that broke it stops the run
with an error rather than giving a silently wrong step.  Outside the box the node arrays keep
whatever they last held: nothing reads them, because every particle's stencil lies inside, and
a node that enters the box is cleared before its first P2G.  The results are bit-identical to
the full-grid loops (tests/unit/test_grid_active_box.py).  A periodic axis keeps its full extent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import warp as wp

BC_X = 1
BC_Y = 2

#: steps between renewals of the active node box [-]
BOX_STEPS = 5
#: cells added to the particles' stencil extent on each side of the active box [-]: one per step
#: to the next renewal (a particle moves less than a cell per step) plus two for wall images
BOX_MARGIN = BOX_STEPS + 2
_NO_EXTENT = (2**30, 2**30, -1, -1)


class ActiveBoxError(RuntimeError):
    """A material point crossed more than a cell per step and left the active node box."""


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
        self.mirror = [wp.array(np.full(n, -1, dtype=np.int32), dtype=wp.int32, device=device) for _ in range(2)]
        self.mirror_sign = [wp.array(np.ones((n, 2)), dtype=wp.vec2d, device=device) for _ in range(2)]
        self.mirror_axes: tuple[int, ...] = ()
        self._walls: list[tuple[int, int, float, str]] = []
        self._base_mask = np.zeros(n, dtype=np.int32)
        # active box (module docstring): node indices, inclusive, and the particle extent since its renewal
        self.box_i0, self.box_j0, self.box_i1, self.box_j1 = 0, 0, spec.nx - 1, spec.ny - 1
        self.box_age = 0
        self.extent = wp.array(np.array(_NO_EXTENT, dtype=np.int32), dtype=wp.int32, device=device)

    # ------------------------------------------------------------------ active box
    @property
    def box(self) -> tuple[int, int, int, int]:
        """(i0, j0, i1, j1): the active node box, inclusive node indices [-]."""
        return self.box_i0, self.box_j0, self.box_i1, self.box_j1

    @property
    def box_node_count(self) -> int:
        """Nodes in the active box [-] (the launch size of the node loops)."""
        return (self.box_i1 - self.box_i0 + 1) * (self.box_j1 - self.box_j0 + 1)

    def box_args(self) -> list:
        """Kernel arguments (i0, j0, box width, nx) of :func:`box_node`."""
        return [self.box_i0, self.box_j0, self.box_i1 - self.box_i0 + 1, self.spec.nx]

    def renew_box(self, check: bool = True) -> None:
        """Set the active box from the accumulated particle extent (plus ``BOX_MARGIN``) and restart the
        accumulation.  With ``check``, first verify that the extent stayed inside the present box.

        Reads four integers from the device (one synchronisation every ``BOX_STEPS`` steps on a GPU).
        Raises :class:`ActiveBoxError` when a particle's stencil left the box since the last renewal.
        """
        s = self.spec
        e0, f0, e1, f1 = (int(v) for v in self.extent.numpy())
        self.box_age = 0
        if e1 < 0:                      # no active particle: an empty-ish box (one node) keeps launches valid
            self.box_i0, self.box_j0, self.box_i1, self.box_j1 = 0, 0, 0, 0
            return
        if check:
            inside_x = s.periodic_x or (e0 >= self.box_i0 and e1 + 2 <= self.box_i1)
            inside_y = s.periodic_y or (f0 >= self.box_j0 and f1 + 2 <= self.box_j1)
            if not (inside_x and inside_y):
                raise ActiveBoxError(
                    f"a material point's stencil reached cells ({e0}..{e1 + 2}, {f0}..{f1 + 2}) outside the active "
                    f"grid box ({self.box_i0}..{self.box_i1}, {self.box_j0}..{self.box_j1}) within {BOX_STEPS} "
                    "steps: it moved more than a cell per step (the MPM time step is too large for the gas speed)")
        m = BOX_MARGIN
        self.box_i0, self.box_i1 = (0, s.nx - 1) if s.periodic_x else (max(0, e0 - m), min(s.nx - 1, e1 + 2 + m))
        self.box_j0, self.box_j1 = (0, s.ny - 1) if s.periodic_y else (max(0, f0 - m), min(s.ny - 1, f1 + 2 + m))
        self.reset_extent()

    def reset_extent(self) -> None:
        """Empty the accumulated particle extent (the particle update then widens it again)."""
        self.extent.assign(np.array(_NO_EXTENT, dtype=np.int32))

    def set_walls(self, xmin=None, xmax=None, ymin=None, ymax=None, kind: str = "slip") -> None:
        """Walls at rest at the given coordinates [m]; kind 'slip' (normal velocity 0) or 'fixed' (both 0).

        Image walls (module docstring) where the wall lies on a node or half-way between two
        nodes; otherwise every node at or beyond the wall is held at rest.  Calls accumulate.
        """
        if kind not in ("slip", "fixed"):
            raise ValueError(f"unknown wall kind '{kind}'")
        if not self._walls:  # conditions set by hand before the first wall are kept
            self._base_mask = self.bc_mask.numpy().copy()
        for val, axis, side in ((xmin, 0, -1), (xmax, 0, 1), (ymin, 1, -1), (ymax, 1, 1)):
            if val is not None:
                self._walls.append((axis, side, float(val), kind))
        self._build_walls()

    def _build_walls(self) -> None:
        s = self.spec
        n = s.node_count
        pos = s.node_positions()
        ij = (np.arange(n) % s.nx, np.arange(n) // s.nx)
        counts, origin = (s.nx, s.ny), (s.x0, s.y0)
        tol = 1e-9 * s.h
        mask = self._base_mask.copy()
        axes = []
        for axis in (0, 1):
            mirror = np.full(n, -1, dtype=np.int64)
            sign = np.ones((n, 2))
            behind_any = np.zeros(n, dtype=bool)  # on or behind some wall of this axis
            plans = []
            for ax, side, val, kind in self._walls:
                if ax != axis:
                    continue
                d = (pos[:, axis] - val) * side  # >= 0: on or behind the wall
                sel = d >= -tol
                on = sel & (np.abs(d) <= tol)
                comps = (0, 1) if kind == "fixed" else (axis,)
                for c in comps:
                    mask[on] |= BC_X if c == 0 else BC_Y
                behind_any |= sel
                plans.append((sel, on, val, comps))
            for sel, on, val, comps in plans:
                two_w = 2.0 * (val - origin[axis]) / s.h  # image index along the axis: two_w - i
                k = int(round(two_w)) - ij[axis]
                ghost = sel & ~on
                ok = ghost & (abs(two_w - round(two_w)) < 1e-6) & (k >= 0) & (k < counts[axis])
                img = np.where(axis == 0, ij[1] * s.nx + k, k * s.nx + ij[0])
                ok[ok] &= ~behind_any[img[ok]]  # the image must be strictly inside
                mirror[ok] = img[ok]
                onw = on & (abs(two_w - round(two_w)) < 1e-6)
                mirror[onw] = np.arange(n)[onw]
                for c in comps:
                    sign[sel, c] = -1.0
                    mask[ghost & ~ok] |= BC_X if c == 0 else BC_Y  # no usable image: plain condition
            self.mirror[axis].assign(mirror.astype(np.int32))
            self.mirror_sign[axis].assign(sign)
            if (mirror >= 0).any():
                axes.append(axis)
        vel = self.bc_vel.numpy().copy()
        vel[mask != self._base_mask] = 0.0  # walls are at rest
        self.bc_mask.assign(mask)
        self.bc_vel.assign(vel)
        self.mirror_axes = tuple(axes)
