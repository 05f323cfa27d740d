#!/usr/bin/env python3
"""Speed of `arbor view` (project issue 32), measured from outside, as the page sees it.

    scripts/view-bench.py --arbor target/release/arbor [--threads 2] [--rounds 5] [--size 480x360] [SCENE ...]

For each scene (default: the built-in Cornell box, and `../shared/meshes/igea.ply` in a lit scene that
this script writes to a temporary folder), it starts `arbor view`, then over HTTP:
- first frame: the time from a view request to its first image (the quarter-resolution preview, or the
  full frame when full passes are fast enough to skip it) and to
  its first full-resolution image (one sample), 480x360 (--size), Whitted, median of --rounds;
- orbiting: views turned by 2 degrees one after the other, each as soon as the last one's first
  full-resolution image has come, for 3 seconds: full-resolution frames per second;
- cancel: a 64-sample view at 960x720 is requested, then after 0.3 s a new view: the time from the new
  request until the old view's last image (its `X-Seq`) stops growing and the new view's first image
  arrives;
- the server's own cost per frame: the `X-Convert-Ms` header (averaging, tone mapping, 8 bits) and the
  time to fetch an image already made (request, copy, transfer over loopback).
Numbers are medians; the machine is shared, so quote them with the load average the script prints.
"""

import argparse
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def start(arbor, scene, threads):
    cmd = [arbor, "view", "--threads", str(threads)] + ([str(scene)] if scene else [])
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    m = re.search(r"(http://[^/]+)/\?token=(\w+)", line)
    if not m:
        proc.kill()
        sys.exit(f"arbor view did not start: {line}{proc.stderr.read()}")
    return proc, m.group(1), m.group(2)


class Client:
    def __init__(self, base, token):
        self.base, self.token = base, token

    def call(self, path, body=None, timeout=30):
        req = urllib.request.Request(self.base + path, data=None if body is None else json.dumps(body).encode(),
                                     headers={"X-Arbor-Token": self.token, "Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, dict(r.headers), r.read()

    def view(self, body):
        return json.loads(self.call("/api/view", body)[2])["view"]

    def image(self, after, view, want_samples=None, wait=20000):
        """The first image of `view` newer than `after` (with `want_samples` samples if given)."""
        while True:
            status, h, data = self.call(f"/api/image?after={after}&wait={wait}")
            if status == 204:
                continue
            after = int(h["X-Seq"] if "X-Seq" in h else h["x-seq"])
            hv = {k.lower(): v for k, v in h.items()}
            if int(hv["x-view"]) < view:
                continue
            if want_samples is None or int(hv["x-samples"]) >= want_samples:
                return after, hv, data


def turned(cam, target, degrees):
    """`cam`'s eye turned about the target around its up axis."""
    eye, up = cam["eye"], cam["up"]
    off = [e - t for e, t in zip(eye, target)]
    a = math.radians(degrees)
    k = up
    kn = math.sqrt(sum(x * x for x in k))
    k = [x / kn for x in k]
    dot = sum(o * x for o, x in zip(off, k))
    cross = [k[1] * off[2] - k[2] * off[1], k[2] * off[0] - k[0] * off[2], k[0] * off[1] - k[1] * off[0]]
    rot = [o * math.cos(a) + c * math.sin(a) + x * dot * (1 - math.cos(a)) for o, c, x in zip(off, cross, k)]
    new_eye = [t + r for t, r in zip(target, rot)]
    return new_eye, [t - e for t, e in zip(target, new_eye)], up


def measure(arbor, scene, threads, rounds, size):
    proc, base, token = start(arbor, scene, threads)
    try:
        c = Client(base, token)
        info = json.loads(c.call("/api/scene")[2])
        cam = info["cameras"][0]
        b = info["bounds"]
        target = [(lo + hi) / 2 for lo, hi in zip(b["min"], b["max"])]
        w, h = size
        base_view = {"camera": 0, "width": w, "height": h, "integrator": "whitted", "spp": 1}
        seq = 0
        first, full = [], []
        for r in range(rounds):
            eye, gaze, up = turned(cam, target, 5 * (r + 1))
            t0 = time.perf_counter()
            v = c.view({**base_view, "eye": eye, "gaze": gaze, "up": up})
            seq, hv, _ = c.image(seq, v)
            first.append((time.perf_counter() - t0) * 1e3)
            if int(hv["x-samples"]) < 1:  # a preview came first (no preview while full passes are fast)
                seq, hv, _ = c.image(seq, v, want_samples=1)
            full.append((time.perf_counter() - t0) * 1e3)
        # Orbiting.
        frames, convert, download, angle = 0, [], [], 0.0
        t_end = time.perf_counter() + 3.0
        t0 = time.perf_counter()
        while time.perf_counter() < t_end:
            angle += 2.0
            eye, gaze, up = turned(cam, target, angle)
            v = c.view({**base_view, "eye": eye, "gaze": gaze, "up": up})
            seq, hv, _ = c.image(seq, v, want_samples=1)
            # The same image again: what the server and the transfer cost, without waiting for a render.
            t_dl = time.perf_counter()
            c.call(f"/api/image?after={seq - 1}&wait=0")
            download.append((time.perf_counter() - t_dl) * 1e3)
            convert.append(float(hv["x-convert-ms"]))
            frames += 1
        fps = frames / (time.perf_counter() - t0)
        # Cancel.
        cancels = []
        for r in range(rounds):
            heavy = {**base_view, "width": 2 * w, "height": 2 * h, "spp": 64}
            v_old = c.view(heavy)
            time.sleep(0.3)
            eye, gaze, up = turned(cam, target, 30 + r)
            t0 = time.perf_counter()
            v = c.view({**base_view, "eye": eye, "gaze": gaze, "up": up})
            seq, hv, _ = c.image(seq, v)
            cancels.append((time.perf_counter() - t0) * 1e3)
        return {
            "scene": str(scene or "(built-in example)"), "size": f"{w}x{h}", "threads": threads,
            "first_image_ms": statistics.median(first), "first_full_ms": statistics.median(full),
            "orbit_fps": fps, "orbit_frames": frames,
            "new_view_while_heavy_ms": statistics.median(cancels),
            "convert_ms": statistics.median(convert), "download_ms": statistics.median(download),
        }
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def igea_scene(folder, meshes):
    """A lit scene around igea.ply: a point light, an area light, grey diffuse, framed from the front."""
    mesh = Path(meshes) / "igea.ply"
    if not mesh.is_file():
        return None
    scene = f"""<Scene>
  <MaxRecursionDepth>2</MaxRecursionDepth>
  <Cameras><Camera id="1" type="lookAt"><Position>0 0.1 2.6</Position><GazePoint>0 0 0</GazePoint><Up>0 1 0</Up>
    <FovY>40</FovY><NearDistance>1</NearDistance><ImageResolution>640 480</ImageResolution><ImageName>igea.png</ImageName></Camera></Cameras>
  <Lights><AmbientLight>25 25 25</AmbientLight>
    <PointLight id="1"><Position>2 3 4</Position><Intensity>4000 4000 4000</Intensity></PointLight></Lights>
  <Materials><Material id="1"><AmbientReflectance>1 1 1</AmbientReflectance><DiffuseReflectance>0.8 0.75 0.7</DiffuseReflectance>
    <SpecularReflectance>0.2 0.2 0.2</SpecularReflectance><PhongExponent>30</PhongExponent></Material></Materials>
  <Objects><Mesh id="1"><Material>1</Material><Faces plyFile="{mesh}"/></Mesh></Objects>
</Scene>
"""
    path = Path(folder) / "igea_lit.xml"
    path.write_text(scene)
    return path


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--arbor", default=str(ROOT / "target/release/arbor"))
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--size", default="480x360", help="view size WxH (the camera's near plane is stretched to it)")
    p.add_argument("--meshes", default=os.environ.get("ARBOR_MESHES", str(ROOT.parent / "shared/meshes")))
    p.add_argument("scenes", nargs="*")
    args = p.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        igea = igea_scene(tmp, args.meshes)
        scenes = [Path(s) for s in args.scenes] if args.scenes else [None] + ([igea] if igea else [])
        for scene in scenes:
            size = tuple(int(v) for v in args.size.split("x"))
            r = measure(args.arbor, scene, args.threads, args.rounds, size)
            print(json.dumps(r), flush=True)


if __name__ == "__main__":
    main()
