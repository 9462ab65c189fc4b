"""Scenario section ``[explosive]``: the MPM detonation-products model and elastic MPM bodies (pydantic v2).

SI units throughout.  The explosive is either a library name (``name``) or a full
custom JWL set (``constants``), never both; a run without charges (elastic bodies only, an
impactor) needs neither.  Example::

    [explosive]
    name = "emulsion"
    charges = [{ kind = "circle", center = [0.0, 0.0], radius = 0.02 }]
    detonation_points = [{ position = [0.0, 0.0], delay = 0.0 }]
    detonation_lines = [{ start = [0.0, -0.02], end = [0.0, 0.02], delay = 0.0, velocity = 7000.0 }]
    [explosive.grid]
    cell_size = 0.002
    margin = 0.06

    [[explosive.bodies]]          # an elastic body on the same grid (mpm/bodies.py)
    kind = "circle"
    center = [0.1, 0.0]
    radius = 0.01
    density = 7800.0
    youngs_modulus = 200e9
    poisson_ratio = 0.3
    velocity = [-50.0, 0.0]
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from . import _geometry as geo

Point = tuple[float, float]


class _Model(BaseModel):
    # allow_inf_nan=False: every float, also inside tuples, lists and nested models, must be finite
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class JWLConstants(_Model):
    """A custom JWL set with its detonation velocity."""

    rho0: float = Field(gt=0, le=5000, description="initial explosive density [kg/m^3]")
    D: float = Field(gt=0, le=12000, description="detonation velocity used for lighting times [m/s]")
    A: float = Field(ge=0, description="JWL coefficient A [Pa]")
    B: float = Field(ge=0, description="JWL coefficient B [Pa]")
    R1: float = Field(gt=0, le=20, description="JWL exponent R1 [-]")
    R2: float = Field(gt=0, le=20, description="JWL exponent R2 [-]")
    omega: float = Field(gt=0, le=3, description="JWL Grueneisen coefficient omega [-]")
    E0: float = Field(gt=0, le=5e10, description="detonation energy per unit initial volume [J/m^3]")


class GasState(_Model):
    """Burnt products in a given state from t = 0 (a gas region: no burn, no chemical energy to release)."""

    density: float = Field(gt=0, le=1e5, description="density of the products [kg/m^3]")
    pressure: float = Field(ge=0, le=1e12, description="pressure [Pa]; the internal energy follows from the JWL")
    velocity: Point = Field(default=(0.0, 0.0), description="velocity (vx, vy) [m/s]")


_GAS_STATE_DOC = ("burnt products in this state from t = 0 instead of an explosive that detonates: a gas region "
                  "(shock tube, gas-only run); its initial internal energy counts as the energy supplied "
                  "(explosive_released)")


class _CircleShape(_Model):
    """A circle: the shape of a charge or a body."""

    kind: Literal["circle"] = Field(description="shape tag")
    center: Point = Field(description="centre (x, y) [m]")
    radius: float = Field(gt=0, description="radius [m]")

    @property
    def area(self) -> float:
        return math.pi * self.radius**2

    @property
    def bbox(self) -> tuple[Point, Point]:
        (x, y), r = self.center, self.radius
        return (x - r, y - r), (x + r, y + r)

    def contains(self, p: Point, tol: float = 1e-9) -> bool:
        """p inside or on the circle (within tol·radius)."""
        return math.dist(p, self.center) <= self.radius * (1 + tol)

    def meets_segment(self, a: Point, b: Point, tol: float = 1e-9) -> bool:
        """The segment ab has a point inside or on the circle (within tol·radius)."""
        return geo.seg_dist(self.center, a, b) <= self.radius * (1 + tol)


class _PolygonShape(_Model):
    """A simple polygon, vertices in order (either orientation): the shape of a charge or a body."""

    kind: Literal["polygon"] = Field(description="shape tag")
    vertices: list[Point] = Field(min_length=3, description="vertices (x, y) [m], at least 3")

    @model_validator(mode="after")
    def _simple(self) -> _PolygonShape:
        v = self.vertices
        rep = geo.repeated_vertex(v)
        if rep is not None:
            raise ValueError(f"vertices[{rep[1]}]: {v[rep[1]]} repeats vertices[{rep[0]}]; every vertex must be distinct")
        if geo.polygon_area(v) == 0:
            raise ValueError("vertices: the polygon encloses no area")
        cross = geo.polygon_self_intersection(v)
        if cross is not None:
            raise ValueError(f"vertices: sides {cross[0]} and {cross[1]} meet; the polygon must not intersect itself")
        return self

    @property
    def area(self) -> float:
        return abs(geo.polygon_area(self.vertices))

    @property
    def bbox(self) -> tuple[Point, Point]:
        xs, ys = [p[0] for p in self.vertices], [p[1] for p in self.vertices]
        return (min(xs), min(ys)), (max(xs), max(ys))

    def contains(self, p: Point, tol: float = 1e-9) -> bool:
        """p inside or on the polygon (within tol of its size)."""
        (x0, y0), (x1, y1) = self.bbox
        return geo.point_in_polygon(p, self.vertices) or geo.polygon_dist(p, self.vertices) <= tol * max(x1 - x0, y1 - y0)

    def meets_segment(self, a: Point, b: Point, tol: float = 1e-9) -> bool:
        """The segment ab has a point inside or on the polygon."""
        if self.contains(a, tol) or self.contains(b, tol):
            return True
        v = self.vertices
        return any(geo.segments_touch(a, b, v[i], v[(i + 1) % len(v)]) for i in range(len(v)))


class CircleCharge(_CircleShape):
    """A circular charge (a borehole section in plane strain)."""

    gas_state: GasState | None = Field(default=None, description=_GAS_STATE_DOC)


class PolygonCharge(_PolygonShape):
    """A polygonal charge; vertices in order (either orientation)."""

    gas_state: GasState | None = Field(default=None, description=_GAS_STATE_DOC)


Charge = Annotated[CircleCharge | PolygonCharge, Field(discriminator="kind")]


class _ElasticBodyMaterial(_Model):
    """The material and initial velocity of an elastic MPM body (mpm/bodies.py)."""

    density: float = Field(gt=0, le=1e5, description="mass density [kg/m^3], at most 1e5")
    youngs_modulus: float = Field(gt=0, le=1e13, description="Young's modulus [Pa], at most 1e13")
    poisson_ratio: float = Field(ge=0, lt=0.5, description="Poisson's ratio [-], in [0, 0.5)")
    velocity: Point = Field(default=(0.0, 0.0), description="initial velocity (vx, vy) [m/s] of the whole body")
    name: str | None = Field(default=None, pattern=r"^[A-Za-z0-9_\-]+$",
                             description="label of the body in summary.json (letters, digits, _ and -); default body<k>")

    @property
    def p_wave_speed(self) -> float:
        """Plane-strain P-wave speed sqrt((λ + 2μ)/ρ) [m/s]."""
        e, nu = self.youngs_modulus, self.poisson_ratio
        return math.sqrt(e * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / self.density)


class CircleBody(_ElasticBodyMaterial, _CircleShape):
    """A circular elastic body (a disk; a rod in plane strain)."""


class PolygonBody(_ElasticBodyMaterial, _PolygonShape):
    """A polygonal elastic body (a slab, a plate); vertices in order (either orientation)."""


Body = Annotated[CircleBody | PolygonBody, Field(discriminator="kind")]


def shapes_overlap(a, b, tol: float = 1e-9) -> bool:
    """True when two charge/body shapes share area (touching along a boundary is allowed); tol relative to the
    shapes' size."""
    scale = max(max(q - p for p, q in zip(*sh.bbox)) for sh in (a, b))
    t = tol * scale
    if a.kind == "circle" and b.kind == "circle":
        return math.dist(a.center, b.center) < a.radius + b.radius - t
    if a.kind == "polygon" and b.kind == "polygon":
        return geo.polygons_overlap(a.vertices, b.vertices, t)
    c, q = (a, b) if a.kind == "circle" else (b, a)
    return geo.point_in_polygon(c.center, q.vertices) or geo.polygon_dist(c.center, q.vertices) < c.radius - t


class DetonationPoint(_Model):
    """An initiation point; lighting time t_l = |X - position| / D + delay."""

    position: Point = Field(description="initiation point (x, y) [m]")
    delay: float = Field(default=0.0, ge=0, description="initiation delay [s]")


class DetonationLine(_Model):
    """A line initiator (detonating cord) from ``start`` to ``end``, fired at ``start`` at ``delay``; its front runs
    along the segment at ``velocity``: the point at distance s from ``start`` lights at delay + s / velocity, and a
    particle at X lights at min over the segment points y of (their lighting time + |X - y| / D).  With
    ``simultaneous`` the whole segment fires at ``delay`` (a plane-wave generator: in 2D the initiating plane is
    this line), and X lights at delay + dist(X, segment) / D."""

    start: Point = Field(description="end of the cord that is fired (x, y) [m]")
    end: Point = Field(description="other end of the cord (x, y) [m]")
    delay: float = Field(default=0.0, ge=0, description="firing time of ``start`` [s]")
    velocity: float | None = Field(
        default=None, gt=0, description="speed of the lighting front along the cord [m/s]; default: the explosive's D"
    )
    simultaneous: bool = Field(
        default=False, description="fire the whole line at ``delay`` (plane-wave initiation); excludes ``velocity``"
    )

    @model_validator(mode="after")
    def _length(self) -> DetonationLine:
        if self.start == self.end:
            raise ValueError("end: equals start; a detonation line needs two distinct ends")
        if self.simultaneous and self.velocity is not None:
            raise ValueError("velocity: not allowed with simultaneous = true (the whole line fires at its delay); "
                             "give one or the other")
        return self


BoundaryKind = Literal["open", "fixed", "slip"]


class GridBoundaries(_Model):
    """Conditions on the four sides of the grid box: 'open' (particles that leave are deactivated), 'fixed' (grid
    velocity 0 on the side) or 'slip' (normal grid velocity 0), as image walls at rest (:mod:`blastfrac.mpm.grid`)."""

    left: BoundaryKind = Field(default="open", description="side x = xmin")
    right: BoundaryKind = Field(default="open", description="side x = xmax")
    bottom: BoundaryKind = Field(default="open", description="side y = ymin")
    top: BoundaryKind = Field(default="open", description="side y = ymax")


class GridConfig(_Model):
    """Background grid; bounds win over margin when both are given."""

    cell_size: float = Field(gt=0, description="grid cell size h [m]")
    bounds: tuple[Point, Point] | None = Field(
        default=None, description="grid box ((xmin, ymin), (xmax, ymax)) [m]; default: the box of the charges (and "
        "bodies) plus margin; required without charges"
    )
    margin: float | None = Field(
        default=None, ge=0, description="clearance added around the charges' (and bodies') box [m]; default: the box's "
        "larger side"
    )
    points_per_cell: int = Field(default=2, ge=1, le=6, description="material points per cell per direction [-]")
    boundaries: GridBoundaries = Field(
        default_factory=GridBoundaries, description="side conditions of the grid box (left, right, bottom, top: "
        "'open', 'fixed' or 'slip'); a wall lies on the box (bounds, or the charges' and bodies' box plus margin) widened outwards "
        "to the nearest grid lines (multiples of cell_size); default: all open"
    )

    @model_validator(mode="after")
    def _check_bounds(self) -> GridConfig:
        if self.bounds is not None:
            (x0, y0), (x1, y1) = self.bounds
            if not (x1 > x0 and y1 > y0):
                raise ValueError("grid.bounds must be ((xmin, ymin), (xmax, ymax)) with xmax > xmin and ymax > ymin")
        return self


class BurnConfig(_Model):
    """Programmed burn (METHOD §2.4)."""

    mode: Literal["combined", "time", "volumetric", "instant"] = Field(
        default="combined", description="burn law: max(time, volumetric), one of them, or all burnt at t=0"
    )
    width_factor: float = Field(
        default=1.5, gt=0, le=10, description="time-burn width in particle lengths (F1 = (t-t_l) D / (k h_e)) [-]"
    )
    p_cj: float | None = Field(
        default=None, gt=0, description="CJ pressure for the volumetric burn [Pa]; default: from the JWL Hugoniot"
    )


class ExplosiveConfig(_Model):
    """MPM explosive section: JWL set, charges, elastic bodies, initiation, grid and numerical options."""

    name: str | None = Field(default=None, description="library explosive: emulsion, petn, tnt, anfo; needed "
                             "with charges (or constants), not for elastic bodies alone")
    constants: JWLConstants | None = Field(default=None, description="custom JWL set (instead of name)")
    charges: list[Charge] = Field(
        default_factory=list, description="charge regions filled with material points; at least one charge or body"
    )
    bodies: list[Body] = Field(
        default_factory=list, description="elastic MPM bodies ([[explosive.bodies]]: an impactor, a flyer plate): "
        "regions of material points with their own density, Young's modulus, Poisson's ratio and initial velocity "
        "on the explosive's grid (no slip against the gas on the grid); they touch the rock through the particle-edge "
        "contact; each lies in a borehole or outside the rock and overlaps no charge or other body (docs/explosive.md)"
    )
    detonation_points: list[DetonationPoint] = Field(
        default_factory=list, description="initiation points; each lights the charge it lies in (and the charges "
        "touching it), never through rock; default: the centroid of each charge, no delay"
    )
    detonation_lines: list[DetonationLine] = Field(
        default_factory=list, description="line initiators (detonating cords), lit together with detonation_points: "
        "t_l is the earliest over both, each lighting only the charges it touches; with neither, each charge "
        "lights at its centroid"
    )
    grid: GridConfig = Field(description="background grid")
    seeding: Literal["conformal", "lattice"] = Field(
        default="conformal", description="material-point layout: 'conformal' seeds circle charges on concentric rings "
        "whose outer ring touches the circle (no void between a borehole-filling charge and the wall; polygons use the "
        "lattice); 'lattice' puts every charge on the grid sub-lattice, which leaves a ragged void up to one point "
        "spacing wide along a circle"
    )
    shape: Literal["bspline2", "ugimp"] = Field(
        default="bspline2", description="shape functions: quadratic B-spline or uGIMP (l_p = h/(2 ppc))"
    )
    transfer: Literal["flip", "apic"] = Field(
        default="flip", description="grid-to-particle velocity transfer: 'flip' (the FLIP/PIC blend set by `flip`) or "
        "'apic' (affine particle-in-cell, Jiang et al. 2015: each point also carries the affine moment B_p [m^2/s] of "
        "its velocity field, C_p = B_p D_p^-1 [1/s]; conserves linear and angular momentum; `flip` is then unused). "
        "Measured (docs/explosive.md): APIC quiets Sod's tube but its transfers lose 12 % of the kinetic energy, its "
        "shock lags 2.5 cells and a wall-initiated slab delivers 2.4 % less impulse than exact, hence the FLIP blend "
        "is the default"
    )
    flip: float = Field(
        default=0.99, ge=0, le=1, description="FLIP fraction of the FLIP/PIC velocity blend of the detonation products "
        "(1 = pure FLIP, as MPM3D; 0 = PIC), used when transfer = 'flip' [-]; elastic bodies use `flip_bodies`. Default 0.99 (since 0.2; was 1.0) with blend_heating and q2 = 2: "
        "chosen on Sod's tube (overshoot 46 % -> 4.3 %, plateaus within 1 %) and the wall impulse of a detonating slab "
        "(within 1.8 %), and it removes pure FLIP's long-run velocity noise in a sealed hole (docs/explosive.md, "
        "'Velocity transfer')"
    )
    flip_bodies: float = Field(
        default=1.0, ge=0, le=1, description="FLIP fraction of the elastic bodies' points (`bodies`), used when "
        "transfer = 'flip' [-]; `flip` is the gas's. Default 1 (pure FLIP): a body's kinetic energy is not heat, so a "
        "PIC share would dissipate it unbooked (a vibrating bar loses its energy)"
    )
    blend_heating: bool = Field(
        default=True, description="with transfer = 'flip' and flip < 1: the kinetic energy the PIC share removes "
        "from each gas point, ½m(|v_FLIP|² − |v|²), goes into its internal energy, so the blend damps the "
        "particles' velocity noise without losing energy (docs/explosive.md, 'Velocity transfer')"
    )
    cfl: float = Field(default=0.2, gt=0, le=0.5, description="CFL factor alpha in dt = alpha h / max(c + |v|) [-]")
    q1: float = Field(default=1.5, ge=0, le=10, description="quadratic artificial-viscosity coefficient Q1 [-] "
                      "of q = ρl(Q1·l·(tr D)² − Q2·c·tr D), l = √V_p the point spacing")
    q2: float = Field(default=2.0, ge=0, le=5, description="linear artificial-viscosity coefficient Q2 [-]; c is the "
                      "products' own sound speed (of the burnt share). Default 2 (since 0.2; was 0.06, applied to the "
                      "time step's signal speed): about 1 on the cell width at 2 points per cell, measured on Sod's "
                      "tube and the slab's wall impulse (docs/explosive.md, 'Artificial viscosity')")
    mass_cutoff: float = Field(
        default=1e-5, ge=0, lt=1, description="node mass cut-off as a fraction of rho0 h^2 (per unit thickness) [-]"
    )
    v_max: float = Field(
        default=100.0, gt=1, description="relative volume beyond which the products' pressure is frozen to 0 [-]"
    )
    burn: BurnConfig = Field(default_factory=BurnConfig, description="programmed burn options")

    @model_validator(mode="after")
    def _one_source(self) -> ExplosiveConfig:
        if not self.charges and not self.bodies:
            raise ValueError("charges: give at least one charge (or an elastic body in explosive.bodies)")
        if self.name is not None and self.constants is not None:
            raise ValueError("give exactly one of explosive.name (library) or explosive.constants (custom JWL set)")
        if self.charges and self.name is None and self.constants is None:
            raise ValueError("give exactly one of explosive.name (library) or explosive.constants (custom JWL set)")
        if self.name is not None:
            from blastfrac.explosives.library import get_explosive

            try:
                get_explosive(self.name)
            except KeyError as exc:
                raise ValueError("name: " + str(exc.args[0])) from None
        for j, ch in enumerate(self.charges):
            for i in range(j):
                if ch == self.charges[i]:
                    raise ValueError(f"charges[{j}]: repeats charges[{i}]")
        shapes = [(f"charges[{i}]", ch) for i, ch in enumerate(self.charges)]
        shapes += [(f"bodies[{i}]", b) for i, b in enumerate(self.bodies)]
        spacing = self.grid.cell_size / self.grid.points_per_cell
        for key, ch in shapes:
            if ch.area < spacing**2:
                raise ValueError(f"grid.cell_size: the particle spacing cell_size/points_per_cell = {spacing:.4g} m leaves "
                                 f"{key} (area {ch.area:.4g} m²) less than one material point; use a finer grid")
        if self.grid.bounds is not None:
            (x0, y0), (x1, y1) = self.grid.bounds
            tol = 1e-9 * max(x1 - x0, y1 - y0)
            for key, ch in shapes:
                (a0, b0), (a1, b1) = ch.bbox
                if a0 < x0 - tol or b0 < y0 - tol or a1 > x1 + tol or b1 > y1 + tol:
                    raise ValueError(f"grid.bounds: (({x0:.6g}, {y0:.6g}), ({x1:.6g}, {y1:.6g})) does not cover "
                                     f"{key} (box ({a0:.6g}, {b0:.6g})–({a1:.6g}, {b1:.6g})); the grid must "
                                     "cover every charge and body")
        elif not self.charges:
            raise ValueError("grid.bounds: needed without charges (elastic bodies only): give the grid box "
                             "((xmin, ymin), (xmax, ymax)) [m] that covers the bodies and the rock they move to")
        for j, b in enumerate(self.bodies):
            for key, other in shapes[: len(self.charges) + j]:
                if shapes_overlap(b, other):
                    raise ValueError(f"bodies[{j}]: overlaps {key}; a body must not overlap a charge or another body")
            if b.name is not None:
                for i in range(j):
                    if self.bodies[i].name == b.name:
                        raise ValueError(f"bodies[{j}].name: '{b.name}' is already used by bodies[{i}]; names must "
                                         "be unique")
        for k, dp in enumerate(self.detonation_points):
            if not any(ch.contains(dp.position) for ch in self.charges):
                raise ValueError(f"detonation_points[{k}]: position ({dp.position[0]:.6g}, {dp.position[1]:.6g}) is "
                                 "not inside any charge")
            for i in range(k):
                if dp == self.detonation_points[i]:
                    raise ValueError(f"detonation_points[{k}]: repeats detonation_points[{i}]")
        for k, dl in enumerate(self.detonation_lines):
            if not any(ch.meets_segment(dl.start, dl.end) for ch in self.charges):
                raise ValueError(f"detonation_lines[{k}]: the segment ({dl.start[0]:.6g}, {dl.start[1]:.6g})–"
                                 f"({dl.end[0]:.6g}, {dl.end[1]:.6g}) neither lies in nor touches any charge")
            for i in range(k):
                if dl == self.detonation_lines[i]:
                    raise ValueError(f"detonation_lines[{k}]: repeats detonation_lines[{i}]")
        return self

    def jwl(self):
        """The resolved :class:`blastfrac.materials.jwl.JWLParams`; None without charges (elastic bodies only: no
        JWL is used, even if one is named)."""
        from blastfrac.explosives.library import get_explosive
        from blastfrac.materials.jwl import JWLParams

        if not self.charges:
            return None
        if self.constants is not None:
            return JWLParams(**self.constants.model_dump())
        return get_explosive(self.name)


__all__ = ["ExplosiveConfig", "JWLConstants", "CircleCharge", "PolygonCharge", "CircleBody", "PolygonBody", "DetonationPoint", "DetonationLine", "GridConfig", "GridBoundaries", "BurnConfig"]
