#!/usr/bin/env bash
# Nsight Compute's profile of one RenderKernel launch of `BENCH --only
# render` (the sections and metrics ncu-summary.py reads), the launches
# before it skipped, into CSV: the one profile gpu-check.sh's profile part
# and variants-check.sh's render section take. The card's clocks are left
# as they are.
#   scripts/gpu/ncu-render.sh SKIP CSV BENCH
set -u
skip=${1:?launches to skip} csv=${2:?CSV file} bench=${3:?octoray_bench_cuda}
exec ncu --clock-control none -k regex:RenderKernel --launch-skip "$skip" --launch-count 1 \
  --section SpeedOfLight --section Occupancy --section LaunchStats --section MemoryWorkloadAnalysis \
  --section WarpStateStats --section ComputeWorkloadAnalysis --section InstructionStats \
  --metrics 'regex:smsp__average_warps_issue_stalled_.*_per_issue_active\.ratio$,regex:sm__inst_executed_pipe_[a-z0-9_]*\.avg\.pct_of_peak_sustained_active$' \
  --csv --page details --log-file "$csv" "$bench" --only render
