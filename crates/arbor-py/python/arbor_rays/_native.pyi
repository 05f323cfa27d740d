"""Type stubs of the extension module (Rust, PyO3). Shapes: N rays, M triangles, K crossings."""

from os import PathLike
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
PerRay = Union[float, npt.ArrayLike]
"""A number for every ray, or an (N,) array of one per ray."""

class Mesh:
    """A triangle mesh and an acceleration structure over it.

    ``Mesh(vertices, faces)``: vertices (N, 3) float32 or float64, faces (M, 3) of any integer dtype,
    0-based, counter-clockwise around the outward normal; C or Fortran order; never written. NaN or
    infinite coordinates, indices out of range and empty arrays raise ValueError.
    """

    def __init__(self, vertices: ArrayLike, faces: ArrayLike) -> None: ...
    def build(self, kind: str = "bvh-sah", *, threads: Optional[int] = None, **params: Any) -> "Mesh":
        """Builds structure ``kind`` (brute, octree, kdtree, bvh-median, bvh-sah, bvh-bottom-up) with
        parameters as keywords (``leaf=4``, ``traversal_cost=1.5``); returns the mesh."""
    def stats(self) -> dict[str, Any]:
        """kind, config, primitives, nodes, leaves, max_depth, mean_depth, refs_per_prim,
        mean_leaf_prims, sah_cost, bytes, build_seconds."""
    def __len__(self) -> int: ...
    @property
    def vertices(self) -> npt.NDArray[np.float32]:
        """(N, 3) float32, a copy."""
    @property
    def faces(self) -> npt.NDArray[np.int64]:
        """(M, 3) int64, a copy."""
    def intersect(
        self,
        origins: ArrayLike,
        directions: ArrayLike,
        t_min: Optional[PerRay] = None,
        t_max: Optional[PerRay] = None,
        *,
        threads: Optional[int] = None,
        fields: Optional[Sequence[str]] = None,
    ) -> dict[str, np.ndarray]:
        """Closest hits in (t_min, t_max), t in units of each direction's length: t (N,) float32 (inf
        on a miss), triangle (N,) int64 (-1), u, v (N,) float32, normal (N, 3) float32 (unit),
        point (N, 3) float32 (on the triangle). fields: the names to compute and return (None: all;
        normal and point read the triangle's corners per hit)."""
    def occluded(
        self,
        origins: ArrayLike,
        directions: ArrayLike,
        t_min: Optional[PerRay] = None,
        t_max: Optional[PerRay] = None,
        *,
        threads: Optional[int] = None,
    ) -> npt.NDArray[np.bool_]:
        """(N,) bool: whether anything is hit in (t_min, t_max) (any-hit query)."""
    def intersect_all(
        self,
        origins: ArrayLike,
        directions: ArrayLike,
        t_min: Optional[PerRay] = None,
        t_max: Optional[PerRay] = None,
        *,
        max_hits: Optional[int] = None,
        threads: Optional[int] = None,
    ) -> dict[str, np.ndarray]:
        """Every surface crossing, each once, in ray then t order: ray, triangle (K,) int64; t, u, v
        (K,) float32; point (K, 3) float32. At most max_hits per ray (the closest)."""
    def count_crossings(
        self,
        origins: ArrayLike,
        directions: ArrayLike,
        t_min: Optional[PerRay] = None,
        t_max: Optional[PerRay] = None,
        *,
        threads: Optional[int] = None,
    ) -> npt.NDArray[np.int64]:
        """(N,) int64: the number of crossings intersect_all reports per ray, uncapped."""
    def contains(self, points: ArrayLike, *, threads: Optional[int] = None) -> npt.NDArray[np.bool_]:
        """(N,) bool: whether each (N, 3) point is inside the closed mesh (robust parity)."""
    def closest_point(
        self, points: ArrayLike, *, max_distance: float = ..., threads: Optional[int] = None
    ) -> dict[str, np.ndarray]:
        """The point of the mesh nearest to each (N, 3) point, among triangles within max_distance
        (default inf): point (N, 3) float64, distance (N,) float64 (unsigned), triangle (N,) int64,
        u, v (N,) float64 barycentric weights; inf, -1 and NaN where none is within the bound. Ties
        to the lowest triangle index."""
    def distance(
        self, points: ArrayLike, *, max_distance: float = ..., threads: Optional[int] = None
    ) -> npt.NDArray[np.float64]:
        """(N,) float64: the unsigned distance from each (N, 3) point to the mesh (inf beyond
        max_distance)."""

def load_mesh(path: Union[str, "PathLike[str]"]) -> Mesh:
    """A mesh file (.ply, .obj, .off) read by Arbor's readers; OSError or a located ValueError."""

def accel_kinds() -> dict[str, list[tuple[str, str, str, str]]]:
    """{kind: [(key, range, default, about), ...]} for Mesh.build."""

def render(
    scene: Union[str, "PathLike[str]"],
    camera: Optional[str] = None,
    spp: Optional[int] = None,
    *,
    accel: str = "bvh-sah",
    seed: int = 0,
    threads: Optional[int] = None,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8]]:
    """(radiance (H, W, 3) float32 in the scene's units, image (H, W, 3) uint8) of one camera, as
    ``arbor render`` writes them to .exr and .png."""
