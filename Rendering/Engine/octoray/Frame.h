// Host-side preparation of a frame: RenderSettings in world coordinates ->
// FrameConstants in the octree's unit cube. Shared by both backends.
#pragma once

#include "RenderKernels.h"
#include "RootCube.h"

#include <array>

namespace octoray
{
// Throws Error for settings that cannot make a picture (CheckSettings, and a
// singular camera matrix).
// Table and depth-buffer pointers are the host vectors of `settings`; a
// device backend replaces them with device copies.
// A tree whose nodes neither reflect nor refract gets a frame that casts no
// mirror or refracted rays, whatever the bounce limit.
FrameConstants MakeFrame(const RenderSettings& settings, const OctreeView& tree);

// Inverse of a row-major 4x4 matrix; false when it is singular.
bool Invert4x4(const double m[16], double inverse[16]);

// The row-major view-projection matrix of an OpenGL-style camera, as VTK's
// composite projection transform gives it: at `eye`, looking at `target`,
// with `up`, a vertical field of view of fovyDegrees (with `parallel`, a
// viewport half parallelScale high) and the clipping range [zNear, zFar].
// The command-line tool, the benchmarks and the tests set their cameras
// with it, so that they drive the engine as the VTK layer does.
std::array<double, 16> ViewProjection(const double eye[3], const double target[3], const double up[3],
  double fovyDegrees, double aspect, double zNear, double zFar, bool parallel = false, double parallelScale = 1.0);
}
