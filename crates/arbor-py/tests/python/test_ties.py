"""Rays aimed exactly at vertices and edges, rays started on the surface, degenerate and NaN rays:
the tie rule (README: each surface crossing once) and the closest hit's tie to the lowest index."""

import numpy as np
import pytest
from conftest import check_closest, grid, icosphere, uv_sphere

import arbor_rays as ar


def test_grid_rays_down_onto_vertices_and_edges_cross_once_at_the_lowest_index():
    v, f = grid(8)
    m = ar.Mesh(v, f)
    xs = np.arange(0, 8.5, 0.5)  # vertices, edge midpoints and the squares' diagonals' midpoints
    px, py = np.meshgrid(xs, xs)
    o = np.stack([px.ravel(), py.ravel(), np.full(px.size, 3.0)], axis=1).astype(np.float32)
    d = np.tile(np.float32([0, 0, -1]), (len(o), 1))
    got = m.intersect(o, d)
    assert np.all(got["triangle"] >= 0) and np.all(got["t"] == 3.0)
    # The lowest index among the triangles that hold the point (float64, exactly on them).
    p = o[:, :2].astype(np.float64)
    for i in range(len(o)):
        a, b, c = (v[f[:, k], :2].astype(np.float64) for k in range(3))
        cross = lambda u, w: u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]  # noqa: E731
        e = np.stack([cross(b - a, p[i] - a), cross(c - b, p[i] - b), cross(a - c, p[i] - c)], 1)
        holders = np.flatnonzero(np.all(e >= 0, axis=1))
        assert got["triangle"][i] == holders.min(), f"ray {i} at {o[i]}"
    assert np.all(m.count_crossings(o, d) == 1), "a vertex of 6 triangles or an edge of 2 is one crossing"
    a = m.intersect_all(o, d)
    assert np.array_equal(a["ray"], np.arange(len(o)))
    assert np.array_equal(a["triangle"], got["triangle"])
    # The same from below.
    assert np.all(m.count_crossings(o * [1, 1, -1], -d) == 1)


def test_oblique_rays_onto_grid_vertices_and_edges_cross_once():
    # About 1% of these slipped through a vertex's fan while the triangle test's double-precision
    # fallback recomputed a whole triangle when one edge function was zero (arbor-accel,
    # geometry/triangle.rs); it recomputes each zero edge on its own now.
    v, f = grid(16)
    m = ar.Mesh(v, f)
    rng = np.random.default_rng(5)
    xs = np.arange(1, 16, 0.5)
    px, py = np.meshgrid(xs, xs)
    target = np.repeat(np.stack([px.ravel(), py.ravel(), np.zeros(px.size)], 1), 10, axis=0)
    src = target + np.concatenate([rng.uniform(-3, 3, (len(target), 2)), rng.uniform(1, 4, (len(target), 1))], 1)
    o = src.astype(np.float32)
    n = m.count_crossings(o, (target - src).astype(np.float32))
    assert np.all(n == 1), f"counts {np.unique(n, return_counts=True)}"


@pytest.mark.parametrize("name,mesh", [("icosphere", icosphere(3)), ("uv sphere", uv_sphere(12, 24))])
def test_rays_through_the_vertices_and_edges_of_a_closed_sphere_cross_it_twice(name, mesh):
    v, f = mesh
    m = ar.Mesh(v, f)
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    mids = (v[edges[:, 0]].astype(np.float64) + v[edges[:, 1]]) / 2
    targets = np.concatenate([v.astype(np.float64), mids])
    rng = np.random.default_rng(2)
    # From outside, through the target, on through the inside (jittered so that exits vary).
    src = targets * 3 + rng.normal(scale=0.2, size=targets.shape)
    o = src.astype(np.float32)
    d = (targets.astype(np.float32) - o).astype(np.float32)
    n = m.count_crossings(o, d)
    assert np.all(n == 2), f"{name}: counts {np.unique(n, return_counts=True)}"
    a = m.intersect_all(o, d)
    assert np.array_equal(np.bincount(a["ray"], minlength=len(o)), n)
    # Axis-aligned rays through the poles of the UV sphere (24 triangles meet there).
    polar = m.count_crossings(np.float32([[0, 0, 3], [0, 0, -3]]), np.float32([[0, 0, -1], [0, 0, 1]]))
    assert list(polar) == [2, 2]
    first = m.intersect(o, d)
    check_closest(v, f, o, d, first)


def test_rays_started_on_the_surface_skip_it_with_t_min():
    v, f = icosphere(3)
    m = ar.Mesh(v, f)
    rng = np.random.default_rng(3)
    o = rng.normal(size=(3000, 3)) * 3
    o = o[np.linalg.norm(o, axis=1) > 1.5][:2000].astype(np.float32)  # outside the sphere
    d = (rng.normal(size=(2000, 3)) * 0.05 - o).astype(np.float32)
    first = m.intersect(o, d)
    hit = first["triangle"] >= 0
    assert hit.sum() > 1500
    p, dd = first["point"][hit], d[hit]
    # From the hit point on, with t_min past the surface: the exit, never the triangle started on.
    again = m.intersect(p, dd, t_min=1e-4)
    assert np.all(again["triangle"] >= 0) and np.all(again["triangle"] != first["triangle"][hit])
    check_closest(v, f, p, dd, again, t_min=1e-4)
    assert np.all(m.count_crossings(p, dd, t_min=1e-4) == 1)
    # Back the other way from the hit point: nothing (the sphere is convex).
    assert not np.any(m.occluded(p, -dd, t_min=1e-4))
    # Starting at the surface without t_min: the watertight test's own guard refuses hits within
    # the rounding error of t = 0, so the start triangle is almost never hit; t_min makes it never.
    t_in_units = m.intersect(p, dd, t_min=0.0)
    assert np.mean(t_in_units["triangle"] == first["triangle"][hit]) < 0.01


def test_degenerate_triangles_and_rays_hit_nothing():
    v = np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0], [3, 0, 0]])
    f = np.array([[0, 1, 2], [0, 1, 3], [1, 1, 1], [0, 3, 4]])  # one real, three of zero area
    m = ar.Mesh(v, f)
    o = np.float32([[0.2, 0.2, 1], [0.5, 0, 1], [0.2, 0.2, 1], [np.nan, 0, 1], [0.2, 0.2, 1], [0.2, 0.2, np.inf], [1.5, 0, 1]])
    d = np.float32([[0, 0, -1], [0, 0, -1], [0, 0, 0], [0, 0, -1], [np.nan, 0, -1], [0, 0, -1], [0, 0, -1]])
    got = m.intersect(o, d)
    assert list(got["triangle"]) == [0, 0, -1, -1, -1, -1, -1]
    assert list(m.occluded(o, d)) == [True, True, False, False, False, False, False]
    assert list(m.count_crossings(o, d)) == [1, 1, 0, 0, 0, 0, 0]
    assert not m.contains(np.float32([[np.nan, 0, 0]]))[0]
    # NaN bounds are a miss too; a ray in the triangle's plane hits nothing.
    assert list(m.intersect(o[:1], d[:1], np.nan)["triangle"]) == [-1]
    assert list(m.intersect(o[:1], d[:1], 0.0, np.nan)["triangle"]) == [-1]
    assert list(m.intersect(np.float32([[-1, 0.2, 0]]), np.float32([[1, 0, 0]]))["triangle"]) == [-1]


def test_every_ray_through_a_sphere_vertex_crosses_it_twice():
    # Failed with the per-triangle fallback too (see test_oblique_rays_onto_grid_vertices_and_edges_cross_once).
    v, f = icosphere(3)
    rng = np.random.default_rng(2)
    o = (v.astype(np.float64) * 3 + rng.normal(scale=0.2, size=v.shape)).astype(np.float32)
    n = ar.Mesh(v, f).count_crossings(o, (v - o).astype(np.float32))
    assert np.all(n == 2), f"counts {np.unique(n, return_counts=True)}"
