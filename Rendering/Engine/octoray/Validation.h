// Input checks and error messages shared by the backends, so both report
// bad input in the same words.
#pragma once

#include "PointCloud.h"

#include <string>

namespace octoray
{
// Throws Error for a cloud the engine cannot take (no points, no or two
// position arrays, a colour that is neither RGB nor RGBA).
void ValidateCloud(const PointCloudView& points);

// Throws Error for a depth outside 0 (automatic) and 1..21.
void ValidateDepth(int depth);

// Throws Error for an update that does not fit an octree of `pointCount`
// points (wrong count, no positions, an index out of range or listed twice),
// or that comes when there is no octree (before any build, or after an
// update that failed part-way discarded it) or when its build released the
// points (BuildOptions::keepPoints off).
void ValidateUpdate(
  const PositionsView& positions, std::size_t pointCount, bool discardedByUpdate, bool pointsKept);

// Throws Error when there is no octree to draw (before any build, or after
// an update that failed part-way discarded it).
void ValidateRender(std::size_t pointCount, bool discardedByUpdate);

std::string NonFinitePointMessage(std::size_t index, const Vec3d& p);
std::string OutsideCubeMessage(std::size_t index, const Vec3d& p);
std::string OutOfMemoryMessage(const char* what, std::size_t bytesNeeded, std::size_t bytesFree);
// The error of an update that failed after its first write, which cost the
// octree (Engine::Update).
std::string DiscardedByUpdateMessage(const std::string& error);
}
