from ._native import Mesh as Mesh
from ._native import __version__ as __version__
from ._native import accel_kinds as accel_kinds
from ._native import load_mesh as load_mesh
from ._native import render as render
from .open3d_adapter import RaycastingScene as RaycastingScene
from .trimesh_adapter import RayMeshIntersector as RayMeshIntersector

__all__ = ["Mesh", "RayMeshIntersector", "RaycastingScene", "accel_kinds", "load_mesh", "render", "__version__"]
