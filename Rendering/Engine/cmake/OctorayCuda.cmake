# Decides whether the CUDA backend is built, and enables CUDA. Included from
# the directory scope that adds the engine and its benchmarks (the top level,
# or Rendering/Engine on its own), since a language enabled in a
# subdirectory is not visible to its siblings.
#   OCTORAY_ENABLE_CUDA: AUTO (when nvcc is found), ON (fail without), OFF.
set(OCTORAY_ENABLE_CUDA AUTO CACHE STRING "Build the CUDA backend: AUTO, ON or OFF")
set_property(CACHE OCTORAY_ENABLE_CUDA PROPERTY STRINGS AUTO ON OFF)
set(OCTORAY_HAVE_CUDA OFF)
if(NOT OCTORAY_ENABLE_CUDA STREQUAL "OFF")
  include(CheckLanguage)
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      # Hopper machine code, plus PTX that newer and older (>= Turing) GPUs
      # compile at load time.
      set(CMAKE_CUDA_ARCHITECTURES "90-real;75-virtual")
    endif()
    enable_language(CUDA)
    set(OCTORAY_HAVE_CUDA ON)
    # The options of nvcc for code that runs the build driver's loops (the
    # engine, and the tests of its CUDA device). --fmad=false: no fused
    # multiply-add contraction, so that device float arithmetic rounds
    # exactly like the CPU backend's and the two backends make the same
    # pictures (the CPU backend is the reference in tests).
    # --extended-lambda: the loops of the shared build driver are lambdas
    # that run on the GPU (OCTORAY_LAMBDA, Config.h).
    set(OCTORAY_CUDA_OPTIONS --expt-relaxed-constexpr --extended-lambda -lineinfo --fmad=false)
  elseif(OCTORAY_ENABLE_CUDA STREQUAL "ON")
    message(FATAL_ERROR "OCTORAY_ENABLE_CUDA=ON but no CUDA compiler was found")
  endif()
endif()
message(STATUS "octoray: CUDA backend ${OCTORAY_HAVE_CUDA}")
set(OCTORAY_CUDA_CONFIGURED ON)
