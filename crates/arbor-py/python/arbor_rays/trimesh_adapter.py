"""trimesh's ``RayMeshIntersector`` interface over an Arbor structure: ``mesh.ray = RayMeshIntersector(mesh)``.

The methods take and return what trimesh's own intersectors (``ray_triangle``, ``ray_pyembree``) do,
but every answer comes from one exact query per batch instead of a Python loop that moves each
ray's origin past its last hit: ``intersects_id(multiple_hits=True)`` reports each surface crossing
once (a ray through a shared edge or vertex is not counted twice nor lost; see
``Mesh.intersect_all``), ``intersects_any`` is a true occlusion query, and ``contains_points`` uses
the robust parity rule of ``Mesh.contains``. Locations are on the triangle hit (from its
barycentric coordinates), as float64.

``closest_point(mesh, points)`` is ``trimesh.proximity.closest_point`` (the same arguments and
return convention) on an Arbor structure, exact and multi-threaded.
"""

import numpy as np

from ._native import Mesh


class RayMeshIntersector:
    """Ray queries on a ``trimesh.Trimesh`` with Arbor (no trimesh import needed to construct one).

    ``kind`` and ``**params`` choose the structure (``Mesh.build``); ``threads`` the threads of every
    query (None: every core). The structure is rebuilt when the mesh's data changes (trimesh's
    ``hash(mesh)``).
    """

    def __init__(self, mesh, kind="bvh-sah", threads=None, **params):
        self.mesh = mesh
        self._kind = kind
        self._params = params
        self._threads = threads
        self._key = None
        self._arbor = None

    @property
    def arbor_mesh(self):
        """The ``arbor_rays.Mesh`` answering the queries (built on first use)."""
        key = hash(self.mesh)
        if self._arbor is None or key != self._key:
            m = Mesh(np.asarray(self.mesh.vertices), np.asarray(self.mesh.faces))
            m.build(self._kind, threads=self._threads, **self._params)
            self._arbor, self._key = m, key
        return self._arbor

    @staticmethod
    def _rays(ray_origins, ray_directions):
        o = np.asarray(ray_origins)
        d = np.asarray(ray_directions)
        if o.shape != d.shape:
            raise ValueError("Ray origin and direction don't match!")
        return o, d

    def intersects_first(self, ray_origins, ray_directions, **kwargs):
        """Index of the first triangle each ray hits, (n,) int64, -1 where it hits none."""
        o, d = self._rays(ray_origins, ray_directions)
        return self.arbor_mesh.intersect(o, d, threads=self._threads, fields=["triangle"])["triangle"]

    def intersects_any(self, ray_origins, ray_directions, **kwargs):
        """Whether each ray hits the surface, (n,) bool (an any-hit query)."""
        o, d = self._rays(ray_origins, ray_directions)
        return self.arbor_mesh.occluded(o, d, threads=self._threads)

    def intersects_id(
        self,
        ray_origins,
        ray_directions,
        multiple_hits=True,
        max_hits=None,
        return_locations=False,
        **kwargs,
    ):
        """Triangles hit: ``index_tri`` (h,) int64, ``index_ray`` (h,) int64 and, with
        ``return_locations``, ``locations`` (h, 3) float64. With ``multiple_hits`` every crossing of
        each ray (at most ``max_hits`` per ray, the closest), else the first hit of each ray that
        hits. Rows are in ray order, then along each ray."""
        o, d = self._rays(ray_origins, ray_directions)
        m = self.arbor_mesh
        if multiple_hits:
            a = m.intersect_all(o, d, max_hits=max_hits, threads=self._threads)
            tri, ray, loc = a["triangle"], a["ray"], a["point"]
        else:
            fields = ["triangle", "point"] if return_locations else ["triangle"]
            c = m.intersect(o, d, threads=self._threads, fields=fields)
            ray = np.flatnonzero(c["triangle"] >= 0)
            tri, loc = c["triangle"][ray], c["point"][ray] if return_locations else None
        if return_locations:
            return tri, ray.astype(np.int64), loc.astype(np.float64)
        return tri, ray.astype(np.int64)

    def intersects_location(self, ray_origins, ray_directions, multiple_hits=True, **kwargs):
        """Where rays hit: ``locations`` (h, 3) float64, ``index_ray`` (h,), ``index_tri`` (h,)."""
        tri, ray, loc = self.intersects_id(
            ray_origins, ray_directions, multiple_hits=multiple_hits, return_locations=True, **kwargs
        )
        return loc, ray, tri

    def contains_points(self, points):
        """Whether each point, (n, 3), is inside the mesh: (n,) bool (robust parity; see
        ``Mesh.contains``). Points on the surface may go either way."""
        return self.arbor_mesh.contains(np.asarray(points), threads=self._threads)

    def closest_point(self, points):
        """``trimesh.proximity.closest_point`` on this intersector's structure: see ``closest_point``."""
        c = self.arbor_mesh.closest_point(np.asarray(points), threads=self._threads)
        return c["point"], c["distance"], c["triangle"]


def closest_point(mesh, points):
    """The point of the mesh nearest to each point, as ``trimesh.proximity.closest_point(mesh,
    points)`` returns it: ``closest`` (m, 3) float64, ``distance`` (m,) float64, ``triangle_id``
    (m,) int64. ``mesh`` is a ``trimesh.Trimesh`` (its ``mesh.ray``'s structure is used when that is
    a ``RayMeshIntersector``, else one is built for the call) or a ``RayMeshIntersector``. Exactly
    what testing every triangle gives: ties (a point nearest to a shared vertex or edge) go to the
    lowest triangle index."""
    if not isinstance(mesh, RayMeshIntersector):
        ray = getattr(mesh, "ray", None)
        mesh = ray if isinstance(ray, RayMeshIntersector) else RayMeshIntersector(mesh)
    return mesh.closest_point(points)
