#!/usr/bin/env python3
"""Render seconds and peak memory of scenes, as a Markdown table for docs/reference-results.md.

Usage: scripts/scene-costs.py ARBOR_BINARY SCENE_OR_FOLDER... [--threads N] [-- EXTRA RENDER ARGS]

Each scene is rendered once by `arbor render` into a scratch folder. The table gives the image size
and samples, the load-and-build and render times from Arbor's summary line, the wall time of the whole
process, and its peak resident memory (the child's ru_maxrss, read with os.wait4: no /usr/bin/time
needed). A scene that does not render (a missing mesh or image) is listed below the table with the
first line of its error.
"""

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def scenes(args):
    for a in args:
        p = Path(a)
        if p.is_dir():
            yield from sorted(q for q in p.rglob("*") if q.suffix in (".xml", ".json"))
        else:
            yield p


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        i = argv.index("--")
        argv, extra = argv[:i], argv[i + 1:]
    threads = 2
    if "--threads" in argv:
        i = argv.index("--threads")
        threads = int(argv[i + 1])
        del argv[i:i + 2]
    if len(argv) < 2:
        sys.exit(__doc__)
    binary, paths = argv[0], argv[1:]
    rows, failed = [], []
    for scene in scenes(paths):
        code, stdout, stderr, wall, peak = measure(binary, scene, threads, extra)
        if code != 0:
            errors = [l for l in stderr.splitlines() if l.startswith("error")] or stderr.splitlines() or ["?"]
            failed.append((scene, errors[0]))
            continue
        for line in stdout.splitlines():
            m = re.search(r"(\d+)x(\d+)\s+(\d+) spp\s+parse ([\d.]+) ms\s+build ([\d.]+) ms.*render ([\d.]+) ms", line)
            if m:
                w, h, spp, parse, build, render = m.groups()
                load = (float(parse) + float(build)) / 1e3
                rows.append((scene.name, f"{w}x{h}", spp, f"{load:.2f}", f"{float(render) / 1e3:.2f}",
                             f"{wall:.2f}", f"{peak / 1024:.0f}"))
    print(f"| scene | size | spp | parse + build s | render s | wall s | peak MiB |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    if failed:
        print()
    for scene, why in failed:
        print(f"- not rendered: {scene.name}: {why}")


def measure(binary, scene, threads, extra):
    """Runs one render; returns (exit code, stdout, stderr, wall seconds, peak RSS in KiB)."""
    with tempfile.TemporaryDirectory() as out:
        cmd = [binary, "render", str(scene), "-o", out, "--threads", str(threads), *extra]
        start = time.monotonic()
        with tempfile.TemporaryFile("w+") as o, tempfile.TemporaryFile("w+") as e:
            proc = subprocess.Popen(cmd, stdout=o, stderr=e, text=True)
            _, status, usage = os.wait4(proc.pid, 0)
            wall = time.monotonic() - start
            proc.returncode = os.waitstatus_to_exitcode(status)
            o.seek(0)
            e.seek(0)
            return proc.returncode, o.read(), e.read(), wall, usage.ru_maxrss


if __name__ == "__main__":
    main()
