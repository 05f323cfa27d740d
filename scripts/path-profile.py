#!/usr/bin/env python3
"""Counts where a path-traced render spends its instructions, per camera sample (issue 34's per-scene
profile in docs/performance.md): the render loop, the camera, bounce and shadow rays' traversal, and the
shading and sampling that is the rest. Runs `valgrind --tool=callgrind` on one `arbor render` and reads
`callgrind_annotate`'s exclusive and inclusive listings.

    scripts/path-profile.py [--arbor BIN] [--spp 16] [--crop 192,192,320,320] [--keep DIR] NAME SCENE CAMERA [ARGS...]

ARGS go to `arbor render` (for example `--path-options mis`). Prints one Markdown row:

    | NAME | total | camera rays | bounce rays | shadow rays | traversal | shading and sampling | of it: padded dimensions |

How instructions are attributed (inlining moves code between functions, so the rule is by where the code
was written, which inlining keeps): traversal is every instruction of `arbor-accel`, of the scene's
geometry queries (`scene/geometry.rs`) and of the ray log's query wrappers (`integrator/ray_log.rs`),
and whatever is inlined into their functions (glam, std, SIMD intrinsics); camera rays are the inclusive cost of
`RayLog::intersect_many` (the render loop's batched camera rays), shadow rays that of
`RayLog::occluded_many` (the wavefront's batches; in a binary from before it, the ray log's lines inlined
into the light sample, `direct`), bounce rays the rest of the traversal. Only the render loop is counted
(`--toggle-collect` on `arbor::render::trace`'s closures): the structure's build and the image's output
are outside it. Under valgrind the AVX2 kernels run (it has no AVX-512): instruction counts are AVX2's.
Needs valgrind; takes seconds to minutes (a Cornell box's 262,144 samples: about 10 s).
"""
import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

LINE = re.compile(r"^\s*([\d,]+) \([ \d.]+%\)\s+(\S.*?):(.+?)(?: \[.*\])?$")


def entries(out_file, inclusive):
    """(count, file, function) of every entry of callgrind_annotate's listing."""
    args = ["callgrind_annotate", "--threshold=100", "--auto=no", f"--inclusive={'yes' if inclusive else 'no'}", out_file]
    text = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    rows = []
    for line in text.splitlines():
        m = LINE.match(line)
        if m and "PROGRAM TOTALS" not in line:
            rows.append((int(m.group(1).replace(",", "")), m.group(2), m.group(3)))
    return rows


def one(rows, test, what):
    """The count of the single entry `test` accepts; exits naming `what` when there is none."""
    found = [c for c, f, fn in rows if test(f, fn)]
    if not found:
        sys.exit(f"path-profile: no {what} in the callgrind listing (renamed or inlined?)")
    return max(found)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--arbor", default="target/release/arbor")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--crop", default="192,192,320,320", help="x0,y0,x1,y1 of the rendered window")
    ap.add_argument("--keep", help="folder for the callgrind output (default: a temporary one)")
    ap.add_argument("name")
    ap.add_argument("scene")
    ap.add_argument("camera")
    ap.add_argument("render_args", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    x0, y0, x1, y1 = (int(v) for v in a.crop.split(","))
    samples = (x1 - x0) * (y1 - y0) * a.spp
    folder = Path(a.keep or tempfile.mkdtemp(prefix="path-profile-"))
    folder.mkdir(parents=True, exist_ok=True)
    out = str(folder / f"callgrind.{a.name}")
    # Only the render loop is counted: the structure's build and the image's output are outside it.
    cmd = ["valgrind", "--tool=callgrind", "--toggle-collect=arbor::render::trace::*", f"--callgrind-out-file={out}", a.arbor, "render", a.scene,
           "--camera", a.camera, "--spp", str(a.spp), "--threads", "1", "--crop", a.crop, "-q",
           "-o", str(folder / f"{a.name}.png"), *a.render_args]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"path-profile: the render failed ({run.returncode}):\n{run.stderr[-2000:]}")
    excl, incl = entries(out, False), entries(out, True)
    # Code written in the query files, or inlined (glam, std, intrinsics) into a query function.
    query_fn = ("arbor_accel::", "<arbor_accel::", "arbor::scene::geometry::", "<arbor::scene::geometry::",
                "arbor::integrator::ray_log::")
    in_traversal = lambda f, fn: ("arbor-accel/" in f or f.endswith("scene/geometry.rs")
                                  or f.endswith("integrator/ray_log.rs") or fn.startswith(query_fn)
                                  # SIMD intrinsics in a generic function (a leaf's triangle test inlined
                                  # into an iterator's `try_fold`): the renderer's own code is in `arbor::`.
                                  or ("core_arch" in f and not fn.startswith(("arbor::", "<arbor::"))))
    loop = sum(c for c, f, fn in excl)
    traversal = sum(c for c, f, fn in excl if in_traversal(f, fn))
    camera = one(incl, lambda f, fn: fn == "arbor::integrator::ray_log::RayLog::intersect_many", "camera rays")
    # The wavefront's shadow rays go as one batch per step; a binary from before it traced each one from
    # the light sample (`direct`), where the ray log's query was inlined.
    batched = [c for c, f, fn in incl if fn == "arbor::integrator::ray_log::RayLog::occluded_many"]
    shadow = max(batched) if batched else one(
        incl, lambda f, fn: f.endswith("integrator/ray_log.rs") and fn.endswith("PathTracer>::direct"),
        "shadow rays (the ray log's batch, or its query inlined into the light sample)")
    padded = sum(c for c, f, fn in incl if fn == "arbor::sampler::Padded::next_2d" and f.endswith(("sampler.rs", "sampler/mod.rs")))
    per = lambda n: f"{round(n / samples):,}"
    share = lambda n: f"{per(n)} ({100 * n / loop:.0f}%)"
    print(f"| {a.name} | {per(loop)} | {per(camera)} | {per(traversal - camera - shadow)} | {per(shadow)} "
          f"| {share(traversal)} | {share(loop - traversal)} | {per(padded)} |")


if __name__ == "__main__":
    main()
