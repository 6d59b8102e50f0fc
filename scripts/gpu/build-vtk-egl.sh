#!/usr/bin/env bash
# VTK 9.2 as ParaView 5.11 ships it, built with EGL and no X: what the VTK
# layer (mappers, the particle reader, the mapper tests and the orbit
# benchmark against VTK's own GPU mappers) needs on a GPU machine that has
# only CUDA, CMake, ninja and a compiler.
#   scripts/gpu/build-vtk-egl.sh SRC PREFIX
# SRC is the folder scripts/gpu/fetch-vtk.sh filled (vtk92-subset.tar.xz and
# gl/*.deb). It builds on either machine: on the GPU machine (Ubuntu 24.04,
# GCC 13, 16 cores: about 5 minutes), or here on Debian 12 once (2 cores:
# 22 minutes on 2026-11-27), packed by scripts/gpu/fetch-vtk.sh --prebuilt and carried,
# so that a GPU run spends no device time on VTK.
set -euo pipefail
src=$(realpath "$1"); prefix=$(realpath -m "$2")
work=${VTK_EGL_WORK:-/tmp/vtk-egl-work}
mkdir -p "$work"
# The GPU machine has NVIDIA's EGL vendor library but no glvnd loader and
# no headers: Debian's, unpacked over /. Here they are installed packages.
if [ ! -f /usr/include/EGL/egl.h ]; then
  for f in "$src"/gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
[ -d "$work/VTK" ] || tar -xJf "$src/vtk92-subset.tar.xz" -C "$work"
# The modules the project's VTK layer, its tests and benchmarks use; their
# dependencies come along. One list, so that a GPU build and a carried
# prebuilt one have the same modules.
modules=(RenderingOpenGL2 RenderingVolumeOpenGL2 RenderingVolume RenderingFreeType
  InteractionStyle FiltersSources FiltersCore FiltersGeneral FiltersPoints
  IOImage IOCore CommonMisc ParallelCore TestingRendering zlib)
enable=()
for m in "${modules[@]}"; do enable+=("-DVTK_MODULE_ENABLE_VTK_$m=YES"); done
# -include cstdint: VTK 9.2 predates GCC 13, whose headers no longer pull
# in <cstdint>. STDThread: vtkSMPTools (vtkPointInterpolator, the resampling
# peer of the benchmark) on every core, as ParaView's own builds do.
cmake -S "$work/VTK" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON \
  -DCMAKE_CXX_FLAGS="-include cstdint" -DCMAKE_INSTALL_PREFIX="$prefix" \
  -DVTK_BUILD_TESTING=OFF -DVTK_BUILD_EXAMPLES=OFF -DVTK_WRAP_PYTHON=OFF \
  -DVTK_SMP_IMPLEMENTATION_TYPE=STDThread \
  -DVTK_GROUP_ENABLE_Imaging=DONT_WANT -DVTK_GROUP_ENABLE_MPI=DONT_WANT -DVTK_GROUP_ENABLE_Qt=DONT_WANT \
  -DVTK_GROUP_ENABLE_Rendering=DONT_WANT -DVTK_GROUP_ENABLE_StandAlone=DONT_WANT \
  -DVTK_GROUP_ENABLE_Views=DONT_WANT -DVTK_GROUP_ENABLE_Web=DONT_WANT \
  "${enable[@]}" -DVTK_OPENGL_HAS_EGL=ON -DVTK_USE_X=OFF >"$work/configure.log"
cmake --build "$work/build" -j "${JOBS:-$(nproc)}" >"$work/build.log"
cmake --install "$work/build" --strip >/dev/null
echo "VTK with EGL in $prefix"
