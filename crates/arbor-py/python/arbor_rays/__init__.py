"""Exact ray queries on NumPy arrays, and Arbor's renderer.

``Mesh(vertices, faces)`` holds a triangle mesh; its queries (``intersect``, ``occluded``,
``intersect_all``, ``count_crossings``, ``contains``, ``closest_point``, ``distance``) take arrays of
rays or points and run on every core with the GIL released. Every closest hit is exactly the one brute
force finds with the watertight ray-triangle test (Woop, Benthin and Wald 2013): the smallest ``t``,
ties to the lowest triangle index; every closest point likewise the nearest, ties to the lowest index.
``RayMeshIntersector`` is a drop-in for trimesh's ``mesh.ray`` (and ``trimesh_adapter.closest_point``
for ``trimesh.proximity.closest_point``); ``RaycastingScene`` follows Open3D's ``cast_rays``
conventions; ``render`` renders a scene file as ``arbor render`` does.

Not the neuroscience simulator on PyPI called ``arbor``: this is ``arbor-rays``, imported as
``arbor_rays``.
"""

from ._native import Mesh, __version__, accel_kinds, load_mesh, render
from .open3d_adapter import RaycastingScene
from .trimesh_adapter import RayMeshIntersector

__all__ = [
    "Mesh",
    "RayMeshIntersector",
    "RaycastingScene",
    "accel_kinds",
    "load_mesh",
    "render",
    "__version__",
]
