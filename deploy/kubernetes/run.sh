#!/bin/bash
# Renders a scene on Kubernetes: the shard Job, then, once all its indexes are complete, the
# merge Job. Usage: deploy/kubernetes/run.sh SCENE.toml
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
scene=${1:?usage: run.sh SCENE.toml}
kubectl create configmap glint-scene --from-file=scene.toml="$scene" \
    --dry-run=client -o yaml | kubectl apply -f -
kubectl apply -f "$here/storage.yaml"
kubectl apply -f "$here/shards-job.yaml"
kubectl wait --for=condition=complete --timeout=24h job/glint-shards
kubectl apply -f "$here/merge-job.yaml"
kubectl wait --for=condition=complete --timeout=1h job/glint-merge
kubectl logs job/glint-merge
