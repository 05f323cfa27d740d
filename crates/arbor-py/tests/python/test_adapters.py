"""The trimesh and Open3D adapters: trimesh's own ray_triangle intersector on the shared meshes (a
subset of rays: it is slow), Open3D's conventions on meshes made here (and Open3D itself when it is
installed)."""

import os

import numpy as np
import pytest
from conftest import icosphere, meshes_dir, soup

import arbor_rays as ar

trimesh = pytest.importorskip("trimesh", reason="NOT CHECKED: trimesh is not installed")


def rays_into(bounds, n, seed):
    lo, hi = bounds
    rng = np.random.default_rng(seed)
    pad = (hi - lo) * 0.5
    o = rng.uniform(lo - pad, hi + pad, (n, 3))
    target = rng.uniform(lo, hi, (n, 3))
    return o, target - o


@pytest.mark.parametrize("name", ["stanford-bunny.obj", "horse.ply"])
def test_trimesh_adapter_agrees_with_trimesh_ray_triangle(name):
    path = os.path.join(meshes_dir(), name)
    native = ar.load_mesh(path)
    tm = trimesh.Trimesh(native.vertices.astype(np.float64), native.faces, process=False)
    theirs = trimesh.ray.ray_triangle.RayMeshIntersector(tm)
    ours = ar.RayMeshIntersector(tm)
    o, d = rays_into(tm.bounds, 200, seed=1)
    scale = tm.scale
    # First hits: the same where trimesh is sure; locations agree.
    a, b = ours.intersects_first(o, d), theirs.intersects_first(o, d)
    assert np.mean(a == b) >= 0.99, f"first hits agree on {np.mean(a == b):.3f}"
    both = (a >= 0) & (b >= 0)
    assert both.sum() > 60
    la, ra, _ = ours.intersects_location(o, d, multiple_hits=False)
    lb, rb, _ = theirs.intersects_location(o, d, multiple_hits=False)
    first_b = {r: p for r, p in zip(rb[::-1], lb[::-1])}  # trimesh: the first row per ray
    close = [np.linalg.norm(p - first_b[r]) < 1e-4 * scale for r, p in zip(ra, la) if r in first_b]
    assert np.mean(close) >= 0.99
    # Any hit.
    hit = ours.intersects_any(o, d)
    assert hit.dtype == bool and np.mean(hit == theirs.intersects_any(o, d)) >= 0.99
    assert np.array_equal(hit, a >= 0)
    # Every hit: the same number of crossings per ray (trimesh's are unique locations).
    ta, ra = ours.intersects_id(o, d, multiple_hits=True)[:2]
    tb, rb, _ = theirs.intersects_id(o, d, multiple_hits=True, return_locations=True)
    ca, cb = np.bincount(ra, minlength=len(o)), np.bincount(rb, minlength=len(o))
    assert np.mean(ca == cb) >= 0.98, f"crossing counts agree on {np.mean(ca == cb):.3f}"
    assert ca.sum() > 120
    capped = ours.intersects_id(o, d, multiple_hits=True, max_hits=1)[1]
    assert np.array_equal(np.bincount(capped, minlength=len(o)), np.minimum(ca, 1))


def test_trimesh_adapter_as_mesh_ray_serves_trimesh_itself():
    v, f = icosphere(3)
    tm = trimesh.Trimesh(v.astype(np.float64), f, process=False)
    tm.ray = ar.RayMeshIntersector(tm)
    p = np.random.default_rng(2).uniform(-1.5, 1.5, (2000, 3))
    r = np.linalg.norm(p, axis=1)
    inside = tm.contains(p)
    assert np.all(inside[r < 0.98]) and not np.any(inside[r > 1.0])
    loc, index_ray, index_tri = tm.ray.intersects_location([[0, 0, 5], [5, 5, 5]], [[0, 0, -1], [1, 0, 0]])
    assert list(index_ray) == [0, 0] and loc.dtype == np.float64
    assert np.allclose(np.sort(loc[:, 2]), [-1, 1], atol=0.01)
    assert list(tm.ray.intersects_any([[0, 0, 5]], [[0, 0, 1]])) == [False]
    # A changed mesh is seen.
    tm.vertices = tm.vertices * 2
    assert np.allclose(tm.ray.intersects_location([[0, 0, 5]], [[0, 0, -1]])[0][:, 2], [2, -2], atol=0.02)


def test_open3d_conventions():
    v, f = icosphere(2)
    scene = ar.RaycastingScene()
    assert scene.add_triangles(v, f) == 0
    assert scene.add_triangles(v + np.float32([5, 0, 0]), f) == 1
    rays = np.zeros((2, 3, 6), np.float32)
    rays[..., 2] = 5
    rays[..., 5] = -2  # a direction of length 2: t_hit in its units
    rays[1, :, 0] = [5, 20, 5]
    out = scene.cast_rays(rays)
    assert out["t_hit"].shape == (2, 3) and out["primitive_normals"].shape == (2, 3, 3)
    assert out["primitive_uvs"].shape == (2, 3, 2) and out["t_hit"].dtype == np.float32
    assert np.allclose(out["t_hit"][0], 2.0, atol=0.01)
    assert list(out["geometry_ids"][1]) == [1, ar.open3d_adapter.INVALID_ID, 1]
    assert out["primitive_ids"][1, 1] == ar.RaycastingScene.INVALID_ID and np.isinf(out["t_hit"][1, 1])
    assert np.allclose(np.linalg.norm(out["primitive_normals"][0], axis=-1), 1)
    assert list(scene.count_intersections(rays)[0]) == [2, 2, 2]
    assert list(scene.test_occlusions(rays, tfar=1.0)[0]) == [False] * 3
    assert list(scene.test_occlusions(rays, tnear=2.1)[0]) == [True] * 3
    lst = scene.list_intersections(rays[0])
    assert list(lst["ray_splits"]) == [0, 2, 4, 6] and list(lst["geometry_ids"]) == [0] * 6
    occ = scene.compute_occupancy(np.float32([[0, 0, 0], [5, 0, 0], [2.5, 0, 0]]))
    assert list(occ) == [1.0, 1.0, 0.0]


def test_open3d_itself_gives_the_same_hits():
    o3d = pytest.importorskip("open3d", reason="NOT CHECKED: open3d is not installed", exc_type=ImportError)
    v, f = soup(500, seed=3)
    ours = ar.RaycastingScene()
    ours.add_triangles(v, f.astype(np.uint32))
    theirs = o3d.t.geometry.RaycastingScene()
    theirs.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f.astype(np.uint32)))
    rng = np.random.default_rng(4)
    rays = np.concatenate([rng.uniform(-2, 12, (3000, 3)), rng.normal(size=(3000, 3)) * 3], 1).astype(np.float32)
    a, b = ours.cast_rays(rays), {k: x.numpy() for k, x in theirs.cast_rays(o3d.core.Tensor(rays)).items()}
    same = a["primitive_ids"] == b["primitive_ids"]
    assert np.mean(same) >= 0.999
    hit = same & (a["primitive_ids"] != ar.RaycastingScene.INVALID_ID)
    assert np.allclose(a["t_hit"][hit], b["t_hit"][hit], rtol=1e-4)
    assert np.allclose(a["primitive_uvs"][hit], b["primitive_uvs"][hit], atol=1e-4)
    assert np.allclose(np.abs(a["primitive_normals"][hit]), np.abs(b["primitive_normals"][hit]), atol=1e-4)
