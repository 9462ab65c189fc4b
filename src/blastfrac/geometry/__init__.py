"""Rock geometry: gmsh meshing of domains with boreholes, .msh import."""

from .mesh import TriMesh, generate_mesh, read_msh

__all__ = ["TriMesh", "generate_mesh", "read_msh"]
