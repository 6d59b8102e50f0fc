#!/usr/bin/env bash
# One engine-only device call over source variants (no VTK): the variants
# built side by side and one benchmark section of each run in turn
# (source-variants.sh, with the engine tests in the variants TESTS names,
# "main" by default), then
# compute-sanitizer over main's CUDA tests of that section and Nsight
# Compute on the variants in NCU. SECTION=build (the default): the build
# benchmark (RENDER=1 adds each one's render section), sanitizers over the
# build, update and stability tests, ncu's kernel times of a 10 M and a
# 100 M-point build by step (ncu-kernel-times.py --steps). SECTION=render:
# the render benchmark, sanitizers over the render and scene tests, and
# ncu's profile of the depth-16 primary-ray frame (ncu-summary.py) with its
# SASS, each instruction's count and the traversal's loop
# (ncu-sass-opcodes.py). Files go to OUTDIR, packed into ARCHIVE (a device
# call returns a limited number of files); the closing lines print last.
#
#   V="main before" [NCU="main before"] [TESTS=1|"NAME..."] [SECTION=build|render] [ROUNDS=2] \
#     [RENDER=1] scripts/gpu/variants-check.sh OUTDIR [ARCHIVE]
#
# NCU=" " (a blank, not empty) profiles none.
#
# The variant files travel in .gpu-vtk/variants (source-variants.sh says how
# they are made), GoogleTest in .gpu-vtk/googletest.
set -u
cd "$(dirname "$0")/../.." || exit 1
D=$(realpath -m "${1:?name the output folder}")
archive=${2:-}
mkdir -p "$D"
V=${V:-"main before"}
section=${SECTION:-build}
t0=$(date +%s)
elapsed() { echo "$1 done $(( $(date +%s) - t0 )) s" >> "$D/times.txt"; }

SOURCE_VARIANTS="$V" SECTION=$section ROUNDS=${ROUNDS:-2} TESTS=${TESTS:-1} timeout 420 \
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
if [ ! -x "$tests" ]; then
  echo "sanitizers not run: main's engine tests were not built (TESTS names the variants that build them)" \
    >> "$D/sanitize.txt"
elif [ "$section" = render ]; then
  for tool in memcheck initcheck; do sanitize "$tool" "$tool" '*RenderTest*CUDA*:*SceneTest*CUDA*:RenderCUDA*'; done
else
  sanitize memcheck memcheck '*OctreeBuild*CUDA*:*OctreeUpdate*CUDA*:*Stability*CUDA*'
  # The launch-refusal tests make the runtime refuse launches on purpose.
  sanitize memcheck-refused memcheck 'CudaFaultsLaunch*' --report-api-errors no
  for tool in racecheck initcheck synccheck; do sanitize "$tool" "$tool" '*OctreeBuild*CUDA*'; done
fi
elapsed sanitizers

# The depth-16 primary frame: RenderKernel launch 43 of `--only render`
# (gpu-check.sh's profile part says which launch is which).
for v in ${NCU:-main before}; do
  [ "$section" = render ] || break
  bench="/tmp/src-$v/build/bin/octoray_bench_cuda"
  timeout 150 scripts/gpu/ncu-render.sh 42 "$D/profile16-$v.csv" "$bench" > /dev/null 2>&1
  python3 scripts/gpu/ncu-summary.py "$D/profile16-$v.csv" > "$D/profile16-$v.txt" 2>&1
  timeout 150 ncu --clock-control none -k regex:RenderKernel --launch-skip 42 --launch-count 1 \
    --section SourceCounters --page source --print-source sass "$bench" --only render > "$D/sass16-$v.txt" 2>&1
  python3 scripts/gpu/ncu-sass-opcodes.py "$D/sass16-$v.txt" 0 > "$D/opcodes16-$v.txt" 2>&1
  python3 scripts/gpu/ncu-sass-opcodes.py "$D/sass16-$v.txt" 0 --loop > "$D/loop16-$v.txt" 2>&1
done
for v in ${NCU:-main before}; do
  [ "$section" = build ] || break
  for n in 1e7 1e8; do
    timeout 120 ncu --clock-control none --metrics gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum \
      --csv --page raw --log-file "$D/pb-$v-$n.csv" "/tmp/src-$v/build/bin/octoray_bench_cuda" --profile-build $n \
      > /dev/null 2>&1
    python3 scripts/gpu/ncu-kernel-times.py "$D/pb-$v-$n.csv" 2 --steps > "$D/steps-$v-$n.txt" 2>&1
    python3 scripts/gpu/ncu-kernel-times.py "$D/pb-$v-$n.csv" 2 > "$D/kernels-$v-$n.txt" 2>&1
  done
done
elapsed ncu
rm -f "$D"/pb-*.csv
[ -n "$archive" ] && tar czf "$archive" -C "$D" .

cat "$D/variants.txt"
grep -H "^render depth" "$D"/render-*.log 2>/dev/null
cat "$D/sanitize.txt"
for f in "$D"/steps-*.txt "$D"/profile16-*.txt; do [ -e "$f" ] && { echo "== $f"; cat "$f"; }; done
for f in "$D"/opcodes16-*.txt; do [ -e "$f" ] && { echo "== $f"; head -30 "$f"; }; done
cat "$D/times.txt"
