"""The MPM grid's active node box (:mod:`blastfrac.mpm.grid`): the node loops run only around the particles.

Checked against the full-grid loops, which are what the box must reproduce:
* a detonating PETN disc next to a slip wall and a fixed wall in a grid ten times its size gives bit-identical
  particle positions, velocities, energies and stresses with the box as with the box widened to the whole grid;
* the box is much smaller than the grid, holds every particle's 3 x 3 stencil with the margin, and follows the
  expanding gas;
* a particle moved by hand more than a cell per step stops the run at the next renewal (never a silently wrong
  step), and an empty solver keeps a valid one-node box.
"""

import numpy as np
import pytest

import blastfrac.mpm.grid as grid_mod
from blastfrac.mpm import MPMSolver
from blastfrac.mpm.grid import BOX_MARGIN, BOX_STEPS, ActiveBoxError
from blastfrac.scenario.explosive import ExplosiveConfig

R = 0.004


def _solver():
    cfg = ExplosiveConfig(
        name="petn", charges=[{"kind": "circle", "center": (0.0, 0.0), "radius": R}],
        grid={"cell_size": 5e-4, "bounds": ((-0.006, -0.05), (0.05, 0.05)), "points_per_cell": 2,
              "boundaries": {"left": "slip", "bottom": "fixed"}},
    )
    return MPMSolver(cfg)


def _run(s, steps):
    t = 0.0
    for _ in range(steps):
        dt = s.stable_dt()
        s.step(dt, t)
        t += dt


def _fields(s):
    return {k: getattr(s, k).numpy().copy() for k in ("x", "v", "ie", "stress", "vol", "burn")}


def test_box_is_bit_identical_to_the_full_grid(monkeypatch):
    box = _solver()
    _run(box, 240)
    monkeypatch.setattr(grid_mod, "BOX_MARGIN", 10**6)     # the box clamps to the whole grid
    full = _solver()
    assert full.grid.box_node_count == full.spec.node_count
    _run(full, 240)
    a, b = _fields(box), _fields(full)
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    assert box.energies() == full.energies()
    # the box is a small part of this grid, and covers every particle's stencil plus the margin
    assert box.grid.box_node_count < 0.2 * box.spec.node_count
    act = box.active.numpy().astype(bool)
    f = (box.x.numpy()[act] - (box.spec.x0, box.spec.y0)) / box.spec.h
    base = np.floor(f - 0.5).astype(int)
    i0, j0, i1, j1 = box.grid.box
    assert base[:, 0].min() >= i0 and base[:, 0].max() + 2 <= i1
    assert base[:, 1].min() >= j0 and base[:, 1].max() + 2 <= j1


def test_box_follows_the_gas():
    s = _solver()
    w0 = s.grid.box_i1 - s.grid.box_i0
    seeded = 2 * R / s.spec.h
    assert w0 <= seeded + 2 * BOX_MARGIN + 4
    _run(s, 400)
    x = s.x.numpy()[s.active.numpy().astype(bool)]
    assert x[:, 0].max() > 1.5 * R                         # the gas has expanded ...
    assert s.grid.box_i1 - s.grid.box_i0 > w0              # ... and the box with it


def test_a_particle_that_jumps_stops_the_run():
    s = _solver()
    _run(s, 3)
    x = s.x.numpy().copy()
    x[0] += (0.03, 0.0)                                    # 60 cells in one step
    s.x.assign(x)
    with pytest.raises(ActiveBoxError, match="more than a cell per step"):
        _run(s, BOX_STEPS)


def test_no_active_particle_keeps_a_valid_box():
    s = _solver()
    s.active.zero_()
    s._init_active_box()
    assert s.grid.box_node_count == 1
    _run(s, BOX_STEPS + 1)
