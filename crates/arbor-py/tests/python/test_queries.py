"""Every query against a float64 NumPy brute force: random soups and rays, every structure."""

import numpy as np
import pytest
from conftest import brute, check_closest, expected_closest, icosphere, random_rays, soup

import arbor_rays as ar

KINDS = ["brute", "octree", "kdtree", "bvh-median", "bvh-sah", "bvh-bottom-up"]


@pytest.mark.parametrize("kind", KINDS)
def test_closest_hit_matches_brute_force_on_random_soups(kind):
    v, f = soup(300, seed=1)
    o, d = random_rays(2000, seed=2)
    m = ar.Mesh(v, f).build(kind)
    got = m.intersect(o, d)
    hits = check_closest(v, f, o, d, got)
    assert 200 < hits < 1900, f"{hits} hits is not a useful test"
    # The normal is the unit normal of the triangle hit, the point lies on it at (u, v).
    i = np.flatnonzero(got["triangle"] >= 0)
    a, b, c = (v[f[got["triangle"][i], k]].astype(np.float64) for k in range(3))
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    assert np.allclose(got["normal"][i], n, atol=1e-5)
    p = a + (b - a) * got["u"][i, None] + (c - a) * got["v"][i, None]
    assert np.allclose(got["point"][i], p, atol=1e-4)
    assert np.allclose(got["point"][i], o[i] + got["t"][i, None] * d[i], atol=1e-3)


@pytest.mark.parametrize("kind", KINDS)
def test_every_structure_gives_the_same_answers_bit_for_bit(kind):
    v, f = soup(400, seed=3)
    o, d = random_rays(1500, seed=4)
    want = ar.Mesh(v, f).build("brute")
    m = ar.Mesh(v, f).build(kind)
    a, b = want.intersect(o, d), m.intersect(o, d)
    for key in a:
        assert np.array_equal(a[key], b[key]), key
    assert np.array_equal(want.occluded(o, d), m.occluded(o, d))
    x, y = want.intersect_all(o, d), m.intersect_all(o, d)
    for key in x:
        assert np.array_equal(x[key], y[key]), key


def test_fields_limit_the_answer_to_the_outputs_asked_for():
    v, f = soup(300, seed=20)
    o, d = random_rays(1000, seed=21)  # not a whole number of the queries' chunks of 256 rays
    m = ar.Mesh(v, f)
    t_min = np.random.default_rng(22).uniform(0.0, 2.0, len(o)).astype(np.float32)
    every = m.intersect(o, d, t_min)
    assert list(every) == ["t", "triangle", "u", "v", "normal", "point"]
    miss = every["triangle"] < 0
    assert 100 < miss.sum() < 900
    assert np.all(np.isinf(every["t"][miss]))
    for key in ("u", "v", "normal", "point"):
        assert not np.any(every[key][miss]), f"a miss has a nonzero {key}"
    for fields in (["triangle"], ["point", "t"], ["v"], ["normal", "u", "triangle"], []):
        got = m.intersect(o, d, t_min, fields=fields)
        assert list(got) == [k for k in every if k in fields]
        for key in got:
            assert np.array_equal(got[key], every[key]), key


def test_any_hit_is_an_occlusion_query_within_its_interval():
    v, f = soup(300, seed=5)
    o, d = random_rays(2000, seed=6)
    m = ar.Mesh(v, f)
    t_max = np.random.default_rng(7).uniform(0.5, 8.0, len(o)).astype(np.float32)
    got = m.occluded(o, d, 0.0, t_max)
    closest = m.intersect(o, d, 0.0, t_max)
    assert got.dtype == bool and got.shape == (len(o),)
    assert np.array_equal(got, closest["triangle"] >= 0)
    _, sure_t, maybe = expected_closest(v, f, o, d, 0.0, t_max)
    assert np.all(got[np.isfinite(sure_t)]), "a ray hits a triangle's interior inside its interval"
    assert not np.any(got & ~maybe.any(axis=1)), "an occlusion the brute force does not allow"


def test_t_min_and_t_max_as_scalars_and_arrays():
    v, f = soup(300, seed=8)
    o, d = random_rays(1500, seed=9)
    m = ar.Mesh(v, f)
    rng = np.random.default_rng(10)
    t_min = rng.uniform(0, 3, len(o))
    t_max = t_min + rng.uniform(0, 6, len(o))
    for lo, hi in [(t_min, t_max), (1.5, t_max), (t_min, 4.0), (2.0, 5.0)]:
        got = m.intersect(o, d, lo, hi)
        check_closest(v, f, o, d, got, lo, hi)
        hit = got["triangle"] >= 0
        assert np.all(got["t"][hit] > np.broadcast_to(lo, len(o))[hit] - 1e-4)
        assert np.all(got["t"][hit] < np.broadcast_to(hi, len(o))[hit] + 1e-4)
        assert np.array_equal(m.occluded(o, d, lo, hi), hit)
    none = m.intersect(o, d, 5.0, 5.0)
    assert np.all(none["triangle"] == -1), "an empty interval hits nothing"


def test_all_hits_are_every_crossing_of_the_brute_force_in_order():
    v, f = soup(300, seed=11, size=2.5)
    o, d = random_rays(800, seed=12)
    m = ar.Mesh(v, f)
    a = m.intersect_all(o, d)
    t, _, _, margin = brute(v, f, o, d)
    with np.errstate(invalid="ignore"):
        sure = (margin > 1e-5) & (t > 1e-4)
        maybe = (margin > -1e-5) & (t > -1e-4)
    counts = np.bincount(a["ray"], minlength=len(o))
    assert np.array_equal(counts, m.count_crossings(o, d))
    assert counts.sum() > 500
    for i in range(len(o)):
        rows = np.flatnonzero(a["ray"] == i)
        tris = a["triangle"][rows]
        assert set(np.flatnonzero(sure[i])) <= set(tris), f"ray {i} lost a crossing"
        assert all(maybe[i, tris]), f"ray {i}: a crossing the brute force refuses"
        assert np.all(np.diff(a["t"][rows]) >= 0), "crossings in order of t"
        assert len(set(tris)) == len(tris)
    # The first crossing is the closest hit.
    c = m.intersect(o, d)
    first = np.concatenate([[True], a["ray"][1:] != a["ray"][:-1]])
    assert np.array_equal(a["triangle"][first], c["triangle"][c["triangle"] >= 0])
    assert np.array_equal(a["t"][first], c["t"][c["triangle"] >= 0])
    # The cap keeps the closest ones.
    capped = m.intersect_all(o, d, max_hits=2)
    assert np.array_equal(np.bincount(capped["ray"], minlength=len(o)), np.minimum(counts, 2))


def test_contains_agrees_with_the_sphere():
    v, f = icosphere(3)
    m = ar.Mesh(v, f)
    rng = np.random.default_rng(13)
    p = rng.uniform(-1.5, 1.5, (5000, 3))
    r = np.linalg.norm(p, axis=1)
    inside = m.contains(p)
    # The icosphere lies between its inscribed radius (about 0.99 at 3 subdivisions) and 1.
    assert np.all(inside[r < 0.98]) and not np.any(inside[r > 1.0])
    assert inside.sum() > 600  # a sixth of the cube
    # Points on the grid of the sphere's own coordinates (rays along axes would meet edges).
    g = np.stack(np.meshgrid(*[np.linspace(-1.25, 1.25, 11)] * 3), -1).reshape(-1, 3)
    r = np.linalg.norm(g, axis=1)
    got = m.contains(g)
    assert np.all(got[r < 0.98]) and not np.any(got[r > 1.0])


def test_threads_do_not_change_answers():
    v, f = soup(500, seed=14)
    o, d = random_rays(3000, seed=15)
    m = ar.Mesh(v, f)
    one, two, every = (m.intersect(o, d, threads=n) for n in (1, 2, None))
    for key in one:
        assert np.array_equal(one[key], two[key]) and np.array_equal(one[key], every[key])
    assert np.array_equal(m.intersect_all(o, d, threads=1)["t"], m.intersect_all(o, d, threads=2)["t"])
    assert np.array_equal(m.contains(o, threads=1), m.contains(o, threads=2))


def test_inputs_of_any_dtype_and_order_give_the_same_answers_and_are_not_written():
    v, f = soup(200, seed=16)
    o, d = random_rays(500, seed=17)
    want = ar.Mesh(v, f).intersect(o, d)
    for vv, ff, oo, dd in [
        (v.astype(np.float64), f.astype(np.int32), o.astype(np.float64), d.astype(np.float64)),
        (np.asfortranarray(v), np.asfortranarray(f.astype(np.uint32)), np.asfortranarray(o), np.asfortranarray(d)),
        (v.astype(np.float64)[::-1][::-1], f.astype(np.int16), o[::1], d.tolist()),
        (v.tolist(), f.astype(np.uint16).tolist(), o, d),
    ]:
        copies = [np.array(x, copy=True) for x in (vv, ff, oo, dd)]
        got = ar.Mesh(vv, ff).intersect(oo, dd)
        for key in want:
            assert np.array_equal(want[key], got[key]), key
        for x, c in zip((vv, ff, oo, dd), copies):
            assert np.array_equal(np.asarray(x), c), "an input was written"
    ro = o.copy()
    ro.flags.writeable = False
    ar.Mesh(v, f).intersect(ro, d)


def test_empty_ray_arrays_give_empty_answers():
    v, f = soup(10, seed=18)
    m = ar.Mesh(v, f)
    e = np.zeros((0, 3), np.float32)
    got = m.intersect(e, e)
    assert got["t"].shape == (0,) and got["normal"].shape == (0, 3)
    assert m.occluded(e, e).shape == (0,)
    assert m.intersect_all(e, e)["point"].shape == (0, 3)
    assert m.count_crossings(e, e).shape == (0,)
    assert m.contains(e).shape == (0,)


def test_stats_and_build_parameters():
    v, f = soup(1000, seed=19)
    m = ar.Mesh(v, f)
    s = m.stats()
    assert s["kind"] == "bvh-sah" and s["primitives"] == 1000 and s["nodes"] > 1
    assert s["build_seconds"] >= 0 and s["bytes"] > 0
    s = m.build("kdtree", depth=12, empty_bonus=0.5).stats()
    assert s["config"] == "kdtree empty-bonus=0.5 depth=12" and s["max_depth"] <= 12
    assert m.build("bvh-bottom-up", method="ploc", radius=8).stats()["config"] == "bvh-bottom-up method=ploc radius=8"
    assert m.build("octree", leaf=4).stats()["kind"] == "octree"
    kinds = ar.accel_kinds()
    assert list(kinds) == KINDS
    for kind, params in kinds.items():
        for key, _, default, _ in params:
            m.build(kind, **{key: default})
    assert len(m) == 1000 and m.vertices.shape == (3000, 3) and m.faces.dtype == np.int64
