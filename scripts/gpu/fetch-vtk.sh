#!/usr/bin/env bash
# Here (Debian 12), for the GPU machine, into DIR (default .gpu-vtk, ignored
# by git and named in the device call's carry):
#   vtk92-subset.tar.xz  VTK's sources from Debian's `paraview` source package
#                        (VTK 9.2 exactly as ParaView 5.11 ships it), without the
#                        third-party trees a rendering build never compiles
#   gl/*.deb             Debian's glvnd EGL/OpenGL loaders and headers: the GPU
#                        machine has NVIDIA's EGL vendor library and nothing else
#   googletest/          Debian's GoogleTest sources (package googletest), built
#                        there with the engine's tests
#   vtk-egl.tar.xz       with --prebuilt: VTK built here with EGL by
#                        scripts/gpu/build-vtk-egl.sh, stripped and packed (the GPU
#                        run then unpacks it instead of building for 5 minutes)
# Nothing is installed and the system's apt sources are left alone.
#   scripts/gpu/fetch-vtk.sh [DIR] [--prebuilt]
set -euo pipefail
cd "$(dirname "$0")/../.."
dir=.gpu-vtk; prebuilt=0
for a in "$@"; do
  case $a in --prebuilt) prebuilt=1 ;; *) dir=$a ;; esac
done
dir=$(realpath -m "$dir"); mkdir -p "$dir/gl"
if [ ! -f "$dir/vtk92-subset.tar.xz" ]; then
  apt=$(mktemp -d); trap 'rm -rf "$apt"' EXIT
  mkdir -p "$apt/lists/partial" "$apt/parts"
  printf '%s\n' "Types: deb-src" "URIs: http://deb.debian.org/debian" "Suites: bookworm" \
    "Components: main" "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" > "$apt/parts/src.sources"
  o=(-oDir::Etc::SourceList=/dev/null -oDir::Etc::SourceParts="$apt/parts" -oDir::State::Lists="$apt/lists")
  apt-get "${o[@]}" update -q
  (cd "$apt" && apt-get "${o[@]}" source --download-only paraview)
  tar -xJf "$apt"/paraview_*.orig.tar.xz -C "$apt" --wildcards '*/VTK/*'
  top=$(dirname "$(ls -d "$apt"/*/VTK)")
  skip=()
  for d in vtkm hdf5 libproj sqlite mpi4py netcdf ioss cgns exodusII xdmf2 xdmf3 h5part libharu \
           theora ogg vpic libxml2; do skip+=(--exclude="VTK/ThirdParty/$d"); done
  for d in Documentation Examples Web Testing/Data Remote; do skip+=(--exclude="VTK/$d"); done
  tar -C "$top" "${skip[@]}" -cf - VTK | xz -T0 -6 > "$dir/vtk92-subset.tar.xz"
fi
if ! ls "$dir"/gl/libegl1_*.deb >/dev/null 2>&1; then
  (cd "$dir/gl" && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 \
     libegl-dev libgl-dev libglvnd-dev libopengl-dev libglx-dev libgles-dev)
fi
[ -d "$dir/googletest" ] || cp -r /usr/src/googletest "$dir/googletest"
if [ "$prebuilt" = 1 ] && [ ! -f "$dir/vtk-egl.tar.xz" ]; then
  # Built outside the carried folder (build-vtk-egl/, ignored; the build
  # tree and the unpacked install would not fit a device call's 64 MiB).
  VTK_EGL_WORK=$PWD/build-vtk-egl-work scripts/gpu/build-vtk-egl.sh "$dir" "$PWD/build-vtk-egl"
  # The whole install (headers, CMake package, libraries, and the wrapping
  # tools VTK's CMake package names) as vtk-egl/. The prefix is relocatable
  # (VTK's CMake files use paths relative to themselves).
  tar -C "$PWD" --transform 's,^build-vtk-egl,vtk-egl,' -cf - build-vtk-egl | xz -T0 -6 > "$dir/vtk-egl.tar.xz"
  rm -rf build-vtk-egl-work
fi
du -sh "$dir"/*.tar.xz "$dir/gl" "$dir/googletest"
