#!/usr/bin/env bash
# Renders SCENE on a Slurm cluster as TILES tiles (a job array) and merges them (a job that depends on the
# whole array succeeding) into OUTPUT. Prints the two job ids as `ARRAY_JOB=<id>` and `MERGE_JOB=<id>`.
#
#   deploy/slurm/submit.sh SCENE TILES OUTPUT [ARBOR RENDER FLAGS...]
#
# Environment: ARBOR (the arbor binary, default: `arbor` on PATH), PARTS (folder for the partial EXRs,
# default: OUTPUT's folder/parts), SBATCH_FLAGS (extra sbatch flags for both jobs, e.g. "-p gpu -t 1:00:00").
# Paths are made absolute, so the jobs may start in any folder of a shared file system. Nothing is
# created (no folder, no job) unless every command it needs is there and the arguments make sense.
set -euo pipefail
if [ $# -lt 3 ]; then
    echo "usage: $0 SCENE TILES OUTPUT [ARBOR RENDER FLAGS...]" >&2
    exit 2
fi
for tool in sbatch realpath dirname mkdir; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        hint=""
        if [ "$tool" = sbatch ]; then
            hint=" (Slurm's job submission; run this on a Slurm login node, or see docs/farm.md for tiles without Slurm)"
        fi
        echo "$0: $tool not found on PATH$hint; nothing was created" >&2
        exit 127
    fi
done
here="$(cd "$(dirname "$0")" && pwd)"
SCENE="$(realpath "$1")"
TILES="$2"
OUTPUT="$(realpath -m "$3")"
shift 3
ARBOR_ARGS="$*"
case "$TILES" in
'' | *[!0-9]* | 0) echo "$0: TILES must be a whole number >= 1, got '$TILES'" >&2; exit 2 ;;
esac
ARBOR="${ARBOR:-arbor}"
if [[ "$ARBOR" == */* ]]; then ARBOR="$(realpath "$ARBOR")"; fi
PARTS="$(realpath -m "${PARTS:-$(dirname "$OUTPUT")/parts}")"
mkdir -p "$PARTS" "$(dirname "$OUTPUT")"
export ARBOR SCENE TILES PARTS OUTPUT ARBOR_ARGS
logs="$(dirname "$OUTPUT")"
# shellcheck disable=SC2086 # SBATCH_FLAGS is a list of flags
array=$(sbatch --parsable --export=ALL --chdir="$logs" --array="0-$((TILES - 1))" ${SBATCH_FLAGS:-} \
    "$here/render-array.sbatch")
array="${array%%;*}"
# shellcheck disable=SC2086
merge=$(sbatch --parsable --export=ALL --chdir="$logs" --dependency="afterok:$array" --kill-on-invalid-dep=yes \
    ${SBATCH_FLAGS:-} "$here/merge.sbatch")
merge="${merge%%;*}"
echo "ARRAY_JOB=$array"
echo "MERGE_JOB=$merge"
