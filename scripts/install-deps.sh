#!/usr/bin/env bash
# Installs what octoray needs on Debian 12, by package name, and only what is
# missing. PCL's headers come from its -dev package unpacked into .deps/pcl:
# libpcl-dev itself depends on Debian's VTK 9.1, which conflicts with
# ParaView's VTK that the whole project builds against (see DESIGN.md).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  # build tools and tests
  cmake ninja-build g++ pkg-config googletest libgtest-dev libbenchmark-dev
  # VTK 9.2 through ParaView 5.11 (C++, Python wrapping, plugin)
  paraview paraview-dev python3-paraview
  qtbase5-dev qttools5-dev libqt5svg5-dev qtxmlpatterns5-dev-tools
  libqt5x11extras5-dev libopenmpi-dev python3-dev
  # find_package(ParaView) without components makes VTK's config find every
  # third-party library its modules were built with; paraview-dev does not
  # depend on these -dev packages, so configuring fails without them
  libutfcpp-dev libogg-dev libtheora-dev libavformat-dev libavcodec-dev
  libavutil-dev libswscale-dev libgdal-dev libgl2ps-dev libglew-dev
  libnetcdf-dev libtiff-dev libdouble-conversion-dev
  # ParaView's VTK config asks for Qt5OpenGL; VTK's FreeType module finds
  # freetype's -dev files; ParaView's plugin macros run xmllint; Qt5X11Extras'
  # config names libXcomposite. None is a Depends of the packages above.
  libqt5opengl5-dev libfreetype-dev libxml2-utils libxcomposite1
  # point-cloud algorithms and the comparison octree (runtime libraries only)
  libpcl-common1.13 libpcl-octree1.13 libpcl-kdtree1.13 libpcl-search1.13
  libpcl-features1.13 libeigen3-dev libflann-dev libboost-dev
  # image slices and picture output
  libopenimageio-dev openimageio-tools
  # DICOM series: image position, orientation and rescale through GDCM
  libgdcm-dev
  # Python tests, rendering without a display (xvfb-run needs xauth, which
  # xvfb only recommends)
  python3-pytest python3-numpy xvfb xauth
  # reliability (issue 8): the ASan+UBSan build and the libFuzzer targets
  # (clang with its sanitizer and fuzzer runtimes; OpenMP for clang)
  clang-14 libclang-rt-14-dev libomp-14-dev
  # what CMake finds beside clang and records in build-asan's cache (llvm-ar,
  # llvm-ranlib, ld.lld): named, so a fresh machine configures the same way
  llvm-14 lld-14
  # reader benchmarks compare against pandas (pyarrow engine when present)
  python3-pandas
  # independent reference values for the DICOM tests; TIFF slices of every
  # pixel type for the slice reader's tests
  python3-pydicom python3-tifffile
  # make report: plots, and SSIM from an independent implementation
  python3-matplotlib python3-skimage
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"

if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

if [ ! -f .deps/pcl/usr/include/pcl-1.13/pcl/octree/octree_pointcloud.h ]; then
  echo "install-deps: unpacking PCL headers into .deps/pcl"
  rm -rf .deps/pcl .deps/pcl-deb && mkdir -p .deps/pcl .deps/pcl-deb
  (cd .deps/pcl-deb && apt-get download libpcl-dev >/dev/null)
  dpkg-deb -x .deps/pcl-deb/libpcl-dev_*.deb .deps/pcl
fi
