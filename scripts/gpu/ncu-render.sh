#!/usr/bin/env bash
# Nsight Compute's profile of one RenderKernel launch of `BENCH --only
# render` (ncu-details.sh), the launches before it skipped: the one profile
# gpu-check.sh's profile part and variants-check.sh's render section take.
#   scripts/gpu/ncu-render.sh SKIP CSV BENCH
set -u
skip=${1:?launches to skip} csv=${2:?CSV file} bench=${3:?octoray_bench_cuda}
exec "$(dirname "$0")/ncu-details.sh" RenderKernel "$skip" 1 "$csv" "$bench" --only render
