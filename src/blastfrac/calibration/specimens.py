"""Laboratory specimens for calibration: the UCS prism and the Brazilian disc.

Both are meshed with the scenario's own mesher (gmsh, plain Delaunay) and carry the rock of the
scenario being calibrated; boundaries are free (the platens of :mod:`.loading` load them).
Default sizes follow the paper's Fig. 5: a 54 × 108 mm prism (3734 triangles) and a 54 mm
disc (2167 triangles). Lengths in metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.builder import ModelBuilder
from ..scenario.schema import (DiscDomain, GeometryConfig, OutputConfig, RectangleDomain, RockConfig,
                               Scenario, SimulationConfig)

UCS_WIDTH, UCS_HEIGHT = 0.054, 0.108       # [m]
DISC_DIAMETER = 0.054                      # [m]
PAPER_UCS_ELEMENTS, PAPER_DISC_ELEMENTS = 3734, 2167
GMSH_DENSITY_FACTOR = 1.10


def mesh_size_for_count(area: float, count: int) -> float:
    """Side a [m] of equilateral triangles such that ``count`` of them tile ``area`` [m²].

    gmsh's Delaunay meshes of a target size h come out about 1.2× denser than equilateral
    triangles of side h (measured: 2632 instead of 2167 elements on the 54 mm disc), hence the
    empirical factor 1.10 on the size.
    """
    return GMSH_DENSITY_FACTOR * math.sqrt(4.0 * area / (math.sqrt(3.0) * count))


def default_ucs_mesh_size() -> float:
    return mesh_size_for_count(UCS_WIDTH * UCS_HEIGHT, PAPER_UCS_ELEMENTS)


def default_disc_mesh_size() -> float:
    return mesh_size_for_count(math.pi * DISC_DIAMETER**2 / 4.0, PAPER_DISC_ELEMENTS)


@dataclass
class Specimen:
    """A built specimen: model, node groups and dimensions.

    kind: 'ucs' or 'brazilian'; width, height [m] (disc: both = diameter);
    top, bottom: candidate platen nodes; left, right: side nodes (UCS, for lateral strain);
    top_face, bottom_face: nodes on the loaded faces (UCS, for the axial strain).
    """

    kind: str
    scenario: Scenario
    model: object
    width: float
    height: float
    top: np.ndarray
    bottom: np.ndarray
    left: np.ndarray
    right: np.ndarray

    @property
    def element_count(self) -> int:
        return self.model.element_count


def _scenario(rock: RockConfig, domain, mesh_size: float, seed: int, device: str) -> Scenario:
    rock = rock.model_copy(deep=True)
    return Scenario(
        title="calibration specimen",
        simulation=SimulationConfig(device=device, seed=seed, progress=False),
        output=OutputConfig(paraview=False, figures=False),
        rock=rock,
        geometry=GeometryConfig(domain=domain, mesh_size=mesh_size),
    )


def ucs_specimen(rock: RockConfig, mesh_size: float | None = None, seed: int = 0, device: str = "cpu",
                 width: float = UCS_WIDTH, height: float = UCS_HEIGHT) -> Specimen:
    """A width × height prism centred at the origin; platens act on the top and bottom faces."""
    h = mesh_size or default_ucs_mesh_size()
    sc = _scenario(rock, RectangleDomain(width=width, height=height), h, seed, device)
    model = ModelBuilder(sc).finalize(device)
    X = model.host["node_X"]
    tol = 1e-9 * height
    return Specimen(
        "ucs", sc, model, width, height,
        top=np.flatnonzero(X[:, 1] >= height / 2 - tol), bottom=np.flatnonzero(X[:, 1] <= -height / 2 + tol),
        left=np.flatnonzero(X[:, 0] <= -width / 2 + tol), right=np.flatnonzero(X[:, 0] >= width / 2 - tol),
    )


def disc_specimen(rock: RockConfig, mesh_size: float | None = None, seed: int = 0, device: str = "cpu",
                  diameter: float = DISC_DIAMETER) -> Specimen:
    """A disc of the given diameter centred at the origin; candidate platen nodes are its rim nodes."""
    h = mesh_size or default_disc_mesh_size()
    sc = _scenario(rock, DiscDomain(radius=diameter / 2), h, seed, device)
    model = ModelBuilder(sc).finalize(device)
    mesh = model.mesh
    rim_vertices = np.zeros(len(mesh.vertices), bool)
    rim_vertices[mesh.boundary_edges.ravel()] = True
    node_vertex = mesh.triangles.ravel()           # node 3e+k is vertex triangles[e, k]
    rim = rim_vertices[node_vertex]
    y = model.host["node_X"][:, 1]
    empty = np.zeros(0, np.int64)
    return Specimen("brazilian", sc, model, diameter, diameter,
                    top=np.flatnonzero(rim & (y > 0)), bottom=np.flatnonzero(rim & (y < 0)), left=empty, right=empty)
