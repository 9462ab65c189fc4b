"""Scenario geometry: the rock domain (rectangle, disc, polygon), boreholes, joint sets and mesh sizes
(``[geometry]``). Part of the scenario schema (schema.py re-exports every name)."""

from __future__ import annotations

import math
from typing import Annotated, Literal, Union

from pydantic import Field, field_validator, model_validator

from . import _geometry as geo
from ._base import Point, _Strict


class RectangleDomain(_Strict):
    type: Literal["rectangle"] = "rectangle"
    width: float = Field(gt=0, description="Width along x [m].")
    height: float = Field(gt=0, description="Height along y [m].")
    center: Point = Field((0.0, 0.0), description="Centre [m].")

    def contains(self, p: Point, margin: float = 0.0) -> bool:
        return (
            abs(p[0] - self.center[0]) <= self.width / 2 - margin
            and abs(p[1] - self.center[1]) <= self.height / 2 - margin
        )

    @property
    def area(self) -> float:
        return self.width * self.height

    @property
    def bbox(self) -> tuple[Point, Point]:
        cx, cy, w2, h2 = self.center[0], self.center[1], self.width / 2, self.height / 2
        return (cx - w2, cy - h2), (cx + w2, cy + h2)

    @property
    def polygon(self) -> list[Point]:
        (x0, y0), (x1, y1) = self.bbox
        return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]

    @property
    def sides(self) -> tuple[str, ...]:
        return ("bottom", "right", "top", "left")


class DiscDomain(_Strict):
    type: Literal["disc"] = "disc"
    radius: float = Field(gt=0, description="Radius [m].")
    center: Point = Field((0.0, 0.0), description="Centre [m].")

    def contains(self, p: Point, margin: float = 0.0) -> bool:
        return math.dist(p, self.center) <= self.radius - margin

    @property
    def area(self) -> float:
        return math.pi * self.radius**2

    @property
    def bbox(self) -> tuple[Point, Point]:
        (cx, cy), r = self.center, self.radius
        return (cx - r, cy - r), (cx + r, cy + r)

    @property
    def sides(self) -> tuple[str, ...]:
        return ("outer",)


class PolygonDomain(_Strict):
    type: Literal["polygon"] = "polygon"
    vertices: list[Point] = Field(min_length=3, description="Vertices in counter-clockwise order [m].")

    @model_validator(mode="after")
    def _ccw(self) -> "PolygonDomain":
        v = self.vertices
        rep = geo.repeated_vertex(v)
        if rep is not None:
            raise ValueError(f"vertices[{rep[1]}]: {v[rep[1]]} repeats vertices[{rep[0]}]; every vertex must be distinct")
        area2 = sum(v[i][0] * v[(i + 1) % len(v)][1] - v[(i + 1) % len(v)][0] * v[i][1] for i in range(len(v)))
        if area2 <= 0:
            raise ValueError("polygon vertices must be counter-clockwise and enclose a positive area")
        cross = geo.polygon_self_intersection(v)
        if cross is not None:
            raise ValueError(f"vertices: sides {cross[0]} and {cross[1]} meet; the polygon must not intersect itself")
        return self

    @property
    def area(self) -> float:
        return geo.polygon_area(self.vertices)

    @property
    def bbox(self) -> tuple[Point, Point]:
        xs, ys = [p[0] for p in self.vertices], [p[1] for p in self.vertices]
        return (min(xs), min(ys)), (max(xs), max(ys))

    @property
    def polygon(self) -> list[Point]:
        return list(self.vertices)

    def contains(self, p: Point, margin: float = 0.0) -> bool:
        v, inside = self.vertices, False
        n = len(v)
        for i in range(n):
            (x1, y1), (x2, y2) = v[i], v[(i + 1) % n]
            if (y1 > p[1]) != (y2 > p[1]) and p[0] < (x2 - x1) * (p[1] - y1) / (y2 - y1) + x1:
                inside = not inside
        if not inside or margin == 0.0:
            return inside
        return all(_seg_dist(p, v[i], v[(i + 1) % n]) >= margin for i in range(n))

    @property
    def sides(self) -> tuple[str, ...]:
        return tuple(f"side{i}" for i in range(len(self.vertices)))


def _seg_dist(p: Point, a: Point, b: Point) -> float:
    ax, ay = b[0] - a[0], b[1] - a[1]
    t = max(0.0, min(1.0, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / (ax * ax + ay * ay)))
    return math.dist(p, (a[0] + t * ax, a[1] + t * ay))


Domain = Annotated[Union[RectangleDomain, DiscDomain, PolygonDomain], Field(discriminator="type")]

#: the sides of a rectangle domain that geometry.symmetry may name
SYMMETRY_SIDES = ("left", "right", "bottom", "top")


class Borehole(_Strict):
    center: Point = Field((0.0, 0.0), description="Centre of the borehole [m].")
    radius: float = Field(gt=0, description="Borehole radius r_b [m].")
    mesh_size: float | None = Field(None, gt=0, description="Element size on this wall [m]; default geometry.mesh_size_near.")


TraceDistribution = Literal["fixed", "uniform", "exponential", "lognormal", "power_law"]


class TraceLengthConfig(_Strict):
    """Distribution of the trace lengths of a generated joint set (geometry/joints.py, docs/joints.md)."""

    distribution: TraceDistribution = Field(
        "fixed", description="'fixed' (every trace `mean` long), 'uniform' on [min, max], 'exponential' of mean `mean`, "
        "'lognormal' of mean `mean` and standard deviation `std`, 'power_law' p(l) ∝ l^−exponent on [min, max].",
    )
    mean: float | None = Field(None, gt=0, description="Mean trace length [m] ('fixed', 'exponential', 'lognormal').")
    std: float | None = Field(None, gt=0, description="Standard deviation of the trace length [m] ('lognormal').")
    min: float | None = Field(None, gt=0, description="Shortest trace [m]: the lower bound of 'uniform' and 'power_law'; "
                              "a truncation (redraw below it) for 'exponential' and 'lognormal'.")
    max: float | None = Field(None, gt=0, description="Longest trace [m]: the upper bound of 'uniform' and 'power_law'; "
                              "a truncation (redraw above it) for 'exponential' and 'lognormal'.")
    exponent: float | None = Field(None, gt=1, description="Exponent a of 'power_law' p(l) ∝ l^−a [-], > 1.")

    @model_validator(mode="after")
    def _parameters(self) -> "TraceLengthConfig":
        d = self.distribution
        need = {"fixed": ("mean",), "uniform": ("min", "max"), "exponential": ("mean",),
                "lognormal": ("mean", "std"), "power_law": ("min", "max", "exponent")}[d]
        allowed = set(need) | ({"min", "max"} if d in ("exponential", "lognormal") else set())
        for k in ("mean", "std", "min", "max", "exponent"):
            v = getattr(self, k)
            if k in need and v is None:
                raise ValueError(f"{k}: distribution '{d}' needs {', '.join(need)}")
            if k not in allowed and v is not None:
                raise ValueError(f"{k}: not a parameter of distribution '{d}' (it takes {', '.join(sorted(allowed))})")
        if self.min is not None and self.max is not None and self.max <= self.min:
            raise ValueError(f"max: must exceed min ({self.max} <= {self.min} m)")
        if self.mean is not None and d in ("exponential", "lognormal"):
            if (self.min is not None and self.mean <= self.min) or (self.max is not None and self.mean >= self.max):
                raise ValueError(f"mean: {self.mean} m must lie between min and max")
        return self


class JointNetworkConfig(_Strict):
    """A seeded discrete fracture network of one joint set: traces of random position, orientation and length
    inside a region (geometry/joints.py, docs/joints.md)."""

    angle: float = Field(ge=-180, le=180, description="Mean trace orientation [deg], counter-clockwise from +x, "
                         "in [−180, 180] (a trace at θ is the same as at θ ± 180).")
    angle_spread: float = Field(0.0, ge=0, le=90, description="Standard deviation of the trace orientation about "
                                "`angle` [deg] (normal distribution), in [0, 90]; 0: all traces parallel.")
    spacing: float | None = Field(None, gt=0, description="Mean set spacing s [m], measured along the set's normal: "
                                  "trace length per unit area P21 = 1/s. Without `length` the traces are persistent "
                                  "(they cross the whole region) at exactly this spacing. Give spacing or density.")
    density: float | None = Field(None, gt=0, description="Traces per unit area P20 [1/m²] (their centres lie in "
                                  "the region); needs `length`. Give spacing or density.")
    length: TraceLengthConfig | None = Field(None, description="`[geometry.joints.dfn.length]`: trace-length "
                                             "distribution; none: persistent traces across the region.")
    region: Domain | None = Field(None, description="Rectangle, disc or polygon (as `geometry.domain`) in which "
                                    "the trace centres lie and to which the traces are clipped; default the "
                                    "domain's bounding box (traces are always clipped to the domain).")
    seed: int | None = Field(None, ge=0, le=2**31 - 1, description="Seed of this set's network [-]; default "
                             "simulation.seed. Two sets of one scenario draw from independent streams.")
    min_gap: float | None = Field(None, gt=0, description="Closest approach [m] allowed between two traces that do not "
                                  "meet, between a trace's end and the domain boundary or another trace (the end is "
                                  "then extended to meet it), and the shortest piece kept beyond a crossing; "
                                  "default the set's mesh size. Features below it would need smaller elements.")
    min_angle: float = Field(20.0, ge=0, lt=90, description="Smallest crossing angle with another trace [deg]; "
                             "a trace that would cross at less is redrawn (thin slivers of rock mesh badly).")

    @model_validator(mode="after")
    def _intensity(self) -> "JointNetworkConfig":
        if (self.spacing is None) == (self.density is None):
            raise ValueError("spacing: give exactly one of spacing [m] and density [1/m²]")
        if self.density is not None and self.length is None:
            raise ValueError("density: needs a trace-length distribution ([geometry.joints.dfn.length]); "
                             "persistent traces are set by their spacing")
        return self


class JointSetConfig(_Strict):
    """Pre-existing joints: lines embedded in the mesh whose interfaces get the joint's spring properties
    (docs/joints.md)."""

    name: str | None = Field(None, pattern=r"^[A-Za-z0-9_\-]+$", description="Name of the set; default 'joint<i>'.")
    segments: list[tuple[Point, Point]] | None = Field(
        None, description="Given joint traces, each [[x0, y0], [x1, y1]] [m]. Clipped to the domain (a trace "
        "across the whole domain may end outside it); a trace wholly outside, of zero length, along the domain "
        "boundary or closer than `borehole_clearance` to a borehole is an error. Give segments or dfn.",
    )
    dfn: JointNetworkConfig | None = Field(None, description="`[geometry.joints.dfn]`: a generated network instead "
                                           "of given segments.")
    tensile_strength: float = Field(0.0, ge=0, description="Tensile strength of the joint's springs [Pa]; 0: "
                                    "the joint opens as soon as it is not in compression.")
    cohesion: float = Field(0.0, ge=0, description="Cohesion of the joint's springs [Pa].")
    friction_angle: float = Field(30.0, ge=0, lt=90, description="Friction angle φ_j of the joint [deg], in [0, 90).")
    residual_friction_angle: float | None = Field(
        None, ge=0, lt=90, description="Friction angle of the joint once broken (or open) [deg]; default "
        "friction_angle. The node-to-edge block contact of faces that have slid or opened by more than half an "
        "element keeps the rock's residual friction.",
    )
    kn: float | None = Field(None, gt=0, description="Normal stiffness of the joint per unit area [Pa/m]; default "
                             "that of the rock's springs at the same interface.")
    ks: float | None = Field(None, gt=0, description="Shear stiffness of the joint per unit area [Pa/m]; default "
                             "that of the rock's springs at the same interface.")
    open: bool = Field(False, description="The joint's springs are broken from t = 0 (pair_mode 1): its faces "
                       "interact by frictional contact only (residual_friction_angle), they carry no tension.")
    mesh_size: float | None = Field(None, gt=0, description="Element size along the joint [m]; default "
                                    "geometry.mesh_size; at most geometry.mesh_size.")
    borehole_clearance: float | None = Field(
        None, gt=0, description="Smallest distance from a joint to a borehole wall [m]; default the joint's mesh "
        "size. Generated traces are cut back to it; a given segment closer than it is an error.",
    )

    @model_validator(mode="after")
    def _source(self) -> "JointSetConfig":
        if (self.segments is None) == (self.dfn is None):
            raise ValueError("segments: give exactly one of segments (given traces) and dfn (a generated network)")
        if self.segments is not None and not self.segments:
            raise ValueError("segments: empty list; give at least one segment [[x0, y0], [x1, y1]]")
        return self

    @property
    def residual_friction(self) -> float:
        """Residual friction angle of the joint [deg] (defaults to friction_angle)."""
        return self.friction_angle if self.residual_friction_angle is None else self.residual_friction_angle


class GeometryConfig(_Strict):
    """Rock domain, boreholes and mesh sizes (meshed by gmsh) or an external .msh file."""

    domain: Domain = Field(description="Outer domain: rectangle, disc or polygon.")
    boreholes: list[Borehole] = Field(default_factory=list, description="Circular holes in the rock.")
    mesh_size: float = Field(gt=0, description="Element size far from the boreholes [m].")
    mesh_size_near: float | None = Field(None, gt=0, description="Element size at the borehole walls [m]; default mesh_size.")
    refinement_distance: float | None = Field(
        None, gt=0, description="Distance from a wall over which the size grows to mesh_size [m]; default 10·r_b."
    )
    mesh_file: str | None = Field(None, description="Use this gmsh .msh file instead of meshing (path relative to the scenario).")
    mesh_algorithm: Literal["delaunay", "frontal-delaunay"] = Field(
        "delaunay",
        description="gmsh 2D algorithm; plain Delaunay gives a less regular mesh, so cracks are less biased to lattice directions.",
    )
    joints: list[JointSetConfig] = Field(
        default_factory=list, description="`[[geometry.joints]]`: pre-existing joint sets (given segments or a "
        "generated network) embedded in the mesh, whose interfaces get joint properties (docs/joints.md).",
    )
    symmetry: list[str] = Field(
        default_factory=list, description="Sides of a rectangle domain that are symmetry lines, e.g. ['left', "
        "'bottom'] (half and quarter models, docs/explosive.md 'Half and quarter models'): each side gets a roller "
        "(boundaries.<side>, written to resolved.toml), a borehole centred on it or crossing it and its charge are cut "
        "by it, and the MPM grid has a slip (image) wall exactly on it. At most one of left/right and one of "
        "bottom/top; not with mesh_file.",
    )

    @field_validator("mesh_file")
    @classmethod
    def _msh_extension(cls, v: str | None) -> str | None:
        if v is not None and not v.lower().endswith(".msh"):
            suffix = v.rsplit(".", 1)[-1] if "." in v.rsplit("/", 1)[-1] else ""
            raise ValueError(f"{v!r}: unknown mesh file type {'.' + suffix if suffix else '(no extension)'}; "
                             "expected a gmsh .msh file")
        return v

    @model_validator(mode="after")
    def _holes_inside(self) -> "GeometryConfig":
        self._check_symmetry()
        for i, b in enumerate(self.boreholes):
            if self.symmetry:
                self._check_cut_hole(i, b)
            elif not self.domain.contains(b.center, margin=b.radius):
                hint = (" (a rectangle's side may cut a borehole when it is a symmetry line, geometry.symmetry)"
                        if isinstance(self.domain, RectangleDomain) else "")
                raise ValueError(
                    f"boreholes[{i}]: centre {b.center}, radius {b.radius} m: not fully inside the domain{hint}"
                )
        for i in range(len(self.boreholes)):
            for j in range(i + 1, len(self.boreholes)):
                bi, bj = self.boreholes[i], self.boreholes[j]
                if math.dist(bi.center, bj.center) <= bi.radius + bj.radius:
                    raise ValueError(f"boreholes[{j}]: overlaps boreholes[{i}] (centres {bi.center} and {bj.center}, "
                                     f"radii {bi.radius} and {bj.radius} m); boreholes must be apart")
        if self.mesh_size_near is not None and self.mesh_size_near > self.mesh_size:
            raise ValueError(f"mesh_size_near: must not exceed mesh_size ({self.mesh_size_near} > {self.mesh_size} m)")
        if self.joints:
            from ..geometry.joints import check_joint_config

            check_joint_config(self)
        return self

    # ------------------------------------------------------------------ symmetry lines (half and quarter models)
    def _check_symmetry(self) -> None:
        if not self.symmetry:
            return
        sides = SYMMETRY_SIDES
        for k, s in enumerate(self.symmetry):
            if not isinstance(self.domain, RectangleDomain):
                raise ValueError(f"symmetry: needs a rectangle domain (a symmetry line is a side of the rectangle); "
                                 f"this domain is a {self.domain.type}")
            if s not in sides:
                raise ValueError(f"symmetry[{k}]: '{s}' is not a side of the rectangle; give some of "
                                 f"{', '.join(repr(x) for x in sides)}")
            if s in self.symmetry[:k]:
                raise ValueError(f"symmetry[{k}]: '{s}' is listed twice; give each side once")
        for a, b in (("left", "right"), ("bottom", "top")):
            if a in self.symmetry and b in self.symmetry:
                raise ValueError(f"symmetry: '{a}' and '{b}' are both symmetry lines; give at most one side per "
                                 "direction (a strip between two parallel symmetry lines is not supported)")
        if self.mesh_file is not None:
            raise ValueError("symmetry: not available with mesh_file (the cut holes and side tags come from the "
                             "mesher); give the sides a roller in [boundaries] and the grid a slip wall by hand")

    def symmetry_lines(self) -> list[tuple[str, int, float, int]]:
        """(side, axis, coordinate [m], sign) of each symmetry line x_axis = coordinate; the modelled part is where
        sign·(x_axis − coordinate) ≤ 0 (sign −1 for 'left' and 'bottom', +1 for 'right' and 'top')."""
        if not self.symmetry:
            return []
        (x0, y0), (x1, y1) = self.domain.bbox
        line = {"left": (0, x0, -1), "right": (0, x1, 1), "bottom": (1, y0, -1), "top": (1, y1, 1)}
        return [(s, *line[s]) for s in self.symmetry]

    def cut_sides(self, i: int) -> list[str]:
        """The symmetry sides that cut borehole i (its circle crosses them or its centre lies on them)."""
        b = self.boreholes[i]
        tol = 1e-9 * b.radius
        return [s for s, axis, c, sign in self.symmetry_lines() if sign * (c - b.center[axis]) < b.radius - tol]

    def _check_cut_hole(self, i: int, b: "Borehole") -> None:
        """A hole inside the rectangle, or cut only by symmetry sides with its centre on the modelled side."""
        (x0, y0), (x1, y1) = self.domain.bbox
        tol = 1e-9 * b.radius
        inward = {"left": b.center[0] - x0, "right": x1 - b.center[0], "bottom": b.center[1] - y0,
                  "top": y1 - b.center[1]}
        for side in SYMMETRY_SIDES:
            d = inward[side]
            if d >= b.radius - tol:
                continue
            if side not in self.symmetry:
                raise ValueError(f"boreholes[{i}]: centre {b.center}, radius {b.radius} m: not fully inside the "
                                 f"domain: it crosses the {side} side, which is not a symmetry line (geometry."
                                 f"symmetry = {self.symmetry}); only a symmetry line may cut a borehole")
            if d < -tol:
                raise ValueError(f"boreholes[{i}]: centre {b.center} lies beyond the symmetry line on the {side} "
                                 "side, outside the modelled part; put the centre on the line (a hole cut by it) or "
                                 "inside the domain")

    def joint_mesh_size(self, i: int) -> float:
        """Element size along joint set i [m] (its mesh_size, default geometry.mesh_size)."""
        return self.joints[i].mesh_size or self.mesh_size

    def joint_name(self, i: int) -> str:
        return self.joints[i].name or f"joint{i}"
