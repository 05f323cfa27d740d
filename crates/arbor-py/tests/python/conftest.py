"""Shared helpers: meshes made here (random soups, grids, spheres) and a float64 NumPy brute force."""

import os

import numpy as np
import pytest


def soup(n, seed, spread=10.0, size=1.0):
    """`n` random triangles in a box of side `spread`, float32 vertices (unwelded)."""
    rng = np.random.default_rng(seed)
    centers = rng.uniform(0, spread, (n, 1, 3))
    v = (centers + rng.uniform(-size, size, (n, 3, 3))).reshape(-1, 3).astype(np.float32)
    f = np.arange(3 * n, dtype=np.int64).reshape(n, 3)
    return v, f


def grid(n):
    """A flat n x n grid of unit squares in z = 0, two triangles each: vertices on integers."""
    xs, ys = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="xy")
    v = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1).astype(np.float32)
    faces = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 2, a + n + 1
            faces += [[a, b, c], [a, c, d]]
    return v, np.array(faces, dtype=np.int64)


def icosphere(subdivisions):
    """A closed unit icosphere (welded, counter-clockwise outward)."""
    t = (1 + 5**0.5) / 2
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    v = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(subdivisions):
        mid, nf = {}, []

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = v[a] + v[b]
                v.append(p / np.linalg.norm(p))
                mid[key] = len(v) - 1
            return mid[key]

        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        f = nf
    return np.array(v, dtype=np.float32), np.array(f, dtype=np.int64)


def uv_sphere(rings, segments):
    """A closed unit UV sphere whose poles are vertices shared by `segments` triangles."""
    v = [[0, 0, 1]]
    for i in range(1, rings):
        th = np.pi * i / rings
        for j in range(segments):
            ph = 2 * np.pi * j / segments
            v.append([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
    v.append([0, 0, -1])
    f = []
    row = lambda i, j: 1 + (i - 1) * segments + j % segments  # noqa: E731
    for j in range(segments):
        f.append([0, row(1, j), row(1, j + 1)])
    for i in range(1, rings - 1):
        for j in range(segments):
            a, b, c, d = row(i, j), row(i + 1, j), row(i + 1, j + 1), row(i, j + 1)
            f += [[a, b, c], [a, c, d]]
    s = len(v) - 1
    for j in range(segments):
        f.append([s, row(rings - 1, j + 1), row(rings - 1, j)])
    return np.array(v, dtype=np.float32), np.array(f, dtype=np.int64)


def random_rays(n, seed, lo=-2.0, hi=12.0):
    rng = np.random.default_rng(seed)
    o = rng.uniform(lo, hi, (n, 3)).astype(np.float32)
    d = rng.normal(size=(n, 3)).astype(np.float32)
    return o, d


def brute(v, f, o, d, t_min=0.0, t_max=np.inf, eps=1e-6):
    """Float64 Möller-Trumbore of every ray against every triangle: (t, b1, b2, margin) arrays of
    shape (rays, triangles), where margin is the smallest barycentric coordinate (negative: outside)
    and t is NaN where the ray is parallel to the plane."""
    v = v.astype(np.float64)
    o = np.asarray(o, np.float64)[:, None, :]
    d = np.asarray(d, np.float64)[:, None, :]
    a, b, c = v[f[:, 0]][None], v[f[:, 1]][None], v[f[:, 2]][None]
    e1, e2 = b - a, c - a
    p = np.cross(d, e2)
    det = np.sum(e1 * p, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - a
        b1 = np.sum(s * p, axis=-1) * inv
        q = np.cross(s, e1)
        b2 = np.sum(d * q, axis=-1) * inv
        t = np.sum(e2 * q, axis=-1) * inv
    margin = np.minimum(np.minimum(b1, b2), 1 - b1 - b2)
    t = np.where(np.abs(det) > 1e-300, t, np.nan)
    return t, b1, b2, margin


def expected_closest(v, f, o, d, t_min=0.0, t_max=np.inf, eps=1e-5):
    """What the float64 brute force says of each ray's closest hit, with a tolerance band:
    (sure_t, maybe): sure_t the smallest t of a hit inside every triangle by more than eps (inf if
    none), and maybe a (rays, triangles) mask of hits within eps of a triangle, t inside the range
    give or take eps."""
    t, _, _, margin = brute(v, f, o, d)
    tmin = np.broadcast_to(np.asarray(t_min, np.float64), (len(o),))[:, None]
    tmax = np.broadcast_to(np.asarray(t_max, np.float64), (len(o),))[:, None]
    tol = 1e-4 * (1 + np.abs(np.nan_to_num(t, nan=0.0)))
    with np.errstate(invalid="ignore"):
        sure = (margin > eps) & (t > tmin + tol) & (t < tmax - tol)
        maybe = (margin > -eps) & (t > tmin - tol) & (t < tmax + tol)
    sure_t = np.where(sure, t, np.inf).min(axis=1)
    return t, sure_t, maybe


def check_closest(v, f, o, d, got, t_min=0.0, t_max=np.inf):
    """Asserts that `got` (Mesh.intersect's dict) is a closest hit the float64 brute force allows:
    a miss only where no ray hits a triangle's interior, else a triangle hit within the tolerance,
    at its t, no farther than the closest sure hit. Returns the number of hits."""
    t, sure_t, maybe = expected_closest(v, f, o, d, t_min, t_max)
    tri, tt = got["triangle"], got["t"].astype(np.float64)
    miss = tri < 0
    assert np.all(np.isinf(sure_t[miss])), f"missed rays {np.flatnonzero(miss & np.isfinite(sure_t))[:10]}"
    assert np.all(np.isinf(tt[miss]))
    i = np.flatnonzero(~miss)
    k = tri[i]
    tol = 1e-4 * (1 + np.abs(tt[i]))
    assert np.all(maybe[i, k]), f"hits the brute force refuses: rays {i[~maybe[i, k]][:10]}"
    assert np.all(np.abs(tt[i] - t[i, k]) <= tol), "t differs from the brute force's"
    assert np.all(tt[i] <= sure_t[i] + tol), f"not the closest: rays {i[tt[i] > sure_t[i] + tol][:10]}"
    return len(i)


def meshes_dir():
    """The shared meshes, or None (a NOT CHECKED skip; a failure under CI=true)."""
    d = os.environ.get("ARBOR_MESHES")
    if d and os.path.isdir(d):
        return d
    msg = "NOT CHECKED: the shared meshes (ARBOR_MESHES) are absent"
    if os.environ.get("CI") == "true":
        pytest.fail(msg + " under CI=true")
    pytest.skip(msg)
