#!/usr/bin/env bash
# Everything the GPU machine proves, in one call: it builds the project with
# CUDA against VTK with EGL (the engine, the VTK layer, their tests and
# benchmarks), runs the engine tests and the mapper tests on both backends,
# compute-sanitizer, and the benchmarks, and prints a short table last.
#
# The GPU machine (Ubuntu 24.04, GCC 13, CUDA, CMake, ninja) has no VTK and no
# network. What it needs travels in the ignored folder .gpu-vtk/, made here by
# scripts/gpu/fetch-vtk.sh [--prebuilt] and named in the device call's carry:
#   gl/*.deb             Debian's EGL/OpenGL loaders and headers
#   vtk-egl.tar.xz       VTK 9.2 built with EGL (--prebuilt); else it is built
#   vtk92-subset.tar.xz  from these sources here (about 5 minutes, 16 cores)
#   googletest/          Debian's GoogleTest sources
# A VTK found in /tmp/vtk-egl (an earlier call on the same machine) is reused.
#
#   scripts/gpu/gpu-check.sh OUTDIR [PARTS]
# PARTS, comma-separated (default all): tests (engine, mapper and tool tests,
# both backends), sanitize (compute-sanitizer memcheck, initcheck and synccheck on
# the engine's CUDA tests, memcheck on the mapper's), racecheck (on the
# engine's CUDA tests: the slowest, about 3 minutes), bench (engine
# benchmarks; BILLION points, default 1e9, generated on the device, 0: none),
# profile (Nsight Compute on the render kernel, with its instruction count
# and busiest pipes: primary rays, and Phong with
# shadows and a bounce, 10 M points at depth 10, 1920x1080), variants (the
# render benchmark built with other register caps, OCTORAY_RENDER_MIN_BLOCKS
# from VARIANT_BLOCKS, default 0 and 8, beside the main build's 6, and with
# other block shapes, OCTORAY_RENDER_BLOCK from VARIANT_SHAPES, default
# 8x16, beside the main build's 16x8), report (the
# report's engine programs), orbit (the mapper against VTK's GPU mappers;
# ORBIT_ARGS adds arguments), profile-build (ncu's time of every kernel of a
# build of PROFILE_BUILD points, default 1e8, and by step of a build of 10 M
# points), profile-nested (Nsight Compute's details of the nested lists'
# count and placement in the second of two builds of 10 M points), sass
# (the primary-ray render kernel's machine code, from cuobjdump).
# Logs and files go to OUTDIR; OUTDIR/report-files.tgz holds what `make
# report` reads (unpack it into Benchmarks/gpu/).
set -uo pipefail
cd "$(dirname "$0")/../.."
out=$(realpath -m "${1:-build-gpu/logs}")
parts=",${2:-tests,sanitize,racecheck,bench,profile,report,orbit},"
mkdir -p "$out"
status=()
step() { # name, command...
  local name=$1; shift
  local t0=$(date +%s%N)
  if "$@" >"$out/$name.log" 2>&1; then r=pass; else r=FAIL; fi
  local t1=$(date +%s%N)
  status+=("$(printf '%-24s %-5s %7d ms' "$name" "$r" "$(( (t1 - t0) / 1000000 ))")")
  tail -n 3 "$out/$name.log"
}
want() { [[ $parts == *",$1,"* ]]; }

# ---- OpenGL through EGL on the NVIDIA driver, and VTK.
carried=$PWD/.gpu-vtk
for f in "$carried"/gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
vtk=/tmp/vtk-egl
if [ ! -f "$vtk/lib/cmake/vtk-9.2/vtk-config.cmake" ]; then
  if [ -f "$carried/vtk-egl.tar.xz" ]; then
    step vtk-unpack bash -c "mkdir -p /tmp && tar -xJf '$carried/vtk-egl.tar.xz' -C /tmp"
  else
    step vtk-build scripts/gpu/build-vtk-egl.sh "$carried" "$vtk"
  fi
fi
export LD_LIBRARY_PATH=$vtk/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$out/gpu.txt"

# ---- One build: engine, VTK modules (those VTK alone serves: the mapper and
# the particle reader), tests and benchmarks. -include cstdint: VTK 9.2's
# headers predate GCC 13.
build=build-gpu
step configure cmake -S . -B $build -G Ninja -DCMAKE_BUILD_TYPE=Release -DOCTORAY_ENABLE_CUDA=ON \
  -DCMAKE_CUDA_ARCHITECTURES=90 -DVTK_DIR="$vtk/lib/cmake/vtk-9.2" -DCMAKE_CXX_FLAGS="-include cstdint" \
  -DOCTORAY_GTEST_SOURCE_DIR="$carried/googletest"
step build cmake --build $build -j "$(nproc)"

# The mapper tests: the CPU ones (label vtk) and the CUDA ones (label gpu).
mapper_tests='RenderingVolumeCxx'
if want tests; then
  step engine-tests $build/bin/octoray_engine_tests --gtest_output=xml:"$out/engine-tests.xml"
  step mapper-tests bash -c "cd $build && ctest -R '$mapper_tests' --no-tests=error --output-on-failure --output-junit '$out/mapper-tests.xml'"
  # The command-line tool, its CUDA half among them (engine.tool.cuda).
  step tool-tests bash -c "cd $build && ctest -R '^engine\.tool' --no-tests=error --output-on-failure -V"
fi

# The engine's tests of launches the CUDA runtime refuses on purpose.
refused='CudaFaultsLaunch*:*RefusedIsNamed'
if want sanitize; then
  # The tests of refused launches (CudaFaultsLaunch, and the device checks'
  # *RefusedIsNamed) make the CUDA runtime refuse launches on purpose, which
  # compute-sanitizer counts as API errors; they run under memcheck on their
  # own, with API errors not reported, so the error paths are still checked.
  tests='*CUDA*:CudaFaults*'
  engine=$build/bin/octoray_engine_tests
  step memcheck compute-sanitizer --tool memcheck --error-exitcode 1 $engine --gtest_filter="$tests:-$refused"
  step memcheck-refused compute-sanitizer --tool memcheck --report-api-errors no --error-exitcode 1 $engine --gtest_filter="$refused"
  step initcheck compute-sanitizer --tool initcheck --error-exitcode 1 $engine --gtest_filter="$tests:-*EveryDepth*:$refused"
  step synccheck compute-sanitizer --tool synccheck --error-exitcode 1 $engine --gtest_filter="$tests:-*EveryDepth*:$refused"
  # Every CUDA mapper test under memcheck, with the command CTest runs.
  (cd $build && ctest -L gpu -R "$mapper_tests" -N -V) | sed -n 's/^[0-9]*: Test command: //p' > "$out/mapper-commands.txt"
  # A test's own failure is the mapper-tests step's business: here only
  # memcheck's findings count (its error exit code 86).
  step memcheck-mapper bash -c "test -s '$out/mapper-commands.txt' || exit 1; status=0; while read -r cmd; do eval compute-sanitizer --tool memcheck --error-exitcode 86 \$cmd; [ \$? = 86 ] && status=1; done < '$out/mapper-commands.txt'; exit \$status"
fi
if want racecheck; then
  step racecheck compute-sanitizer --tool racecheck --error-exitcode 1 $build/bin/octoray_engine_tests \
    --gtest_filter="*CUDA*:CudaFaults*:-*EveryDepth*:$refused"
fi

if want bench; then
  step bench $build/bin/octoray_bench_cuda --json "$out/bench-results-cuda.json" --billion "${BILLION:-1e9}"
fi
if want profile; then
  # RenderKernel launches of `--only render`: 10 with the copy to the host,
  # then 10 primary and 10 full frames at depth 10 (one of each profiled),
  # then the same at depth 16 (its primary frame profiled too, the goal
  # furthest off).
  for run in primary:12 full:22 primary16:42; do
    step "profile-${run%%:*}" scripts/gpu/ncu-render.sh "${run##*:}" "$out/profile-${run%%:*}.csv" \
      $build/bin/octoray_bench_cuda
  done
  python3 scripts/gpu/ncu-summary.py "$out"/profile-primary.csv "$out"/profile-full.csv "$out"/profile-primary16.csv \
    > "$out/profile.txt" 2>&1
fi
if want profile-build; then
  # Every kernel of two builds at depth 10, timed by ncu with its DRAM
  # traffic: of 100 M points, the second build's time per kernel
  # (profile-build.txt), and of 10 M points, where the device phases are
  # furthest from the sort's floor, the second build's time per step and
  # level (profile-build-10m.txt).
  for tag in "" -10m; do
    step profile-build$tag ncu --clock-control none \
      --metrics gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum --csv --page raw \
      --log-file "$out/profile-build$tag.csv" $build/bin/octoray_bench_cuda \
      --profile-build "$([ -z "$tag" ] && echo "${PROFILE_BUILD:-1e8}" || echo 1e7)"
  done
  python3 scripts/gpu/ncu-kernel-times.py "$out/profile-build.csv" 2 > "$out/profile-build.txt" 2>&1
  python3 scripts/gpu/ncu-kernel-times.py "$out/profile-build-10m.csv" 2 --steps > "$out/profile-build-10m.txt" 2>&1
fi
if want profile-nested; then
  # The two passes over the sorted points that give every level's run
  # starts, below the memory's speed (profile-build-10m.txt): what stalls
  # them. The first build places the lists twice (no room from a build
  # before it): three launches skipped, the second build's two profiled.
  step profile-nested scripts/gpu/ncu-details.sh 'Nested(Count|Place)Kernel' 3 2 "$out/profile-nested.csv" \
    $build/bin/octoray_bench_cuda --profile-build 1e7
  python3 scripts/gpu/ncu-summary.py "$out/profile-nested.csv" > "$out/profile-nested.txt" 2>&1
fi
if want sass; then
  # The render kernel's machine code (primary rays), to count what one
  # traversal step costs.
  step sass bash -c "cuobjdump -sass $build/bin/octoray_bench_cuda | awk '/Function : .*RenderKernel.*FeaturesILb0ELb0ELb0ELb0E/{p=1} p&&/Function : /&&!/FeaturesILb0ELb0ELb0ELb0E/{p=0} p' > '$out/sass-primary.txt'"
fi
if want variants; then
  variant() { # name, CMake definitions...
    local name=$1; shift
    local vb=build-gpu-$name
    step "variant-$name" bash -c "cmake -S . -B $vb -G Ninja -DCMAKE_BUILD_TYPE=Release -DOCTORAY_ENABLE_CUDA=ON \
      -DCMAKE_CUDA_ARCHITECTURES=90 -DVTK_DIR='$vtk/lib/cmake/vtk-9.2' -DCMAKE_CXX_FLAGS='-include cstdint' \
      -DOCTORAY_GTEST_SOURCE_DIR='$carried/googletest' $* >/dev/null &&
      cmake --build $vb --target octoray_bench_cuda >/dev/null && $vb/bin/octoray_bench_cuda --only render"
  }
  for blocks in ${VARIANT_BLOCKS-0 8}; do
    variant "blocks$blocks" -DOCTORAY_RENDER_MIN_BLOCKS=$blocks
  done
  for shape in ${VARIANT_SHAPES-8x16}; do
    variant "shape$shape" -DOCTORAY_RENDER_BLOCK=$shape
  done
fi
if want report; then
  # The CT scene is made here by `make report` (VTK reads the DICOM series)
  # and carried as build/report/scenes/ct5n.particles.
  step quality $build/bin/octoray_bench_quality --backend cuda --scenes build/report/scenes --json "$out/quality-cuda.json"
  step bench-render $build/bin/octoray_bench_render --backend cuda --size 1920x1080 --parts modes --json "$out/bench-render-cuda.json"
  step bench-thesis $build/bin/octoray_bench_thesis --backend cuda --json "$out/bench-thesis-cuda.json"
  step bench-quantisation $build/bin/octoray_bench_quantisation --backend cuda --json "$out/bench-quantisation-cuda.json"
fi
if want orbit; then
  mkdir -p "$out/orbit"
  # shellcheck disable=SC2086
  step orbit $build/bin/octoray_bench_orbit --json "$out/orbit.json" --images "$out/orbit" ${ORBIT_ARGS:-}
fi

{
echo
echo "== octoray GPU check, $(date -u +%Y-%m-%d): $(cat "$out/gpu.txt") =="
[ -f "$out/engine-tests.log" ] && grep -E "tests? (ran|from)|PASSED|FAILED" "$out/engine-tests.log" | tail -3
[ -f "$out/mapper-tests.log" ] && grep -E "tests passed|tests failed|\(Failed\)|\(Skipped\)" "$out/mapper-tests.log" | tail -8
[ -f "$out/tool-tests.log" ] && grep -E "Test +#[0-9]+: engine\.tool" "$out/tool-tests.log"
for f in memcheck memcheck-refused racecheck initcheck synccheck memcheck-mapper; do
  [ -f "$out/$f.log" ] && echo "$f: $(grep -E "ERROR SUMMARY|RACECHECK SUMMARY" "$out/$f.log" | sort | uniq -c | tr -s ' ' | paste -sd';')"
done
[ -f "$out/bench.log" ] && grep -E "^(device|upload|build|every attribute|update|render)" "$out/bench.log"
[ -f "$out/profile.txt" ] && cat "$out/profile.txt"
[ -f "$out/profile-build.txt" ] && head -25 "$out/profile-build.txt"
[ -f "$out/profile-build-10m.txt" ] && cat "$out/profile-build-10m.txt"
[ -f "$out/sass-primary.txt" ] && echo "sass-primary.txt: $(grep -c '/\*[0-9a-f]*\*/' "$out/sass-primary.txt") instructions"
for log in "$out"/variant-*.log; do
  [ -f "$log" ] && grep -E "^render" "$log" | sed "s/^/$(basename "$log" .log): /"
done
[ -f "$out/orbit.log" ] && grep -E "points: generated|frame median|  =>|skipped" "$out/orbit.log" | cut -c1-220
printf '%s\n' "${status[@]}"
} | tee "$out/summary.txt"
# What `make report` reads, in one archive (the device tool brings back only
# a limited number of files).
files=()
for f in summary.txt gpu.txt engine-tests.xml mapper-tests.xml bench-results-cuda.json quality-cuda.json \
  bench-render-cuda.json bench-thesis-cuda.json bench-quantisation-cuda.json orbit.json profile.txt \
  profile-primary.csv profile-full.csv profile-primary16.csv profile-build.txt profile-build-10m.txt; do
  [ -e "$out/$f" ] && files+=("$f")
done
(cd "$out" && tar czf report-files.tgz "${files[@]}")
