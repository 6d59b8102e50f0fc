#!/usr/bin/env bash
# One engine-only device call over source variants of the build (no VTK):
# the variants built side by side and their build benchmarks run in turn
# (source-variants.sh, SECTION=build, with the engine tests in "main"),
# optionally each one's render section, compute-sanitizer over main's CUDA
# build, update and stability tests, and ncu's kernel times of a 10 M and a
# 100 M-point build by step (ncu-kernel-times.py --steps) for the variants
# in NCU. Files go to OUTDIR, packed into ARCHIVE (a device call returns a
# limited number of files); the closing lines print last.
#
#   V="main before" [NCU="main before"] [ROUNDS=2] [RENDER=1] \
#     scripts/gpu/variants-check.sh OUTDIR [ARCHIVE]
#
# The variant files travel in .gpu-vtk/variants (source-variants.sh says how
# they are made), GoogleTest in .gpu-vtk/googletest.
set -u
cd "$(dirname "$0")/../.." || exit 1
D=$(realpath -m "${1:?name the output folder}")
archive=${2:-}
mkdir -p "$D"
V=${V:-"main before"}
t0=$(date +%s)
elapsed() { echo "$1 done $(( $(date +%s) - t0 )) s" >> "$D/times.txt"; }

SOURCE_VARIANTS="$V" SECTION=build ROUNDS=${ROUNDS:-2} TESTS=1 timeout 420 \
  scripts/gpu/source-variants.sh "$D/variants" > "$D/variants.txt" 2>&1
elapsed variants
if [ "${RENDER:-0}" = 1 ]; then
  for v in $V; do "/tmp/src-$v/build/bin/octoray_bench_cuda" --only render > "$D/render-$v.log" 2>&1; done
  elapsed render
fi

# LOG, tool, filter, extra arguments: one line of sanitize.txt.
tests=/tmp/src-main/build/bin/octoray_engine_tests
sanitize() {
  local log=$1 tool=$2 filter=$3; shift 3
  timeout 150 compute-sanitizer --tool "$tool" "$@" --error-exitcode 1 "$tests" --gtest_filter="$filter" \
    > "$D/$log.log" 2>&1
  echo "$log rc $? : $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY' "$D/$log.log" | tail -1)" \
    "$(grep -E '^\[  (PASSED|FAILED)' "$D/$log.log" | head -2 | tr '\n' ' ')" >> "$D/sanitize.txt"
}
sanitize memcheck memcheck '*OctreeBuild*CUDA*:*OctreeUpdate*CUDA*:*Stability*CUDA*'
# The launch-refusal tests make the runtime refuse launches on purpose.
sanitize memcheck-refused memcheck 'CudaFaultsLaunch*' --report-api-errors no
for tool in racecheck initcheck synccheck; do sanitize "$tool" "$tool" '*OctreeBuild*CUDA*'; done
elapsed sanitizers

for v in ${NCU:-main before}; do
  for n in 1e7 1e8; do
    timeout 120 ncu --clock-control none --metrics gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum \
      --csv --page raw --log-file "$D/pb-$v-$n.csv" "/tmp/src-$v/build/bin/octoray_bench_cuda" --profile-build $n \
      > /dev/null 2>&1
    python3 scripts/gpu/ncu-kernel-times.py "$D/pb-$v-$n.csv" 2 --steps > "$D/steps-$v-$n.txt" 2>&1
    python3 scripts/gpu/ncu-kernel-times.py "$D/pb-$v-$n.csv" 2 > "$D/kernels-$v-$n.txt" 2>&1
  done
done
elapsed ncu
rm -f "$D"/*.csv
[ -n "$archive" ] && tar czf "$archive" -C "$D" .

cat "$D/variants.txt"
grep -H "^render depth" "$D"/render-*.log 2>/dev/null
cat "$D/sanitize.txt"
for f in "$D"/steps-*.txt; do echo "== $f"; cat "$f"; done
cat "$D/times.txt"
