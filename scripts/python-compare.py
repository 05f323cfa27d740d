#!/usr/bin/env python3
"""Ray queries from Python: arbor_rays against embreex (raw and through trimesh), Open3D's
RaycastingScene and trimesh's pure-Python ray_triangle, on the same float32 rays, in one run.

Meshes: igea.ply from the shared meshes and an icosphere of about 1.3M triangles (8 subdivisions,
made here). Ray sets of --rays rays each (1M by default), float32:
  primary   from a plane above the mesh's bounding box, straight into it (coherent);
  diffuse   from random surface points, offset along the triangle's normal by 1e-4 of the box's
            diagonal, cosine-distributed around the normal (incoherent);
  aimed     from random points around the mesh, aimed exactly at its vertices (half) and at its edge
            midpoints (half): t = 1 lands on them.
For every tool and thread count: Mrays/s of closest-hit queries, the conversions from and to NumPy
arrays included (median of --runs), and for the structures the build seconds (Open3D builds on its
first query: add_triangles plus a one-ray cast). Agreement with a float64 brute force on --check rays
of each set: a hit agrees when the float64 test puts its triangle's hit within 1e-6 of the box's
diagonal of the triangle's boundary at that t (1e-4 relative) and no triangle is hit surely (the ray
passes more than that inside) closer; a miss agrees when no triangle is hit surely. Distances to the
boundary are taken across the ray (in the plane perpendicular to it): a ray that grazes a triangle
nearly edge-on passes within rounding of its edges even where its hit point lies far inside. On the aimed set, which reaches the surface at t = 1
at the latest, the share of all rays missed is printed too: rays that slipped through a vertex or an
edge. trimesh's ray_triangle runs on --slow rays only.

embreex and trimesh's embree path are single-threaded: their rows are the same on 1 and 2 threads.

Closest points (--points per mesh, 0 skips them): half from surface points moved along the triangle's
normal by up to 2% of the box's diagonal either way, half anywhere in the box grown by 20%, float64.
Arbor's Mesh.closest_point, Open3D's RaycastingScene.compute_closest_points (when installed) and
trimesh.proximity.closest_point (needs scipy; --slow-points points only: it is slow) in thousands of
points per second; agreement: the share of --check points whose distance is within 1e-6 of the box's
diagonal of the one Arbor's brute-force structure gives (every triangle tested; the pytest suite holds
that one to a float64 NumPy brute force).

Setup (a venv): pip install numpy trimesh rtree embreex open3d ./crates/arbor-py
(Open3D needs libusb: apt-get install libusb-1.0-0). Run:
    scripts/python-compare.py --meshes /work/shared/meshes --rays 1000000 --runs 3
"""

import argparse
import json
import os
import statistics
import sys
import time

# NumPy's OpenBLAS threads spin after each call and take cores from the queries being timed.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import arbor_rays as ar  # noqa: E402


def icosphere(levels):
    """A unit icosphere, subdivided `levels` times (vectorised: 20 * 4^levels triangles)."""
    t = (1 + 5**0.5) / 2
    v = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
                  [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    for _ in range(levels):
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(edges, axis=0, return_inverse=True)
        mids = v[uniq[:, 0]] + v[uniq[:, 1]]
        mids /= np.linalg.norm(mids, axis=1, keepdims=True)
        m = inv.reshape(3, -1).T + len(v)
        a, b, c = f.T
        ab, bc, ca = m.T
        f = np.concatenate([np.stack(x, 1) for x in ([a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca])])
        v = np.concatenate([v, mids])
    return v.astype(np.float32), f.astype(np.int64)


def ray_sets(v, f, n, seed):
    rng = np.random.default_rng(seed)
    lo, hi = v.min(0).astype(np.float64), v.max(0).astype(np.float64)
    diag = np.linalg.norm(hi - lo)
    # Primary: a square grid above the box, straight down -z.
    side = int(np.ceil(np.sqrt(n)))
    gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], side), np.linspace(lo[1], hi[1], side))
    o = np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, hi[2] + 0.1 * diag)], 1)[:n]
    primary = (o.astype(np.float32), np.tile(np.float32([0, 0, -1]), (n, 1)))
    # Diffuse: cosine directions around the normal of a random point's triangle.
    tri = rng.integers(0, len(f), n)
    a, b, c = (v[f[tri, k]].astype(np.float64) for k in range(3))
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    p = a * (1 - s)[:, None] + b * (s * (1 - r2))[:, None] + c * (s * r2)[:, None]
    nrm = np.cross(b - a, c - a)
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-30)
    u1, u2 = rng.random(n), rng.random(n)
    local = np.stack([np.sqrt(u1) * np.cos(2 * np.pi * u2), np.sqrt(u1) * np.sin(2 * np.pi * u2), np.sqrt(1 - u1)], 1)
    helper = np.where(np.abs(nrm[:, :1]) > 0.9, [[0, 1, 0]], [[1, 0, 0]])
    t1 = np.cross(nrm, helper)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(nrm, t1)
    d = local[:, :1] * t1 + local[:, 1:2] * t2 + local[:, 2:] * nrm
    diffuse = ((p + nrm * 1e-4 * diag).astype(np.float32), d.astype(np.float32))
    # Aimed: from random points around the mesh to its vertices and edge midpoints, t = 1 at them.
    half = n // 2
    targets = np.concatenate([
        v[rng.integers(0, len(v), half)].astype(np.float64),
        (lambda e: (v[e[:, 0]].astype(np.float64) + v[e[:, 1]]) / 2)(
            f[rng.integers(0, len(f), n - half)][:, [0, 1]]),
    ]).astype(np.float32)
    src = ((lo + hi) / 2 + rng.normal(size=(n, 3)) * diag).astype(np.float32)
    aimed = (src, (targets - src).astype(np.float32))
    return {"primary": primary, "diffuse": diffuse, "aimed": aimed}


CPU = []


def timed(fn, runs):
    """The median wall time of `runs` calls, and the last call's answer; the cores each call had
    (process CPU time over wall time) go to CPU."""
    times, cores, out = [], [], None
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        times.append(time.perf_counter() - t0)
        cores.append((time.process_time() - c0) / times[-1])
    CPU.append(statistics.median(cores))
    return statistics.median(times), out


def plane_t(v, f, o, d, tri):
    """The t at which each ray meets the plane of the triangle it reports (inf for -1), for tools that
    return only triangle indices."""
    t = np.full(len(o), np.inf)
    i = np.flatnonzero(tri >= 0)
    a, b, c = (v[f[tri[i], k]].astype(np.float64) for k in range(3))
    n = np.cross(b - a, c - a)
    dd = d[i].astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        t[i] = np.einsum("ij,ij->i", a - o[i], n) / np.einsum("ij,ij->i", dd, n)
    return t


class Reference:
    """A float64 brute force for the rays `o`, `d`: every triangle within tolerance of each ray, with
    its t and its margin (how far inside the triangle's boundary the ray passes, measured across the
    ray, negative outside: what a floating-point ray test can resolve, unlike the distance in the
    triangle's plane, which a grazing ray stretches by 1 / cos).
    Candidates come from trimesh's r-tree of the triangles' boxes, queried along 32 pieces of the ray
    inside the mesh's box. The tolerance is 1e-6 of the box's diagonal (float32 coordinates are good to
    about 6e-8 of it)."""

    def __init__(self, tm, o, d):
        v = tm.vertices.astype(np.float64)
        f = tm.faces
        lo, hi = v.min(0), v.max(0)
        self.tol = 1e-6 * np.linalg.norm(hi - lo)
        self.rows = []
        tree = tm.triangles_tree
        for oi, di in zip(o.astype(np.float64), d.astype(np.float64)):
            with np.errstate(divide="ignore", invalid="ignore"):
                ta, tb = (lo - oi) / di, (hi - oi) / di
            t0 = max(np.nanmax(np.minimum(ta, tb)), 0.0)
            t1 = np.nanmin(np.maximum(ta, tb))
            if not t1 >= t0:
                self.rows.append((np.zeros(0, np.int64), np.zeros(0), np.zeros(0)))
                continue
            ts = np.linspace(t0, t1, 33)
            cand = set()
            for a, b in zip(ts[:-1], ts[1:]):
                p, q = oi + di * a, oi + di * b
                box = np.concatenate([np.minimum(p, q) - self.tol, np.maximum(p, q) + self.tol])
                cand.update(tree.intersection(box))
            cand = np.fromiter(cand, np.int64, len(cand))
            A, B, C = v[f[cand, 0]], v[f[cand, 1]], v[f[cand, 2]]
            e1, e2 = B - A, C - A
            pv = np.cross(di, e2)
            det = np.einsum("ij,ij->i", e1, pv)
            with np.errstate(divide="ignore", invalid="ignore"):
                inv = 1 / det
                sv = oi - A
                u = np.einsum("ij,ij->i", sv, pv) * inv
                q = np.cross(sv, e1)
                w = (q @ di) * inv
                t = np.einsum("ij,ij->i", e2, q) * inv
                # Across the ray: twice the projected area over each projected edge's length is
                # the projected height, and a barycentric times its height is the distance to
                # the opposite edge.
                dn = di / np.linalg.norm(di)
                area2 = np.abs(np.cross(e1, e2) @ dn)

                def across(e):
                    return np.linalg.norm(e - np.outer(e @ dn, dn), axis=1)

                margin = np.minimum(np.minimum(u * area2 / across(e2), w * area2 / across(e1)),
                                    (1 - u - w) * area2 / across(C - B))
            keep = (margin > -self.tol) & (t > 0)
            self.rows.append((cand[keep], t[keep], margin[keep]))

    def agree(self, tri, t_hit):
        """Per ray: whether the answer (triangle, t; -1 for a miss) agrees (see the module doc)."""
        ok = np.zeros(len(self.rows), bool)
        for i, (cand, t, margin) in enumerate(self.rows):
            sure = margin > self.tol
            if tri[i] < 0:
                ok[i] = not np.any(sure)
                continue
            th = float(t_hit[i])
            tol = 1e-4 * (1 + abs(th))
            here = np.any((cand == tri[i]) & (np.abs(t - th) <= tol))
            ok[i] = bool(here and not np.any(sure & (t < th - tol)))
        return ok


def query_points(v, f, n, seed):
    """`n` float64 points: half near the surface (either side), half anywhere around the mesh."""
    rng = np.random.default_rng(seed)
    v = v.astype(np.float64)
    lo, hi = v.min(axis=0), v.max(axis=0)
    diag = np.linalg.norm(hi - lo)
    t = f[rng.integers(0, len(f), n // 2)]
    w = rng.dirichlet([1, 1, 1], len(t))
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    nrm = np.cross(b - a, c - a)
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
    near = np.einsum("ik,kij->ij", w, np.stack([a, b, c])) + nrm * rng.uniform(-0.02, 0.02, (len(t), 1)) * diag
    pad = 0.2 * (hi - lo)
    return np.concatenate([near, rng.uniform(lo - pad, hi + pad, (n - len(t), 3))]), diag


def closest_points(args, name, v, f, m, tm, threads, rs):
    """The closest-point section of one mesh: printed, and returned as rows."""
    points, diag = query_points(v, f, args.points, seed=3)
    n = len(points)
    check = np.random.default_rng(4).choice(n, min(args.check, n), replace=False)
    ref = ar.Mesh(v, f).build("brute").distance(points[check])
    results = {}

    def record(tool, th, secs, count, dist):
        agree = np.abs(dist - ref[: len(dist)]) <= 1e-6 * diag
        results[(tool, th)] = (count / secs / 1e3, float(agree.mean()), CPU[-1])

    for th in threads:
        secs, out = timed(lambda: m.closest_point(points, threads=th), args.runs)
        record("arbor closest_point", th, secs, n, out["distance"][check])
    if rs:
        import open3d as o3d

        for th in threads:
            def o3d_closest():
                return rs.compute_closest_points(o3d.core.Tensor(points.astype(np.float32)), nthreads=th)["points"].numpy()
            secs, out = timed(o3d_closest, args.runs)
            record("open3d compute_closest_points", th, secs, n, np.linalg.norm(out[check] - points[check], axis=1))
    try:
        import scipy  # noqa: F401  (trimesh.proximity needs it)

        import trimesh

        slow = check[: min(args.slow_points, len(check))]
        secs, (_, dist, _) = timed(lambda: trimesh.proximity.closest_point(tm, points[slow]), 1)
        for th in threads:
            record("trimesh proximity (subset)", th, secs, len(slow), dist)
    except ImportError:
        print("   trimesh.proximity.closest_point: skipped, scipy is absent", flush=True)
    print(f"-- closest points ({n} points, {len(check)} checked)", flush=True)
    rows = []
    for (tool, th), (kp, ag, cores) in results.items():
        print(f"   {tool:30s} threads {th}: {kp:10.1f} kpoints/s  cores {cores:.2f}  agreement {100 * ag:.2f}%", flush=True)
        rows.append({"mesh": name, "set": "closest points", "tool": tool, "threads": th, "kpoints": kp,
                     "agreement": ag, "cores": cores})
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--meshes", default=os.environ.get("ARBOR_MESHES", "../shared/meshes"))
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--check", type=int, default=1000, help="rays per set checked against the float64 brute force")
    ap.add_argument("--slow", type=int, default=2000, help="rays per set for trimesh's ray_triangle")
    ap.add_argument("--points", type=int, default=100_000, help="closest-point queries per mesh (0: none)")
    ap.add_argument("--slow-points", type=int, default=200, help="points for trimesh.proximity.closest_point")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--json", help="write every number here too")
    args = ap.parse_args()
    threads = [int(x) for x in args.threads.split(",")]

    import trimesh
    try:
        from embreex import rtcore_scene as rtcs
        from embreex.mesh_construction import TriangleMesh as EmbreeMesh
    except ImportError:
        rtcs = None
    try:
        import open3d as o3d
    except ImportError:
        o3d = None

    meshes = {}
    igea = ar.load_mesh(os.path.join(args.meshes, "igea.ply"))
    meshes["igea"] = (igea.vertices, igea.faces)
    meshes["icosphere"] = icosphere(8)
    rows = []
    print(f"arbor_rays {ar.__version__}, trimesh {trimesh.__version__}, "
          f"open3d {o3d.__version__ if o3d else 'absent'}, embreex {'present' if rtcs else 'absent'}; "
          f"{args.rays} rays per set, median of {args.runs}; load {os.getloadavg()[0]:.2f}", flush=True)
    for name, (v, f) in meshes.items():
        print(f"\n== {name}: {len(f)} triangles", flush=True)
        tm = trimesh.Trimesh(v.astype(np.float64), f, process=False)
        builds = {}
        t0 = time.perf_counter()
        m = ar.Mesh(v, f).build()
        builds["arbor"] = time.perf_counter() - t0
        if rtcs:
            t0 = time.perf_counter()
            scene = rtcs.EmbreeScene()
            EmbreeMesh(scene, v[f])
            scene.run(np.zeros((1, 3), np.float32), np.float32([[0, 0, 1]]))
            builds["embreex"] = time.perf_counter() - t0
            tm.ray = trimesh.ray.ray_pyembree.RayMeshIntersector(tm)
            t0 = time.perf_counter()
            tm.ray.intersects_first(np.zeros((1, 3)), [[0, 0, 1]])
            builds["trimesh+embreex"] = time.perf_counter() - t0
        if o3d:
            t0 = time.perf_counter()
            rs = o3d.t.geometry.RaycastingScene()
            rs.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f.astype(np.uint32)))
            rs.cast_rays(o3d.core.Tensor(np.float32([[0, 0, 0, 0, 0, 1]])))
            builds["open3d"] = time.perf_counter() - t0
        print("build seconds: " + ", ".join(f"{k} {s:.3f}" for k, s in builds.items()), flush=True)
        rows.append({"mesh": name, "triangles": len(f), "builds": builds})
        if args.points:
            rows += closest_points(args, name, v, f, m, tm, threads, o3d and rs)
        tri_tm = trimesh.ray.ray_triangle.RayMeshIntersector(tm)
        for set_name, (o, d) in ray_sets(v, f, args.rays, seed=1).items():
            n = len(o)
            k = min(args.check, n)
            sub = np.random.default_rng(2).choice(n, k, replace=False)
            results, misses = {}, {}
            ref = Reference(tm, o[sub], d[sub])

            def record(tool, th, secs, tri, t_hit):
                agree = ref.agree(tri[sub], t_hit[sub])
                results[(tool, th)] = (n / secs / 1e6, float(agree.mean()), CPU[-1])
                if set_name == "aimed":
                    # Every aimed ray reaches the surface at t = 1 at the latest: a miss slipped through
                    # a vertex or an edge (or touched it tangentially, which few can).
                    misses[(tool, th)] = float(np.mean(tri < 0))

            for th in threads:
                secs, out = timed(lambda: m.intersect(o, d, threads=th), args.runs)
                record("arbor", th, secs, out["triangle"], out["t"])
                secs, hit = timed(lambda: m.occluded(o, d, threads=th), args.runs)
                results[("arbor any-hit", th)] = (n / secs / 1e6, None, CPU[-1])
            if rtcs:
                def raw():
                    r = scene.run(o, d, output=1)
                    return r["primID"], r["tfar"]
                secs, (tri, t_hit) = timed(raw, args.runs)
                t_hit = np.where(tri >= 0, t_hit, np.inf).astype(np.float32)
                for th in threads:
                    record("embreex raw", th, secs, tri, t_hit)
                secs, tri = timed(lambda: tm.ray.intersects_first(o, d), args.runs)
                for th in threads:
                    record("trimesh+embreex first", th, secs, tri, plane_t(v, f, o, d, tri))
                secs, hit = timed(lambda: tm.ray.intersects_any(o, d), args.runs)
                for th in threads:
                    results[("trimesh+embreex any", th)] = (n / secs / 1e6, None, CPU[-1])
            for th in threads:
                m_tm = ar.RayMeshIntersector(tm, threads=th)
                m_tm._arbor, m_tm._key = m, hash(tm)
                secs, tri = timed(lambda: m_tm.intersects_first(o, d), args.runs)
                record("arbor trimesh adapter first", th, secs, tri, plane_t(v, f, o, d, tri))
                secs, hit = timed(lambda: m_tm.intersects_any(o, d), args.runs)
                results[("arbor trimesh adapter any", th)] = (n / secs / 1e6, None, CPU[-1])
            if o3d:
                for th in threads:
                    def cast():
                        r = rs.cast_rays(o3d.core.Tensor(np.concatenate([o, d], 1)), nthreads=th)
                        return r["primitive_ids"].numpy(), r["t_hit"].numpy()
                    secs, (pid, t_hit) = timed(cast, args.runs)
                    tri = np.where(pid == 4294967295, -1, pid.astype(np.int64))
                    record("open3d cast_rays", th, secs, tri, t_hit)
            # trimesh's pure-Python intersector, on a subset.
            slow = sub[: min(args.slow, k)]
            # In pieces of 25 rays: its candidate lists (every triangle whose box meets a ray's box)
            # take gigabytes for long rays through a large mesh.
            pieces = [slow[i:i + 25] for i in range(0, len(slow), 25)]
            t0 = time.perf_counter()
            first = np.concatenate([tri_tm.intersects_first(o[p], d[p]) for p in pieces])
            secs = time.perf_counter() - t0
            found = [tri_tm.intersects_location(o[p], d[p], multiple_hits=False) for p in pieces]
            locs = np.concatenate([x[0].reshape(-1, 3) for x in found])
            ray_idx = np.concatenate([x[1] + 25 * j for j, x in enumerate(found)]).astype(np.int64)
            dd = d[slow][ray_idx].astype(np.float64)
            tt = np.einsum("ij,ij->i", locs - o[slow][ray_idx], dd) / np.einsum("ij,ij->i", dd, dd)
            loc_t = np.full(len(slow), np.inf)
            np.minimum.at(loc_t, ray_idx, tt)
            agree = ref.agree(np.concatenate([first, np.full(k - len(slow), -2)]), np.concatenate([loc_t, np.zeros(k - len(slow))]))[: len(slow)]
            for th in threads:
                results[("trimesh ray_triangle", th)] = (len(slow) / secs / 1e6, float(agree.mean()), 1.0)
            print(f"-- {set_name}", flush=True)
            for (tool, th), (mr, ag, cores) in results.items():
                ag_s = "" if ag is None else f"  agreement {100 * ag:.2f}%"
                if (tool, th) in misses:
                    ag_s += f"  misses {100 * misses[(tool, th)]:.4f}%"
                print(f"   {tool:30s} threads {th}: {mr:8.3f} Mrays/s  cores {cores:.2f}{ag_s}", flush=True)
                rows.append({"mesh": name, "set": set_name, "tool": tool, "threads": th, "mrays": mr,
                             "agreement": ag, "cores": cores, "misses": misses.get((tool, th))})
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
