#!/usr/bin/env bash
# Arbor and its peers (Embree 4, obvhs) side by side on identical rays, in one run.
#
# Usage: scripts/peer-compare.sh [-r ROUNDS] [-t "1 2"] [-a KINDS] MESH...
#   PEERBENCH=/tmp/peerbench  a built copy of ../shared/peerbench (cp -r, cargo build --release,
#                             ./get-embree4.sh); ARBOR=target/release/arbor; OUT=/tmp/peer-compare
# For each mesh: peerbench dumps its rays and Embree 4's hits once (OUT/rays-NAME), then every round
# runs peerbench (embree4,obvhs) and `arbor bench MESH --ray-dir DIR` one after the other at each thread
# count, so that machine load drifts hit both alike. Prints every raw line to OUT/raw.txt and a
# Markdown table of medians over rounds, with Arbor's ratios to each peer.
set -euo pipefail
rounds=3 threads="1 2" kinds="bvh-sah" peers="embree4,obvhs"
while getopts "r:t:a:p:" o; do
  case $o in
    r) rounds=$OPTARG ;; t) threads=$OPTARG ;; a) kinds=$OPTARG ;; p) peers=$OPTARG ;;
    *) echo "usage: $0 [-r ROUNDS] [-t THREADS] [-a KINDS] [-p PEERS] MESH..." >&2; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -gt 0 ] || { echo "usage: $0 [-r ROUNDS] [-t THREADS] [-a KINDS] [-p PEERS] MESH..." >&2; exit 2; }
here="$(cd "$(dirname "$0")/.." && pwd)"
pb="${PEERBENCH:-/tmp/peerbench}/target/release/peerbench"
arbor="${ARBOR:-$here/target/release/arbor}"
out="${OUT:-/tmp/peer-compare}"
[ -x "$pb" ] || { echo "no peerbench at $pb (see docs/performance.md)" >&2; exit 2; }
[ -x "$arbor" ] || { echo "no arbor at $arbor: cargo build --release -p arbor-cli" >&2; exit 2; }
mkdir -p "$out"
raw="$out/raw.txt"
: > "$raw"
for mesh in "$@"; do
  name="$(basename "${mesh%.*}")"
  rays="$out/rays-$name"
  if [ ! -f "$rays/diffuse.hits" ]; then
    echo "# dumping rays of $mesh" >&2
    "$pb" --peers embree4 --threads 1 --build-runs 1 --min-runs 1 --min-time 0 --dump-rays "$rays" "$mesh" > /dev/null
  fi
  for r in $(seq "$rounds"); do
    for t in $threads; do
      echo "# $name round $r threads $t" >&2
      "$pb" --peers "$peers" --threads "$t" "$mesh" | grep '^peer=' | sed "s|\$| round=$r mesh_name=$name|" >> "$raw"
      "$arbor" bench "$mesh" --ray-dir "$rays" --threads "$t" --accel "$kinds" | grep '^peer=' \
        | sed "s|\$| round=$r mesh_name=$name|" >> "$raw"
    done
  done
done
python3 - "$raw" <<'PY'
import sys, statistics
from collections import defaultdict
rows = defaultdict(lambda: defaultdict(list))
order = []
for line in open(sys.argv[1]):
    kv = dict(f.split("=", 1) for f in line.split() if "=" in f)
    key = (kv["mesh_name"], kv["threads"], kv["set"])
    if key not in order:
        order.append(key)
    rows[key][kv["peer"]].append((float(kv["build_ms"]), float(kv["mrays"]), float(kv.get("mismatch", "nan"))))
med = lambda xs: statistics.median(xs)
peers = []
for k in order:
    for p in rows[k]:
        if p not in peers:
            peers.append(p)
arbor = [p for p in peers if p.startswith("arbor-")]
others = [p for p in peers if not p.startswith("arbor-")]
head = ["mesh", "threads", "set"] + [f"{p} build ms / Mrays/s" for p in peers]
head += [f"{a} / {o} (trace, build)" for a in arbor for o in others] + [f"{a} mismatch" for a in arbor]
print("| " + " | ".join(head) + " |")
print("|" + "---|" * len(head))
for k in order:
    r = rows[k]
    m = {p: (med([x[0] for x in r[p]]), med([x[1] for x in r[p]]), max(x[2] for x in r[p])) for p in r}
    cells = list(k)
    cells += [f"{m[p][0]:.1f} / {m[p][1]:.2f}" if p in m else "-" for p in peers]
    for a in arbor:
        for o in others:
            if a in m and o in m:
                cells.append(f"{m[a][1] / m[o][1]:.2f}x, {m[a][0] / m[o][0]:.2f}x")
            else:
                cells.append("-")
    cells += [f"{m[a][2]:.6f}" if a in m else "-" for a in arbor]
    print("| " + " | ".join(cells) + " |")
print(f"\n(medians over rounds; raw lines in {sys.argv[1]})")
PY
