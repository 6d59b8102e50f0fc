// The engine's render modes by name, as the benchmarks report them and the
// tests walk through them: each blend mode, and the surface shadings with
// and without shadows and mirror bounces.
#pragma once

#include "Render.h"

namespace octoray
{
struct NamedRenderMode
{
  const char* name;
  BlendMode blend;
  ShadeMode shade;
  bool shadows;
  int bounces;

  // Sets the mode's blend, shading, shadows and bounce limit.
  void ApplyTo(RenderSettings& settings) const
  {
    settings.blend = blend;
    settings.shade = shade;
    settings.shadows = shadows;
    settings.maxBounces = bounces;
  }
};

inline constexpr NamedRenderMode kRenderModes[] = {
  { "surface-flat", BlendMode::Surface, ShadeMode::Flat, false, 0 },
  { "depth-cue", BlendMode::Surface, ShadeMode::DepthCue, false, 0 },
  { "phong", BlendMode::Surface, ShadeMode::Phong, false, 0 },
  { "phong-shadows", BlendMode::Surface, ShadeMode::Phong, true, 0 },
  { "reflections", BlendMode::Surface, ShadeMode::Phong, true, 2 },
  { "composite", BlendMode::Composite, ShadeMode::Flat, false, 0 },
  { "mip", BlendMode::Maximum, ShadeMode::Flat, false, 0 },
  { "minip", BlendMode::Minimum, ShadeMode::Flat, false, 0 },
  { "average", BlendMode::Average, ShadeMode::Flat, false, 0 },
  { "additive", BlendMode::Additive, ShadeMode::Flat, false, 0 },
};
}
