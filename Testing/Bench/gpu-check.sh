#!/usr/bin/env bash
# Builds, tests and benchmarks the CUDA backend in one go on a GPU machine
# that has only the CUDA toolkit, CMake and a compiler. GoogleTest comes as
# Debian's sources copied to .deps/googletest (scripts/install-deps.sh
# installs the googletest package; cp -r /usr/src/googletest .deps/).
#   Testing/Bench/gpu-check.sh [OUTDIR]
# Prints a short table last; full logs go to OUTDIR (default build-gpu/logs),
# the files `make report` reads to OUTDIR/report-files.tgz.
set -uo pipefail
cd "$(dirname "$0")/../.."
out=${1:-build-gpu/logs}
mkdir -p "$out"
status=()
step() { # name, command...
  local name=$1; shift
  local t0=$(date +%s%N)
  if "$@" >"$out/$name.log" 2>&1; then r=pass; else r=FAIL; fi
  local t1=$(date +%s%N)
  status+=("$(printf '%-22s %-5s %6d ms' "$name" "$r" "$(( (t1 - t0) / 1000000 ))")")
  tail -n 5 "$out/$name.log"
}

nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$out/gpu.txt"
step configure cmake -S Rendering/Engine -B build-gpu -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DOCTORAY_ENABLE_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 -DOCTORAY_GTEST_SOURCE_DIR="$PWD/.deps/googletest"
step build cmake --build build-gpu -j 16
step tests build-gpu/bin/octoray_engine_tests --gtest_output=xml:"$out/engine-tests.xml"
# CudaFaultsLaunch makes the CUDA runtime refuse launches on purpose, which
# compute-sanitizer counts as API errors; it runs under memcheck on its own,
# with API errors not reported, so the error paths are still checked for
# memory faults.
tests='*CUDA*:CudaFaults*'
step synccheck compute-sanitizer --tool synccheck --error-exitcode 1 build-gpu/bin/octoray_engine_tests --gtest_filter="$tests:-*EveryDepth*:CudaFaultsLaunch*"
step memcheck compute-sanitizer --tool memcheck --error-exitcode 1 build-gpu/bin/octoray_engine_tests --gtest_filter="$tests:-CudaFaultsLaunch*"
step memcheck-refused compute-sanitizer --tool memcheck --report-api-errors no --error-exitcode 1 build-gpu/bin/octoray_engine_tests --gtest_filter='CudaFaultsLaunch*'
step racecheck compute-sanitizer --tool racecheck --error-exitcode 1 build-gpu/bin/octoray_engine_tests --gtest_filter="$tests:-*EveryDepth*:CudaFaultsLaunch*"
step initcheck compute-sanitizer --tool initcheck --error-exitcode 1 build-gpu/bin/octoray_engine_tests --gtest_filter="$tests:-*EveryDepth*:CudaFaultsLaunch*"
step bench build-gpu/bin/octoray_bench_cuda --json "$out/bench-results-cuda.json"
# The report's GPU rows (make report reads them from Testing/Bench/gpu/).
# The CT scene is made here by `make report` (VTK reads the DICOM series)
# and carried to the GPU machine as build/report/scenes/ct5n.particles.
step quality build-gpu/bin/octoray_bench_quality --backend cuda --scenes build/report/scenes --json "$out/quality-cuda.json"
step bench-render build-gpu/bin/octoray_bench_render --backend cuda --size 1920x1080 --parts modes --json "$out/bench-render-cuda.json"
step bench-thesis build-gpu/bin/octoray_bench_thesis --backend cuda --json "$out/bench-thesis-cuda.json"
step bench-quantisation build-gpu/bin/octoray_bench_quantisation --backend cuda --json "$out/bench-quantisation-cuda.json"

{
echo
echo "== octoray CUDA check, $(date -u +%Y-%m-%d) =="
grep -E "tests? (ran|from)|PASSED|FAILED" "$out/tests.log" | tail -3
grep -E "ERROR SUMMARY|RACECHECK SUMMARY" "$out"/memcheck.log "$out"/memcheck-refused.log "$out"/racecheck.log "$out"/initcheck.log "$out"/synccheck.log
grep -E "^(device|build|update|render|thesis|  [0-9]+ points)" "$out/bench.log"
printf '%s\n' "${status[@]}"
} | tee "$out/summary.txt"
# What `make report` reads, in one archive (the device tool brings back only
# a limited number of files): unpack it into Testing/Bench/gpu/.
tar czf "$out/report-files.tgz" -C "$out" summary.txt gpu.txt engine-tests.xml bench-results-cuda.json \
  quality-cuda.json bench-render-cuda.json bench-thesis-cuda.json bench-quantisation-cuda.json
