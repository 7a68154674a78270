#!/usr/bin/env bash
# ctest `k8s_job_files`: every Kubernetes file under jobs/k8s passes the offline schema
# and sharding check of tools/k8s/check-jobs.mjs (the Kubernetes 1.33 OpenAPI schema of
# batch/v1 Job, unknown fields rejected as `kubectl --validate=strict` does, and
# HANDLABEL_SHARD_COUNT = spec.completions), and the check rejects broken copies of each
# (--self-test), so that it can fail.
# Skips (exit 77) only when node or tools/k8s/node_modules are missing
# (`bash scripts/install-deps` installs both; CI runs it).
# Usage: k8s_job_files_test.sh SOURCE_DIR
set -euo pipefail
src=$(realpath "$1")
if ! command -v node > /dev/null; then
  echo "k8s_job_files: SKIP: node is not installed (run: bash scripts/install-deps)"
  exit 77
fi
if [ ! -d "$src/tools/k8s/node_modules/kubernetes-models" ]; then
  echo "k8s_job_files: SKIP: tools/k8s/node_modules missing (run: bash scripts/npm-ci-pinned tools/k8s)"
  exit 77
fi
mapfile -t files < <(find "$src/jobs/k8s" -name '*.yaml' -o -name '*.yml' | sort)
if [ ${#files[@]} -eq 0 ]; then
  echo "k8s_job_files: no YAML file under $src/jobs/k8s"
  exit 1
fi
node "$src/tools/k8s/check-jobs.mjs" --self-test "${files[@]}"
