#!/usr/bin/env bash
# Nsight Compute's details of COUNT launches of the kernels whose names
# match REGEX, the first SKIP of them skipped (the sections and metrics
# ncu-summary.py reads: throughput, occupancy, the stall reasons, the
# pipes), into CSV. The card's clocks are left as they are.
#   scripts/gpu/ncu-details.sh REGEX SKIP COUNT CSV PROGRAM [ARGUMENT...]
set -u
regex=${1:?kernel name regex} skip=${2:?launches to skip} count=${3:?launches} csv=${4:?CSV file}
shift 4
exec ncu --clock-control none -k "regex:$regex" --launch-skip "$skip" --launch-count "$count" \
  --section SpeedOfLight --section Occupancy --section LaunchStats --section MemoryWorkloadAnalysis \
  --section WarpStateStats --section ComputeWorkloadAnalysis --section InstructionStats \
  --metrics 'regex:smsp__average_warps_issue_stalled_.*_per_issue_active\.ratio$,regex:sm__inst_executed_pipe_[a-z0-9_]*\.avg\.pct_of_peak_sustained_active$' \
  --csv --page details --log-file "$csv" "$@"
