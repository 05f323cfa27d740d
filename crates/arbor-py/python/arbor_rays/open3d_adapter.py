"""Open3D's ``RaycastingScene`` conventions over Arbor: ``cast_rays`` takes rays as one array of shape
(..., 6) (origin, direction) and returns a dict of arrays shaped like the rays' leading dimensions,
``t_hit`` in units of each direction's length (inf on a miss) and ``geometry_ids``/``primitive_ids``
``INVALID_ID`` on a miss. The arrays are NumPy arrays, not ``open3d.core.Tensor``; Open3D is not
needed. Unlike Open3D, queries may run from several Python threads at once, ``test_occlusions``
honours ``tnear``, hit points are on the triangle, and ``compute_closest_points`` is exact (ties to the
lowest triangle index of the scene).
"""

import numpy as np

from ._native import Mesh

INVALID_ID = 4294967295


def _threads(nthreads):
    return None if not nthreads or nthreads <= 0 else int(nthreads)


class RaycastingScene:
    """A scene of triangle meshes for ray casting, as Open3D's ``t.geometry.RaycastingScene``."""

    INVALID_ID = INVALID_ID

    def __init__(self, nthreads=0, kind="bvh-sah", **params):
        self._threads = _threads(nthreads)
        self._kind = kind
        self._params = params
        self._parts = []
        self._mesh = None
        self._first = None

    def add_triangles(self, vertex_positions, triangle_indices=None):
        """Adds a mesh: ``(vertex_positions (N, 3), triangle_indices (M, 3))``, or one object with
        Open3D's ``vertex.positions`` and ``triangle.indices``. Returns its geometry id (0, 1, ...)."""
        if triangle_indices is None:
            mesh = vertex_positions
            vertex_positions = mesh.vertex.positions.numpy()
            triangle_indices = mesh.triangle.indices.numpy()
        v = np.asarray(vertex_positions)
        f = np.asarray(triangle_indices)
        Mesh(v, f)  # checks the arrays now, with the error naming them
        self._parts.append((v, f))
        self._mesh = None
        return len(self._parts) - 1

    def _scene(self):
        if self._mesh is None:
            if not self._parts:
                raise ValueError("the scene has no geometry: add_triangles first")
            offset, verts, faces, first = 0, [], [], []
            for v, f in self._parts:
                first.append(sum(len(x) for x in faces))
                verts.append(v)
                faces.append(np.asarray(f, dtype=np.int64) + offset)
                offset += len(v)
            self._v, self._f = np.concatenate(verts), np.concatenate(faces)
            self._mesh = Mesh(self._v, self._f)
            self._mesh.build(self._kind, threads=self._threads, **self._params)
            self._first = np.asarray(first, dtype=np.int64)
        return self._mesh

    @staticmethod
    def _split(rays):
        r = np.asarray(rays)
        if r.ndim < 1 or r.shape[-1] != 6:
            raise ValueError(f"rays must have shape (..., 6), got {r.shape}")
        flat = r.reshape(-1, 6)
        return r.shape[:-1], flat[:, :3], flat[:, 3:]

    def _ids(self, tri):
        geometry = np.searchsorted(self._first, tri, side="right") - 1
        primitive = tri - self._first[np.maximum(geometry, 0)]
        miss = tri < 0
        g = np.where(miss, INVALID_ID, geometry).astype(np.uint32)
        p = np.where(miss, INVALID_ID, primitive).astype(np.uint32)
        return g, p

    def cast_rays(self, rays, nthreads=0):
        """Closest hits: ``t_hit`` (...) float32, ``geometry_ids``, ``primitive_ids`` (...) uint32,
        ``primitive_uvs`` (..., 2) float32, ``primitive_normals`` (..., 3) float32 (unit)."""
        shape, o, d = self._split(rays)
        m = self._scene()
        fields = ["t", "triangle", "u", "v", "normal"]
        c = m.intersect(o, d, threads=_threads(nthreads) or self._threads, fields=fields)
        g, p = self._ids(c["triangle"])
        return {
            "t_hit": c["t"].reshape(shape),
            "geometry_ids": g.reshape(shape),
            "primitive_ids": p.reshape(shape),
            "primitive_uvs": np.stack([c["u"], c["v"]], axis=-1).reshape(shape + (2,)),
            "primitive_normals": c["normal"].reshape(shape + (3,)),
        }

    def test_occlusions(self, rays, tnear=0.0, tfar=np.inf, nthreads=0):
        """Whether each ray hits anything in ``(tnear, tfar)``: (...) bool."""
        shape, o, d = self._split(rays)
        hit = self._scene().occluded(o, d, tnear, tfar, threads=_threads(nthreads) or self._threads)
        return hit.reshape(shape)

    def count_intersections(self, rays, nthreads=0):
        """Surface crossings of each ray: (...) int32 (each crossing once, see ``Mesh.intersect_all``)."""
        shape, o, d = self._split(rays)
        n = self._scene().count_crossings(o, d, threads=_threads(nthreads) or self._threads)
        return n.astype(np.int32).reshape(shape)

    def list_intersections(self, rays, nthreads=0):
        """Every crossing, flat: ``ray_splits`` (R+1,) uint32, ``ray_ids``, ``geometry_ids``,
        ``primitive_ids`` uint32, ``primitive_uvs`` (K, 2) and ``t_hit`` (K,) float32."""
        _, o, d = self._split(rays)
        a = self._scene().intersect_all(o, d, threads=_threads(nthreads) or self._threads)
        g, p = self._ids(a["triangle"])
        counts = np.bincount(a["ray"], minlength=len(o))
        splits = np.concatenate([[0], np.cumsum(counts)]).astype(np.uint32)
        return {
            "ray_splits": splits,
            "ray_ids": a["ray"].astype(np.uint32),
            "geometry_ids": g,
            "primitive_ids": p,
            "primitive_uvs": np.stack([a["u"], a["v"]], axis=-1),
            "t_hit": a["t"],
        }

    def compute_occupancy(self, query_points, nthreads=0, nsamples=1):
        """1.0 for points inside the (closed) meshes, else 0.0: (...) float32."""
        q = np.asarray(query_points)
        inside = self._scene().contains(q.reshape(-1, 3), threads=_threads(nthreads) or self._threads)
        return inside.astype(np.float32).reshape(q.shape[:-1])

    def compute_closest_points(self, query_points, nthreads=0):
        """The nearest point of the scene to each point (..., 3): ``points`` (..., 3) float32,
        ``geometry_ids``, ``primitive_ids`` (...) uint32, ``primitive_uvs`` (..., 2) float32,
        ``primitive_normals`` (..., 3) float32 (unit)."""
        q = np.asarray(query_points)
        shape = q.shape[:-1]
        m = self._scene()
        c = m.closest_point(q.reshape(-1, 3), threads=_threads(nthreads) or self._threads)
        g, p = self._ids(c["triangle"])
        a, b, t = (self._v[self._f[c["triangle"], k]].astype(np.float64) for k in range(3))
        n = np.cross(b - a, t - a)
        n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-300)
        return {
            "points": c["point"].astype(np.float32).reshape(shape + (3,)),
            "geometry_ids": g.reshape(shape),
            "primitive_ids": p.reshape(shape),
            "primitive_uvs": np.stack([c["u"], c["v"]], axis=-1).astype(np.float32).reshape(shape + (2,)),
            "primitive_normals": n.astype(np.float32).reshape(shape + (3,)),
        }

    def compute_distance(self, query_points, nthreads=0):
        """The unsigned distance from each point (..., 3) to the scene: (...) float32."""
        q = np.asarray(query_points)
        d = self._scene().distance(q.reshape(-1, 3), threads=_threads(nthreads) or self._threads)
        return d.astype(np.float32).reshape(q.shape[:-1])
