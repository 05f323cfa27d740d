"""Closest point and unsigned distance against a float64 NumPy brute force: random soups and points,
points exactly on vertices and edges (ties to the lowest triangle index), inside a closed mesh, far
away, bounds; the shared meshes on a subset; trimesh's own proximity query; bad input."""

import os

import numpy as np
import pytest
from conftest import grid, icosphere, meshes_dir, soup

import arbor_rays as ar

KINDS = ["brute", "octree", "kdtree", "bvh-median", "bvh-sah", "bvh-bottom-up"]


def segment_dist2(p, a, b):
    """Squared distance from points p (P, 1, 3) to segments a-b (1, T, 3), float64."""
    d = b - a
    len2 = np.sum(d * d, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(len2 > 0, np.sum((p - a) * d, axis=-1) / len2, 0.0)
    t = np.clip(t, 0.0, 1.0)
    q = a + t[..., None] * d
    return np.sum((p - q) ** 2, axis=-1)


def brute_dist(v, f, points):
    """(P, T) float64 distances from every point to every triangle: to the plane where the point's
    projection falls inside the triangle, else to the nearest edge."""
    v = np.asarray(v, np.float64)
    p = np.asarray(points, np.float64)[:, None, :]
    a, b, c = v[f[:, 0]][None], v[f[:, 1]][None], v[f[:, 2]][None]
    n = np.cross(b - a, c - a)
    n2 = np.sum(n * n, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.sum((p - a) * n, axis=-1) / n2
        proj = p - h[..., None] * n
        inside = np.ones(h.shape, bool)
        for x, y in ((a, b), (b, c), (c, a)):
            inside &= np.sum(np.cross(y - x, proj - x) * n, axis=-1) >= 0
        face = np.where((n2 > 0) & inside, h * h * n2, np.inf)
    edges = np.minimum(np.minimum(segment_dist2(p, a, b), segment_dist2(p, b, c)), segment_dist2(p, c, a))
    return np.sqrt(np.minimum(face, edges))


def check_against_brute(v, f, points, got, max_distance=np.inf, chunk=64):
    """`got` (Mesh.closest_point's dict) is what the brute force allows: the nearest distance within
    1e-9 of the mesh's size, a triangle at that distance, a point on it at that distance from the
    query point, and nothing where no triangle is within the bound. Returns the answered count."""
    scale = 1.0 + float(np.abs(v).max())
    tol = 1e-9 * scale
    v64 = np.asarray(v, np.float64)
    answered = 0
    for s in range(0, len(points), chunk):
        p = np.asarray(points[s : s + chunk], np.float64)
        d = brute_dist(v, f, p)
        best = d.min(axis=1)
        tri, dist, pt = got["triangle"][s : s + chunk], got["distance"][s : s + chunk], got["point"][s : s + chunk]
        none = best > max_distance + tol
        sure = best < max_distance - tol
        assert np.all(tri[sure] >= 0), f"points {s + np.flatnonzero(sure & (tri < 0))} have a triangle within the bound"
        assert np.all(tri[none] == -1) and np.all(np.isinf(dist[none])) and np.all(np.isnan(pt[none]))
        i = np.flatnonzero(tri >= 0)
        answered += len(i)
        assert np.all(np.abs(dist[i] - best[i]) <= tol), f"distances off at points {s + i[np.abs(dist[i] - best[i]) > tol]}"
        assert np.all(d[i, tri[i]] <= best[i] + tol), "a triangle farther than the nearest"
        assert np.allclose(np.linalg.norm(pt[i] - p[i], axis=1), dist[i], rtol=0, atol=tol)
        # The point lies on its triangle, where its barycentric weights put it.
        a, b, c = (v64[f[tri[i], k]] for k in range(3))
        u, w = got["u"][s : s + chunk][i, None], got["v"][s : s + chunk][i, None]
        assert np.all((u >= 0) & (w >= 0) & (u + w <= 1 + 1e-12))
        assert np.allclose(a + (b - a) * u + (c - a) * w, pt[i], rtol=0, atol=tol)
    return answered


@pytest.mark.parametrize("kind", KINDS)
def test_closest_point_matches_brute_force_on_random_soups(kind):
    v, f = soup(300, seed=1)
    rng = np.random.default_rng(2)
    points = np.concatenate([rng.uniform(-3, 13, (1500, 3)), rng.uniform(-1e4, 1e4, (100, 3))])
    m = ar.Mesh(v, f).build(kind)
    got = m.closest_point(points)
    assert got["point"].dtype == np.float64 and got["point"].shape == (len(points), 3)
    assert got["distance"].dtype == np.float64 and got["triangle"].dtype == np.int64
    assert check_against_brute(v, f, points, got) == len(points)
    assert np.array_equal(m.distance(points), got["distance"])
    # Every structure gives brute force's answers, bit for bit, float32 points too, on any threads.
    want = ar.Mesh(v, f).build("brute").closest_point(points)
    for key in want:
        assert np.array_equal(got[key], want[key], equal_nan=True), key
    one = m.closest_point(points.astype(np.float32), threads=1)
    same = ar.Mesh(v, f).build("brute").closest_point(points.astype(np.float32).astype(np.float64))
    for key in one:
        assert np.array_equal(one[key], same[key], equal_nan=True), key


@pytest.mark.parametrize("kind", KINDS)
def test_points_on_vertices_and_edges_tie_to_the_lowest_triangle(kind):
    v, f = grid(8)
    m = ar.Mesh(v, f).build(kind)
    xs = np.arange(-1, 9.5, 0.5)
    pts = np.array([[x, y, z] for x in xs for y in xs for z in (0.0, 0.0, 1.5)])
    got = m.closest_point(pts)
    d = brute_dist(v, f, pts)
    best = d.min(axis=1)
    assert check_against_brute(v, f, pts, got) == len(pts)
    # Ties are exact on this lattice: the lowest index among the triangles at the nearest distance.
    lowest = np.argmax(d <= best[:, None], axis=1)
    assert np.array_equal(got["triangle"], lowest)
    ties = np.sum(d <= best[:, None], axis=1) > 1
    assert ties.mean() > 0.5, f"only {ties.mean():.2f} of the points are ties"
    on = (pts[:, 2] == 0) & (pts[:, 0] >= 0) & (pts[:, 0] <= 8) & (pts[:, 1] >= 0) & (pts[:, 1] <= 8)
    assert np.all(got["distance"][on] == 0.0) and np.array_equal(got["point"][on], pts[on])


def test_closed_mesh_inside_outside_and_on_the_surface():
    v, f = icosphere(3)
    m = ar.Mesh(v, f)
    rng = np.random.default_rng(3)
    inside = rng.uniform(-0.5, 0.5, (500, 3))
    outside = rng.normal(size=(500, 3)) * 3
    on_vertices = v[rng.integers(0, len(v), 200)].astype(np.float64)
    t = f[rng.integers(0, len(f), 300)]
    w = rng.dirichlet([1, 1, 1], 300)
    on_faces = np.einsum("ik,ikj->ij", w, v[t].astype(np.float64))
    pts = np.concatenate([inside, outside, on_vertices, on_faces, [[0, 0, 0]]])
    got = m.closest_point(pts)
    assert check_against_brute(v, f, pts, got) == len(pts)
    assert np.all(got["distance"][1000:1200] == 0.0), "a point on a vertex is at distance 0"
    assert np.all(got["distance"][1200:1500] < 1e-7)
    assert np.array_equal(m.contains(inside), np.ones(len(inside), bool))


def test_max_distance_bounds_the_answer():
    v, f = soup(200, seed=4)
    rng = np.random.default_rng(5)
    pts = rng.uniform(-1, 11, (2000, 3))
    for kind in ("brute", "bvh-sah", "octree", "kdtree"):
        m = ar.Mesh(v, f).build(kind)
        full = m.closest_point(pts)
        got = m.closest_point(pts, max_distance=0.75)
        within = full["distance"] <= 0.75
        assert 0.1 < within.mean() < 0.9
        assert check_against_brute(v, f, pts, got, max_distance=0.75) == within.sum()
        assert np.array_equal(got["triangle"], np.where(within, full["triangle"], -1))
        assert np.array_equal(m.distance(pts, max_distance=0.75), np.where(within, full["distance"], np.inf))
        assert np.all(m.closest_point(pts, max_distance=0.0)["triangle"] == -1)


def test_closest_point_on_the_shared_meshes():
    d = meshes_dir()
    rng = np.random.default_rng(6)
    for name in ("stanford-bunny.obj", "horse.ply"):
        m = ar.load_mesh(os.path.join(d, name))
        v, f = m.vertices, m.faces
        lo, hi = v.min(axis=0), v.max(axis=0)
        near = v[rng.integers(0, len(v), 100)] + rng.normal(size=(100, 3)) * 0.02 * (hi - lo)
        pts = np.concatenate([rng.uniform(lo - (hi - lo) * 0.3, hi + (hi - lo) * 0.3, (60, 3)), near,
                              v[rng.integers(0, len(v), 40)]])
        got = m.closest_point(pts)
        assert check_against_brute(v, f, pts, got, chunk=8) == len(pts)
        other = ar.load_mesh(os.path.join(d, name)).build("kdtree").closest_point(pts)
        for key in got:
            assert np.array_equal(got[key], other[key], equal_nan=True), (name, key)


def test_trimesh_closest_point_convention_and_agreement():
    trimesh = pytest.importorskip("trimesh", reason="NOT CHECKED: trimesh is not installed")
    pytest.importorskip("scipy", reason="NOT CHECKED: scipy (for trimesh.proximity) is not installed")
    v, f = icosphere(2)
    tm = trimesh.Trimesh(v.astype(np.float64), f, process=False)
    rng = np.random.default_rng(7)
    pts = rng.normal(size=(300, 3)) * 1.5
    theirs = trimesh.proximity.closest_point(tm, pts)
    ours = ar.trimesh_adapter.closest_point(tm, pts)
    assert [x.shape for x in ours] == [x.shape for x in theirs] == [(300, 3), (300,), (300,)]
    assert ours[0].dtype == np.float64 and ours[1].dtype == np.float64 and ours[2].dtype == np.int64
    assert np.allclose(ours[1], theirs[1], atol=1e-6)
    assert np.allclose(ours[0], theirs[0], atol=1e-5)
    # With mesh.ray set, its structure answers; an intersector is taken as it is.
    tm.ray = ar.RayMeshIntersector(tm, kind="octree")
    for x, y in zip(ar.trimesh_adapter.closest_point(tm, pts), ours):
        assert np.array_equal(x, y)
    assert tm.ray.arbor_mesh.stats()["kind"] == "octree"
    for x, y in zip(tm.ray.closest_point(pts), ours):
        assert np.array_equal(x, y)


def test_bad_points_and_bounds_raise_value_errors():
    v, f = soup(10, seed=8)
    m = ar.Mesh(v, f)
    p = np.zeros((4, 3))
    nan = p.copy()
    nan[2, 1] = np.nan
    cases = [
        (lambda: m.closest_point(p[:, :2]), "points must have shape (N, 3), got (4, 2)"),
        (lambda: m.distance(p.ravel()), "points must have shape (N, 3), got (12,)"),
        (lambda: m.closest_point(p.astype(complex)), "points must hold numbers, got dtype complex128"),
        (lambda: m.closest_point(nan), "points[2, 1]: non-finite coordinate `NaN`"),
        (lambda: m.distance(np.where(nan == nan, p, np.inf)), "points[2, 1]: non-finite coordinate `inf`"),
        (lambda: m.closest_point(p + 1e39), "points[0, 0]: non-finite coordinate `1e39`"),
        (lambda: m.closest_point(p, max_distance=-1.0), "max_distance must be a number >= 0 (inf: no bound), got -1.0"),
        (lambda: m.distance(p, max_distance=np.nan), "max_distance must be a number >= 0 (inf: no bound), got NaN"),
        (lambda: m.closest_point(p, threads=0), "threads must be at least 1 (None uses every core)"),
    ]
    for call, message in cases:
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value) == message
    with pytest.raises(TypeError):
        m.closest_point(p, max_distance="far")
    empty = m.closest_point(np.zeros((0, 3)))
    assert empty["point"].shape == (0, 3) and empty["triangle"].shape == (0,)
    ints = m.closest_point(np.array([[1, 2, 3]]))
    assert np.array_equal(ints["distance"], m.distance(np.array([[1.0, 2.0, 3.0]])))


def test_open3d_compute_closest_points_conventions():
    scene = ar.RaycastingScene()
    v, f = grid(2)
    a = scene.add_triangles(v, f)
    b = scene.add_triangles(v + np.float32([0, 0, 5]), f)
    q = np.array([[[0.5, 0.25, 1.0], [0.5, 0.25, 4.0]], [[3.0, 3.0, 0.0], [1.0, 1.0, 2.5]]])
    out = scene.compute_closest_points(q)
    assert out["points"].shape == (2, 2, 3) and out["points"].dtype == np.float32
    assert out["geometry_ids"].dtype == np.uint32 and out["primitive_uvs"].shape == (2, 2, 2)
    assert out["geometry_ids"].tolist() == [[a, b], [a, a]], "the middle point ties between the two: the first"
    assert out["primitive_ids"].tolist() == [[0, 0], [6, 0]]
    assert np.allclose(out["points"], [[[0.5, 0.25, 0], [0.5, 0.25, 5]], [[2, 2, 0], [1, 1, 0]]])
    assert np.allclose(np.abs(out["primitive_normals"][..., 2]), 1.0)
    assert np.allclose(scene.compute_distance(q), [[1.0, 1.0], [2 ** 0.5, 2.5]])
