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
// points (wrong count, no positions, an index out of range).
void ValidateUpdate(const PositionsView& positions, std::size_t pointCount);

std::string NonFinitePointMessage(std::size_t index, const double p[3]);
std::string OutsideCubeMessage(std::size_t index, const double p[3]);
std::string OutOfMemoryMessage(const char* what, std::size_t bytesNeeded, std::size_t bytesFree);
}
