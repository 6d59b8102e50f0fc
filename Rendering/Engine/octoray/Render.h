// What a frame asks of the engine and what it gets back.
#pragma once

#include "Types.h"

#include <vector>

namespace octoray
{
// How a ray turns the voxels it meets into a colour.
enum class BlendMode
{
  Surface,   // the first occupied voxel (the thesis's first-hit rendering), shaded
  Composite, // front-to-back alpha through the transfer function, early termination
  Maximum,   // maximum intensity projection of the scalar
  Minimum,   // minimum intensity projection
  Average,   // length-weighted mean of the scalar along the ray
  Additive   // integral of the scalar along the ray
};

// How a surface hit is lit (BlendMode::Surface only).
enum class ShadeMode
{
  Flat,     // the voxel's colour as it is
  DepthCue, // darkened with distance across the octree's depth range
  Phong     // ambient + diffuse + specular from every light
};

struct Light
{
  // w = 0: directional, xyz points towards the light; w = 1: positional.
  double position[4] = { 0, 0, 1, 0 };
  float color[3] = { 1, 1, 1 };
  float intensity = 1.0f;
};

// A colour and opacity lookup over a scalar range (VTK's colour transfer
// function and scalar opacity, sampled by the VTK layer).
struct TransferFunction
{
  float range[2] = { 0.0f, 1.0f };
  std::vector<Rgba> table; // non-premultiplied; empty = node colours, opaque
};

// The most lights a frame takes (the kernels hold them in a fixed array).
constexpr int kMaxLights = 8;

// A clipping plane, as VTK's mappers take them (vtkAbstractMapper's
// clipping planes): the side the normal points to is kept,
// normal . (p - origin) >= 0; the rest of the scene is not there for any ray.
// A voxel the plane cuts is drawn up to the cut, a flat face lit by the
// plane's normal (RenderKernels.h's SurfaceNormal).
struct ClipPlane
{
  double origin[3] = { 0, 0, 0 };
  double normal[3] = { 0, 0, 1 };
};

// The most clipping planes a frame takes: six of a mapper's own and the six
// faces of its cropping box.
constexpr int kMaxClipPlanes = 12;

struct RenderSettings
{
  int width = 0, height = 0;
  // World <- normalised device coordinates: the inverse of VTK's
  // GetCompositeProjectionTransformMatrix(aspect, -1, 1), row-major.
  double inverseViewProjection[16] = {};

  BlendMode blend = BlendMode::Surface;
  ShadeMode shade = ShadeMode::Flat;
  float ambient = 0.1f, diffuse = 0.7f, specular = 0.2f, specularPower = 10.0f;
  float depthCue = 0.7f; // fraction of brightness lost at the far side
  // Lights in world coordinates, at most kMaxLights; none = a headlight at
  // the camera.
  std::vector<Light> lights;
  bool shadows = false;
  // Where the octree has no normals (its points had none), light and bend
  // rays by normals fitted to the voxels around each node
  // (NormalEstimation.h), made at the first such frame after a build or an
  // update and kept; off, by the six neighbours' occupancy gradient
  // (RenderKernels.h's SurfaceNormal).
  bool estimateNormals = false;
  // In world coordinates, at most kMaxClipPlanes; each normal non-zero.
  std::vector<ClipPlane> clipPlanes;
  int maxBounces = 2;          // reflections and refractions together
  float lodPixels = 0.0f;      // stop descending at voxels smaller than this many pixels; 0 = leaves
  float opacityUnitDistance = 1.0f / 256; // composite: opacity is per this length (unit cube)
  TransferFunction transfer;
  // Window depth ([0,1], OpenGL convention, row-major from the bottom row) of
  // opaque geometry already drawn; rays stop there. Empty = none.
  std::vector<float> depthBuffer;
  // CUDA: the same window depth already in the engine's device memory (an
  // OpenGL buffer mapped by CUDA-OpenGL interop), width x height values,
  // read in place instead of depthBuffer. Not for the CPU backend.
  const float* deviceDepthBuffer = nullptr;
  // CUDA: copy the picture to the host Image. Off, it stays in device memory
  // (Engine::LastDeviceImage) for a caller that draws it from there.
  bool copyToHost = true;
  // Colour as float (Image::rgba) or 8-bit (Image::rgba8, a quarter of the
  // bytes to copy and upload): the caller's choice.
  bool rgba8 = false;
};

// Throws Error naming what no frame can be drawn with: an empty viewport, a
// depth buffer of the wrong size, more than kMaxLights lights or
// kMaxClipPlanes planes, a plane without a normal, a shading number that is
// not finite, an empty transfer range. Every Render checks; a caller may
// check first (the VTK mapper, which then keeps its octree).
void CheckSettings(const RenderSettings& settings);

// Premultiplied RGBA and window depth (1 where nothing was hit), rows from
// the bottom, as OpenGL reads them back.
struct Image
{
  int width = 0, height = 0;
  std::vector<float> rgba;         // 4 floats a pixel (RenderSettings::rgba8 off)
  std::vector<std::uint8_t> rgba8; // 4 bytes a pixel, rounded from the floats (rgba8 on)
  std::vector<float> depth;
};

// A picture in device memory (Engine::LastDeviceImage): the same layout as
// Image, colour as 4 floats a pixel or, after an rgba8 frame, 4 bytes.
struct DeviceImage
{
  int width = 0, height = 0;
  int device = -1; // the CUDA device that holds it; -1: none (CPU backend)
  const float* rgba = nullptr;
  const std::uint8_t* rgba8 = nullptr;
  const float* depth = nullptr;
};

struct RenderStats
{
  double seconds = 0.0;     // the frame, up to the picture in the backend's memory
  double copySeconds = 0.0; // CUDA: the copy of the picture to the host
  // Of `seconds`: the normals estimated for this octree (RenderSettings::
  // estimateNormals) where this frame made them; 0 where it did not.
  double normalSeconds = 0.0;
  std::size_t primaryRays = 0;
  std::size_t secondaryRays = 0; // shadow, reflected and refracted
};
}
