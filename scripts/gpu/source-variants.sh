#!/usr/bin/env bash
# A benchmark section of source variants of engine headers, on the GPU
# machine: for each NAME in SOURCE_VARIANTS, every .gpu-vtk/variants/FILE.NAME.h
# replaces Rendering/Engine/octoray/FILE.h (Traversal.h, CudaUpload.h, ...)
# in a copy of the tree with a build folder of its own; "main" names the
# tree itself; a .gpu-vtk/variants/FILE.NAME.cpp replaces FILE.cpp there
# alike (CpuEngine.cpp, which the render headers' callers live in), and a
# .gpu-vtk/variants/CudaBench.NAME.cu the benchmark (for a variant whose
# engine the tree's benchmark no longer compiles against). All are
# built first (in parallel), then `octoray_bench_cuda
# --only SECTION` (default render) runs ROUNDS times (default 1) over all of
# them in turn, so that a drift of the card's clocks reaches every variant
# alike. A variant file is made here from the commit Benchmarks/gpu/COMMAND.md
# names and the patch in Benchmarks/gpu/variants/:
#   git show COMMIT:Rendering/Engine/octoray/FILE.h > .gpu-vtk/variants/FILE.NAME.h
#   patch .gpu-vtk/variants/FILE.NAME.h Benchmarks/gpu/variants/NAME.patch
# and travels in the device call's carry (.gpu-vtk/variants).
#
# Run after gpu-check.sh, it builds against that call's VTK (/tmp/vtk-egl);
# without it, the engine alone (OCTORAY_ENABLE_VTK=OFF), which is all the
# benchmark needs. With TESTS=1 the "main" folder also builds and runs the
# engine's tests (both backends); TESTS="main NAME..." names the variants
# that do (those whose files still fit the tree's tests).
#
# BENCH="octoray_bench_build ARGS..." runs another of the project's
# benchmarks in place of the section (built in each variant's folder).
#
#   SOURCE_VARIANTS="main NAME..." [SECTION=render|build] [ROUNDS=N] [TESTS=1|"NAME..."] [BENCH=...] \
#     scripts/gpu/source-variants.sh OUTDIR
set -uo pipefail
cd "$(dirname "$0")/../.."
tested=" ${TESTS:-} "
[ "${TESTS:-}" = 1 ] && tested=" main "
out=$(realpath -m "$1")
mkdir -p "$out"
vtk=/tmp/vtk-egl
section=${SECTION:-render}
bench=(${BENCH:-octoray_bench_cuda --only $section})
if [ -f "$vtk/lib/cmake/vtk-9.2/vtk-config.cmake" ]; then
  with_vtk=(-DVTK_DIR="$vtk/lib/cmake/vtk-9.2")
else
  with_vtk=(-DOCTORAY_ENABLE_VTK=OFF)
fi

# Each variant gets a copy of the source tree, so that the builds can run
# side by side.
# A variant without its files would run main's engine under its name.
for v in ${SOURCE_VARIANTS:?name the variants}; do
  if [ "$v" != main ] && ! compgen -G ".gpu-vtk/variants/*.$v.*" > /dev/null; then
    echo "== $v: no .gpu-vtk/variants/*.$v.* (carried?)" >&2; exit 1
  fi
done
for v in $SOURCE_VARIANTS; do
  src=/tmp/src-$v
  rm -rf "$src" && mkdir -p "$src"
  # Tracked files and new ones not yet in the index the copy arrived with.
  git ls-files -z --cached --others --exclude-standard | xargs -0 cp --parents -t "$src"
  cp -r .gpu-vtk "$src/"
  for ext in h cpp cu; do
    for f in .gpu-vtk/variants/*."$v".$ext; do
      [ -e "$f" ] || continue
      # The tracked file of that name (one of the engine's or the benchmark's).
      target=$(git ls-files Rendering/Engine Benchmarks/Cuda | grep -E "(^|/)$(basename "$f" ."$v".$ext)\.$ext\$")
      [ "$(echo "$target" | wc -l)" = 1 ] && [ -n "$target" ] || { echo "== $v: no one file for $f" >&2; exit 1; }
      cp "$f" "$src/$target"
    done
  done
  # The tests belong to the tree's own headers: built in the variants TESTS names.
  targets=("${bench[0]}")
  [[ "$tested" == *" $v "* ]] && targets+=(octoray_engine_tests)
  { cmake -S "$src" -B "$src/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DOCTORAY_ENABLE_CUDA=ON \
      -DCMAKE_CUDA_ARCHITECTURES=90 "${with_vtk[@]}" -DCMAKE_CXX_FLAGS='-include cstdint' \
      -DOCTORAY_GTEST_SOURCE_DIR="$src/.gpu-vtk/googletest" &&
    cmake --build "$src/build" --target "${targets[@]}" -j 8; } > "$out/build-$v.log" 2>&1 &
done
wait
for v in $SOURCE_VARIANTS; do
  [ -x "/tmp/src-$v/build/bin/${bench[0]}" ] || { echo "== $v: build failed"; tail -5 "$out/build-$v.log"; }
done
for v in $SOURCE_VARIANTS; do
  tests=/tmp/src-$v/build/bin/octoray_engine_tests
  [[ "$tested" == *" $v "* ]] || continue
  "$tests" > "$out/variant-$v-tests.log" 2>&1
  echo "== $v: engine tests, exit $?"; grep -E "tests ran|PASSED|FAILED" "$out/variant-$v-tests.log" | head -5
done
for r in $(seq "${ROUNDS:-1}"); do
  for v in $SOURCE_VARIANTS; do
    "/tmp/src-$v/build/bin/${bench[0]}" "${bench[@]:1}" >> "$out/source-$v.log" 2>&1
  done
done
for v in $SOURCE_VARIANTS; do
  echo "== source variant $v"
  [ -n "${BENCH:-}" ] && grep -E "^ *[0-9]" "$out/source-$v.log" && continue
  grep -E "^(render depth|upload of|build n=.*depth=10)" "$out/source-$v.log"
  [ "$section" = build ] && python3 scripts/gpu/build-ratios.py "$out/source-$v.log" | tail -n +2
  [ "$section" = render ] && python3 scripts/gpu/render-rates.py "$out/source-$v.log" | tail -n +2
done
