# The third-party libraries of the optional VTK modules, found before the
# module scan: a module whose library is missing is hidden (its vtk.module
# CONDITION) and the build says so, as VTK does for IO/PDAL or IO/GDAL. On
# Debian every one is installed by scripts/install-deps.sh; a machine with
# only VTK (the GPU machine) builds the mapper and the particle reader.

# ---- OpenImageIO and GDCM: octoray::IOImageStack. Debian's
# OpenImageIO::OpenImageIO target names /usr/include/opencv4 (OpenCV is not
# otherwise needed), and GDCM's CMake package also describes Debian's VTK 9.1
# bindings, which must not come near ParaView's VTK: both are found directly.
find_path(OCTORAY_OIIO_INCLUDE_DIR OpenImageIO/imageio.h)
find_library(OCTORAY_OIIO_LIBRARY OpenImageIO)
find_library(OCTORAY_OIIO_UTIL_LIBRARY OpenImageIO_Util)
find_path(OCTORAY_GDCM_INCLUDE_DIR gdcmImageReader.h PATH_SUFFIXES gdcm-3.0)
find_library(OCTORAY_GDCM_MSFF_LIBRARY gdcmMSFF)
find_library(OCTORAY_GDCM_DSED_LIBRARY gdcmDSED)
find_library(OCTORAY_GDCM_COMMON_LIBRARY gdcmCommon)
set(OCTORAY_HAVE_IMAGE_LIBRARIES ON)
foreach(var IN ITEMS OIIO_INCLUDE_DIR OIIO_LIBRARY OIIO_UTIL_LIBRARY GDCM_INCLUDE_DIR
    GDCM_MSFF_LIBRARY GDCM_DSED_LIBRARY GDCM_COMMON_LIBRARY)
  if(NOT OCTORAY_${var})
    set(OCTORAY_HAVE_IMAGE_LIBRARIES OFF)
  endif()
endforeach()
if(NOT OCTORAY_HAVE_IMAGE_LIBRARIES)
  message(STATUS "octoray: OpenImageIO or GDCM not found: octoray::IOImageStack "
    "(slice stacks, DICOM, depth maps) is skipped")
endif()

# ---- PCL: octoray::FiltersPCL (normals with NormalEstimationOMP and a k-d
# tree). libpcl-dev cannot be installed beside ParaView (it pulls Debian's
# VTK 9.1), so scripts/install-deps.sh unpacks its headers into .deps/pcl
# and the versioned runtime libraries are linked by full path. No PCL
# component that links VTK (io, visualization) is used.
set(OCTORAY_PCL_INCLUDE_DIR "${PROJECT_SOURCE_DIR}/.deps/pcl/usr/include/pcl-1.13"
  CACHE PATH "PCL 1.13 headers (unpacked from libpcl-dev by scripts/install-deps.sh)")
set(OCTORAY_HAVE_PCL OFF)
if(EXISTS "${OCTORAY_PCL_INCLUDE_DIR}/pcl/features/normal_3d_omp.h")
  set(OCTORAY_PCL_LIBRARIES)
  set(OCTORAY_HAVE_PCL ON)
  foreach(component IN ITEMS features search kdtree common)
    find_library(OCTORAY_PCL_${component}_LIBRARY NAMES libpcl_${component}.so.1.13)
    if(NOT OCTORAY_PCL_${component}_LIBRARY)
      set(OCTORAY_HAVE_PCL OFF)
    endif()
    list(APPEND OCTORAY_PCL_LIBRARIES "${OCTORAY_PCL_${component}_LIBRARY}")
  endforeach()
  find_package(Eigen3 QUIET NO_MODULE)
  find_path(OCTORAY_FLANN_INCLUDE_DIR flann/flann.hpp)
  find_package(OpenMP QUIET COMPONENTS CXX)
  if(NOT Eigen3_FOUND OR NOT OCTORAY_FLANN_INCLUDE_DIR OR NOT OpenMP_CXX_FOUND)
    set(OCTORAY_HAVE_PCL OFF)
  endif()
endif()
if(NOT OCTORAY_HAVE_PCL)
  message(STATUS "octoray: PCL 1.13 (headers in ${OCTORAY_PCL_INCLUDE_DIR}, runtime libraries, "
    "Eigen, FLANN, OpenMP) not found: octoray::FiltersPCL (normals) is skipped")
endif()
