"""Size estimates of a scenario before it is meshed: rock elements, material points and MPM grid nodes.

``check`` prints them and ``check`` / ``run`` refuse a scenario above the limits below unless ``--force``
is given, so that a mistyped mesh size ends in a message instead of minutes of meshing or an exhausted memory.

Elements: gmsh's size field is h_near at the borehole walls, growing linearly with the distance d from a wall
to mesh_size at d = refinement_distance (default 10·r_b), and mesh_size beyond (geometry/mesh.py); a borehole's own
mesh_size without mesh_size_near spreads over about 0.7 of its distance to the domain boundary. A
triangulation of size h has about 1/(C·h²) triangles per unit area; C = 0.375 is fitted to the shipped
examples (their counts come within 2 %). The estimate integrates 1/(C·h(x)²) over the rock, the
graded band around each hole in polar coordinates clipped to the domain. Material points: the charges' area
over the point spacing squared (spacing = cell_size/points_per_cell). Grid nodes: the grid's box over the
cell size squared.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ScenarioError

#: refuse (without --force) a scenario whose rock mesh is estimated above this many elements
MAX_ELEMENTS = 3_000_000
#: ... or whose charges hold more material points than this
MAX_PARTICLES = 2_000_000
#: ... or whose MPM background grid has more nodes than this
MAX_GRID_NODES = 20_000_000

#: triangles per unit area of a mesh of size h = 1/(C h²)
ELEMENT_AREA_FACTOR = 0.375


@dataclass
class SizeEstimate:
    elements: int | None            # None with an external mesh file
    particles: int
    grid_nodes: int
    detail: str                      # how the element estimate was made (for messages)
    near_share: float = 0.0          # part of the elements in the graded bands around the holes

    def rows(self) -> list[tuple[str, str]]:
        el = "from the mesh file" if self.elements is None else f"~{self.elements:,} (limit {MAX_ELEMENTS:,})"
        rows = [("estimated elements", el)]
        if self.particles or self.grid_nodes:
            rows.append(("estimated material points", f"~{self.particles:,} (limit {MAX_PARTICLES:,})"))
            rows.append(("estimated grid nodes", f"~{self.grid_nodes:,} (limit {MAX_GRID_NODES:,})"))
        return rows


def _inside(domain, pts: np.ndarray) -> np.ndarray:
    from . import _geometry as geo
    from .schema import DiscDomain, RectangleDomain

    if isinstance(domain, RectangleDomain):
        (x0, y0), (x1, y1) = domain.bbox
        return (pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1)
    if isinstance(domain, DiscDomain):
        return np.hypot(pts[:, 0] - domain.center[0], pts[:, 1] - domain.center[1]) <= domain.radius
    return geo.points_in_polygon(pts, domain.vertices)


def _boundary_distance(domain, p) -> float:
    from . import _geometry as geo
    from .schema import DiscDomain

    if isinstance(domain, DiscDomain):
        return domain.radius - math.dist(p, domain.center)
    return geo.polygon_dist(p, domain.polygon)


def estimate_elements(geom) -> tuple[int | None, str, float]:
    """Estimated triangle count of the gmsh mesh of ``geom``, a one-line description, the graded bands' share."""
    if geom.mesh_file is not None:
        return None, "external mesh file", 0.0
    h = geom.mesh_size
    holes = geom.boreholes
    rock_area = max(geom.domain.area - sum(math.pi * b.radius**2 for b in holes), 0.0)
    base = integral = rock_area / h**2               # ∫ h(x)^-2 dA with h = mesh_size everywhere
    h_near = geom.mesh_size_near or h
    refined = bool(holes) and h_near < h
    dist = geom.refinement_distance or (10.0 * max((b.radius for b in holes), default=0.0))
    graded = []
    for i, b in enumerate(holes):
        # mesh.py: with refinement every wall gets h_near from the size field (point sizes are then ignored);
        # without it a hole's own mesh_size, if finer, spreads from its wall over about 0.7 of the way to the
        # domain's boundary (gmsh's extension of boundary sizes; fitted within about 10 %)
        if refined:
            h0, dist_i = h_near, dist
        else:
            h0, dist_i = min(b.mesh_size or h, h), 0.7 * _boundary_distance(geom.domain, b.center)
        if h0 >= h or dist_i <= 0:
            continue
        graded.append((i, b, h0, dist_i))
    if graded:
        n_u, n_t = 48, 96
        th = (np.arange(n_t) + 0.5) * 2 * math.pi / n_t
        circ = np.stack([np.cos(th), np.sin(th)], axis=1)
        centers = np.array([b.center for b in holes], float)
        radii = np.array([b.radius for b in holes], float)
        for i, b, h0, dist in graded:
            k = (h - h0) / dist                      # h(d) = h0 + k d for 0 <= d <= dist
            # no rock farther from the wall than the domain box's farthest corner
            (x0, y0), (x1, y1) = geom.domain.bbox
            reach = max(math.dist(b.center, q) for q in ((x0, y0), (x1, y0), (x0, y1), (x1, y1))) - b.radius
            d_end = min(dist, max(reach, 0.0))
            u_end = h0 + k * d_end
            if u_end > 1.01 * h0:
                # nodes uniform in ln u, u = h(d): the integrand ∝ 1/u² is resolved at the wall and far out
                d = (h0 * (u_end / h0) ** np.linspace(0.0, 1.0, n_u + 1) - h0) / k
            else:                                    # h hardly grows within the domain
                d = np.linspace(0.0, d_end, n_u + 1)
            u = h0 + k * d
            r = b.radius + d
            # fraction of each circle of radius r that is rock nearest to this hole (inside the domain)
            frac = np.empty(len(r))
            for j, rj in enumerate(r):
                pts = np.asarray(b.center) + rj * circ
                ok = _inside(geom.domain, pts)
                if len(holes) > 1:
                    dw = np.hypot(pts[:, None, 0] - centers[None, :, 0], pts[:, None, 1] - centers[None, :, 1]) - radii
                    ok &= np.argmin(dw, axis=1) == i
                    ok &= np.all(dw >= 0, axis=1)
                frac[j] = ok.mean()
            f = 2 * math.pi * r * frac * (1.0 / u**2 - 1.0 / h**2)
            integral += float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(d)))
    n = int(round(min(integral / ELEMENT_AREA_FACTOR, 1e18)))
    how = f"rock area {rock_area:.4g} m², mesh_size {h:.4g} m"
    if graded:
        how += f", {graded[0][2]:.4g} m at the walls graded over {graded[0][3]:.4g} m"
    return n, how, (integral - base) / integral if integral > 0 else 0.0


def _mpm_regions(ex, geom=None) -> list:
    """The charges (cut at geometry.symmetry's lines when a geometry is given: a half or quarter model seeds the
    modelled part only) and the elastic bodies: every region the run fills with material points."""
    charges = list(ex.charges)
    if geom is not None and getattr(geom, "symmetry", None):
        from ..mpm.seeding import cut_charges

        charges = cut_charges(charges, geom.symmetry_lines())
    return charges + list(getattr(ex, "bodies", []) or [])


def estimate_particles(ex, geom=None) -> int:
    """Material points the run seeds: the charges' (modelled part) and bodies' area over the point spacing²."""
    s = ex.grid.cell_size / ex.grid.points_per_cell
    return int(round(sum(r.area for r in _mpm_regions(ex, geom)) / s**2))


def estimate_grid_nodes(ex, geom) -> int:
    """Nodes of the MPM grid the run builds (simulation.py / mpm.solver.grid_from_config, 2 pad cells a side)."""
    g = ex.grid
    if g.bounds is not None:
        (x0, y0), (x1, y1) = g.bounds
    else:
        boxes = [r.bbox for r in _mpm_regions(ex, geom)]
        (x0, y0), (x1, y1) = (min(b[0][0] for b in boxes), min(b[0][1] for b in boxes)), \
                             (max(b[1][0] for b in boxes), max(b[1][1] for b in boxes))
        if g.margin is None and geom.mesh_file is None:
            (x0, y0), (x1, y1) = geom.domain.bbox      # the run's default: the rock's box
        else:
            m = g.margin if g.margin is not None else max(x1 - x0, y1 - y0)
            x0, y0, x1, y1 = x0 - m, y0 - m, x1 + m, y1 + m
    nx = (x1 - x0) / g.cell_size + 6
    ny = (y1 - y0) / g.cell_size + 6
    return int(min(nx * ny, 1e18))


def estimate(scenario) -> SizeEstimate:
    elements, how, near = estimate_elements(scenario.geometry)
    ex = scenario.explosive
    particles = estimate_particles(ex, scenario.geometry) if ex is not None else 0
    nodes = estimate_grid_nodes(ex, scenario.geometry) if ex is not None else 0
    return SizeEstimate(elements, particles, nodes, how, near)


def check_sizes(scenario, force: bool = False) -> SizeEstimate:
    """The estimate; raises ScenarioError above a limit unless ``force``."""
    est = estimate(scenario)
    if force:
        return est
    hint = " (or pass --force to run it anyway)"
    if est.elements is not None and est.elements > MAX_ELEMENTS:
        g = scenario.geometry
        if est.near_share > 0.5:
            key = "geometry.mesh_size_near" if g.mesh_size_near is not None else "geometry.boreholes[].mesh_size"
        else:
            key = "geometry.mesh_size"
        raise ScenarioError(
            f"{key}: the rock mesh would have about {est.elements:,} elements ({est.detail}), above "
            f"the limit of {MAX_ELEMENTS:,}; use a larger {key} or a smaller domain{hint}")
    if est.particles > MAX_PARTICLES:
        ex = scenario.explosive
        raise ScenarioError(
            f"explosive.grid.cell_size: the charges and bodies would hold about {est.particles:,} material points "
            f"(area {sum(r.area for r in _mpm_regions(ex, scenario.geometry)):.4g} m², spacing cell_size/points_per_cell = "
            f"{ex.grid.cell_size / ex.grid.points_per_cell:.4g} m), above the limit of {MAX_PARTICLES:,}; use a "
            f"larger explosive.grid.cell_size or fewer points_per_cell{hint}")
    if est.grid_nodes > MAX_GRID_NODES:
        raise ScenarioError(
            f"explosive.grid.cell_size: the MPM grid would have about {est.grid_nodes:,} nodes (cell_size "
            f"{scenario.explosive.grid.cell_size:.4g} m), above the limit of {MAX_GRID_NODES:,}; use a larger "
            f"explosive.grid.cell_size or smaller explosive.grid.bounds{hint}")
    return est
