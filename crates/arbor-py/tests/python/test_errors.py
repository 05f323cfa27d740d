"""Bad input: a ValueError (or OSError for files) with the CLI's wording, never a crash."""

import os
import subprocess
import sys
import threading

import numpy as np
import pytest
from conftest import soup

import arbor_rays as ar

V = np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
F = np.array([[0, 1, 2], [1, 3, 2]])


@pytest.mark.parametrize(
    "vertices,faces,message",
    [
        (V[:, :2], F, "vertices must have shape (N, 3), got (4, 2)"),
        (V.ravel(), F, "vertices must have shape (N, 3), got (12,)"),
        (V, F[:, :2], "faces must have shape (M, 3), got (2, 2)"),
        (V, F.astype(np.float64), "faces must hold integer vertex indices, got dtype float64"),
        (V, F.astype(bool), "faces must hold integer vertex indices, got dtype bool"),
        (V.astype(complex), F, "vertices must hold numbers, got dtype complex128"),
        (np.array([["a", "b", "c"]]), F, "vertices must hold numbers, got dtype <U1"),
        (V, F + 2, "faces[0, 2]: vertex index 4 out of range (there are 4 vertices)"),
        (V, F - 1, "faces[0, 0]: vertex index -1 out of range (there are 4 vertices)"),
        (V, F.astype(np.uint64) + np.uint64(2**63), "faces[0, 0]: vertex index 9223372036854775808 out of range (there are 4 vertices)"),
        (V, F.astype(np.int64) + 2**32, "faces[0, 0]: vertex index 4294967296 out of range (there are 4 vertices)"),
        (np.where(np.arange(12).reshape(4, 3) == 4, np.nan, V), F, "vertices[1, 1]: non-finite coordinate `NaN`"),
        (np.where(np.arange(12).reshape(4, 3) == 11, np.inf, V), F, "vertices[3, 2]: non-finite coordinate `inf`"),
        (V.astype(np.float64) * 1e39, F, "vertices[1, 0]: non-finite coordinate `1e39`"),
        (V, F[:0], "faces is empty: a mesh needs at least one triangle"),
        (V[:0], F[:0], "faces is empty: a mesh needs at least one triangle"),
        (V[:0], F, "faces[0, 0]: vertex index 0 out of range (there are 0 vertices)"),
    ],
)
def test_bad_meshes_raise_value_errors_naming_the_problem(vertices, faces, message):
    with pytest.raises(ValueError) as e:
        ar.Mesh(vertices, faces)
    assert str(e.value) == message


def test_bad_rays_and_arguments_raise_value_errors():
    m = ar.Mesh(V, F)
    o = np.zeros((5, 3), np.float32)
    d = np.ones((5, 3), np.float32)
    cases = [
        (lambda: m.intersect(o, d[:4]), "origins has 5 rows but directions has 4: one of each per ray"),
        (lambda: m.intersect(o[:, :2], d), "origins must have shape (N, 3), got (5, 2)"),
        (lambda: m.occluded(o, d.T), "directions must have shape (N, 3), got (3, 5)"),
        (lambda: m.intersect(o, d, np.zeros(4)), "t_min must be a number or have shape (5,), one per ray, got (4,)"),
        (lambda: m.intersect_all(o, d, 0.0, np.zeros((5, 1))), "t_max must be a number or have shape (5,), one per ray, got (5, 1)"),
        (lambda: m.intersect(o, d, "near"), "t_min must be a number or an array of one per ray"),
        (lambda: m.intersect(o, d, threads=0), "threads must be at least 1 (None uses every core)"),
        (lambda: m.intersect(o, d, fields=["t", "depth"]), "fields: unknown field `depth` (the fields are t, triangle, u, v, normal, point)"),
        (lambda: m.contains(o[:, :1]), "points must have shape (N, 3), got (5, 1)"),
        (lambda: m.build("quadtree"), "unknown acceleration structure 'quadtree' (expected one of: brute, octree, kdtree, bvh-median, bvh-sah, bvh-bottom-up)"),
        (lambda: m.build("octree", depth=99), "parameter 'depth': 99 is outside its range 0..=16"),
        (lambda: m.build("bvh-sah", depth=3), "bvh-sah has no parameter 'depth' (it has: leaf, bins, traversal-cost, intersection-cost, leaf-block)"),
        (lambda: m.build("brute", leaf=1), "brute takes no parameters (got 'leaf')"),
        (lambda: m.build("bvh-bottom-up", method="best"), "parameter 'method': cannot read 'best' (expected auto|greedy|ploc)"),
    ]
    for call, message in cases:
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value) == message
    with pytest.raises(OverflowError):
        m.intersect(o, d, threads=-1)
    # A refused rebuild keeps the structure that was there.
    assert m.stats()["kind"] == "bvh-sah"


def test_files_raise_os_errors_and_located_value_errors(tmp_path):
    with pytest.raises(OSError) as e:
        ar.load_mesh(str(tmp_path / "missing.ply"))
    assert "missing.ply" in str(e.value)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n")
    with pytest.raises(ValueError) as e:
        ar.load_mesh(str(bad))
    assert str(e.value) == f"{bad}:3:5: non-finite coordinate `nan`"
    ok = tmp_path / "ok.obj"
    ok.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    m = ar.load_mesh(ok)
    assert len(m) == 1 and m.intersect([[0.2, 0.2, 1]], [[0, 0, -1]])["triangle"][0] == 0
    with pytest.raises(ValueError) as e:
        ar.render(str(ok))
    assert "mesh file" in str(e.value) or str(e.value).startswith(str(ok))


def test_the_gil_is_released_during_a_query():
    """Another Python thread makes progress while a long query runs in this one."""
    v, f = soup(20000, seed=1, size=0.5)
    m = ar.Mesh(v, f).build()
    rng = np.random.default_rng(2)
    points = rng.uniform(0, 10, (150000, 3)).astype(np.float32)
    m.contains(points[:10])  # the collecting structure, built now
    running = threading.Event()
    done = threading.Event()
    ticks = []

    def other():
        running.set()
        while not done.is_set():
            ticks.append(1)
            done.wait(0.0005)

    t = threading.Thread(target=other)
    t.start()
    running.wait()
    before = len(ticks)
    m.contains(points, threads=1)
    during = len(ticks) - before
    done.set()
    t.join()
    # Holding the GIL, the query would leave the other thread at most the one switch interval
    # before it started.
    assert during >= 20, f"the other thread ran {during} times during the query"


def test_help_shows_shapes_dtypes_and_units_and_the_stubs_name_what_exists():
    import ast
    import pathlib

    for f in (ar.Mesh.intersect, ar.Mesh.intersect_all, ar.Mesh.occluded, ar.Mesh.contains, ar.Mesh.closest_point, ar.render):
        doc = f.__doc__
        assert "(N, 3)" in doc or "(H, W, 3)" in doc, f.__name__
        assert "float32" in doc or "bool" in doc, f.__name__
    assert "units of" in ar.Mesh.intersect.__doc__
    stub = pathlib.Path(ar.__file__).with_name("_native.pyi")
    if not stub.exists():  # an installed wheel keeps its stubs beside the package
        stub = pathlib.Path(__file__).parents[2] / "python" / "arbor_rays" / "_native.pyi"
    tree = ast.parse(stub.read_text())
    names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    assert names == {"Mesh", "load_mesh", "accel_kinds", "render"}
    methods = {n.name for n in next(n for n in tree.body if getattr(n, "name", "") == "Mesh").body if isinstance(n, ast.FunctionDef)}
    for m in methods - {"__init__"}:
        assert hasattr(ar.Mesh, m), m
    for m in ("intersect", "occluded", "intersect_all", "count_crossings", "contains", "closest_point", "distance", "build", "stats"):
        assert m in methods, m


def test_an_unknown_kernel_cap_fails_the_import():
    env = dict(os.environ, ARBOR_MAX_ISA="avx3")
    o = subprocess.run([sys.executable, "-c", "import arbor_rays"], env=env, capture_output=True, text=True)
    assert o.returncode != 0
    assert 'ValueError: ARBOR_MAX_ISA="avx3": expected avx512, avx2 or sse' in o.stderr
    env["ARBOR_MAX_ISA"] = "sse"
    subprocess.run([sys.executable, "-c", "import arbor_rays"], env=env, check=True)
