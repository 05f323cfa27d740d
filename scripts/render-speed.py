#!/usr/bin/env python3
"""Render-level speed of two Arbor binaries on the same scenes: Mrays/s and the traversal share.

Each round renders every scene with each binary in turn (A, B, A, B...), so that drifts of a shared
machine's load hit both alike, and the table gives the median over rounds of the render time, the rays,
Mrays/s and, when the binary reports it, the share of thread time in the structure's queries (all read
from `arbor render --stats-json`). Images go to a temporary folder; a scene may name one camera
(`scene.xml:ID`) and extra `arbor render` flags are passed with `--flags`.

    scripts/render-speed.py --before /tmp/arbor-old --after target/release/arbor --rounds 3 --threads 1 \\
        ../shared/scenes/ceng795-2024-hw1/hw1/inputs/cornellbox_recursive.xml ...
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile


def run(binary, scene, threads, flags, out):
    """(render ms, M rays, Mrays/s, traversal %) of one render, from `arbor render --stats-json`, summed
    over the scene's images (traversal weighted by render time; None when the binary does not report it)."""
    path, _, camera = scene.partition(":")
    stats = os.path.join(out, "stats.json")
    cmd = [binary, "render", path, "--threads", str(threads), "-o", out, "--no-warnings", "-q",
           "--stats-json", stats] + flags
    if camera:
        cmd += ["--camera", camera]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{done.stderr.strip()}")
    with open(stats) as f:
        images = json.load(f)["images"]
    ms = sum(i["render_ms"] for i in images)
    rays = sum(i["rays"] for i in images)
    shares = [i.get("traversal_share") for i in images]
    share = None if None in shares else 100 * sum(s * i["render_ms"] for s, i in zip(shares, images)) / ms
    return ms, rays / 1e6, rays / 1e3 / ms, share


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="+", metavar="SCENE[:CAMERA]")
    parser.add_argument("--before", required=True, help="the binary before the change")
    parser.add_argument("--after", required=True, help="the binary after it")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--flags", default="", help="extra arbor render flags, one string")
    args = parser.parse_args()
    flags = args.flags.split()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for scene in args.scenes:
            results = {"before": [], "after": []}
            for r in range(args.rounds):
                for name in ("before", "after"):
                    binary = getattr(args, name)
                    results[name].append(run(binary, scene, args.threads, flags, tmp))
                    print(f"# {os.path.basename(scene)} round {r + 1} {name}: {results[name][-1]} "
                          f"load {os.getloadavg()[0]:.1f}", file=sys.stderr, flush=True)
            med = {k: [statistics.median(x[i] for x in v) if v[0][i] is not None else None for i in range(4)]
                   for k, v in results.items()}
            rows.append((os.path.basename(scene), med))
    print(f"| scene | rays (M) | before Mrays/s | after Mrays/s | after / before | before traversal | "
          f"after traversal |\n|---|---:|---:|---:|---:|---:|---:|")
    share = lambda s: "-" if s is None else f"{s:.0f}%"
    for scene, m in rows:
        b, a = m["before"], m["after"]
        print(f"| {scene} | {a[1]:.2f} | {b[2]:.2f} | {a[2]:.2f} | {a[2] / b[2]:.2f} | {share(b[3])} | "
              f"{share(a[3])} |")
    print(f"\n({args.rounds} alternating rounds, medians, {args.threads} thread(s), "
          f"load average at the end {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
