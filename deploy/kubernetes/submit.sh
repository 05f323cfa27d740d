#!/usr/bin/env bash
# Runs the Kubernetes recipe: the Indexed Job of tiles, a wait for its completion, then the merge Job.
#
#   deploy/kubernetes/submit.sh [TIMEOUT]       (default 1h; kubectl's current context and namespace)
#
# Assumes the PersistentVolumeClaim `arbor-work` (ReadWriteMany) holds the scene under /work/scenes.
set -euo pipefail
if ! command -v kubectl >/dev/null 2>&1; then
    echo "$0: kubectl not found on PATH; nothing was submitted" >&2
    exit 127
fi
here="$(cd "$(dirname "$0")" && pwd)"
timeout="${1:-1h}"
kubectl delete job arbor-tiles arbor-merge --ignore-not-found
kubectl apply -f "$here/render-job.yaml"
kubectl wait --for=condition=complete job/arbor-tiles --timeout="$timeout"
kubectl apply -f "$here/merge-job.yaml"
kubectl wait --for=condition=complete job/arbor-merge --timeout="$timeout"
kubectl logs job/arbor-merge
