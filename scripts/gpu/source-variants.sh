#!/usr/bin/env bash
# The render benchmark of source variants of the traversal, on the GPU
# machine after gpu-check.sh (whose VTK in /tmp/vtk-egl it reuses): for each
# NAME in SOURCE_VARIANTS, .gpu-vtk/variants/Traversal.NAME.h replaces
# Rendering/Engine/octoray/Traversal.h in a build folder of its own, where
# `octoray_bench_cuda --only render` runs; the tree's own Traversal.h is put
# back after each. A variant file is made here from the commit Benchmarks/gpu/COMMAND.md
# names and the patch in Benchmarks/gpu/variants/:
#   git show COMMIT:Rendering/Engine/octoray/Traversal.h > .gpu-vtk/variants/Traversal.NAME.h
#   patch .gpu-vtk/variants/Traversal.NAME.h Benchmarks/gpu/variants/NAME.patch
# and travels in the device call's carry (.gpu-vtk/variants).
#
#   SOURCE_VARIANTS="NAME..." scripts/gpu/source-variants.sh OUTDIR
set -uo pipefail
cd "$(dirname "$0")/../.."
out=$1
vtk=/tmp/vtk-egl
traversal=Rendering/Engine/octoray/Traversal.h
for v in ${SOURCE_VARIANTS:?name the variants}; do
  cp $traversal /tmp/Traversal.main.h
  cp .gpu-vtk/variants/Traversal.$v.h $traversal
  vb=build-gpu-src-$v
  { cmake -S . -B $vb -G Ninja -DCMAKE_BUILD_TYPE=Release -DOCTORAY_ENABLE_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 \
      -DVTK_DIR="$vtk/lib/cmake/vtk-9.2" -DCMAKE_CXX_FLAGS='-include cstdint' \
      -DOCTORAY_GTEST_SOURCE_DIR="$PWD/.gpu-vtk/googletest" >/dev/null &&
    cmake --build $vb --target octoray_bench_cuda >/dev/null && $vb/bin/octoray_bench_cuda --only render; } > "$out/source-$v.log" 2>&1
  cp /tmp/Traversal.main.h $traversal
  echo "== source variant $v"
  grep "render depth" "$out/source-$v.log"
done
