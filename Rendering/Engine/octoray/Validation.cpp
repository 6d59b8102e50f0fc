#include "Validation.h"

#include <sstream>
#include <vector>

namespace octoray
{
void ValidateCloud(const PointCloudView& points)
{
  if (points.count == 0)
  {
    throw Error("octoray: cannot build an octree from 0 points");
  }
  if (!points.xyzFloat == !points.xyzDouble)
  {
    throw Error("octoray: give the point positions as exactly one of float or double xyz");
  }
  if (points.count > 0xFFFFFFFEu)
  {
    throw Error("octoray: " + std::to_string(points.count) + " points exceed the 32-bit point index");
  }
  if ((points.color8 || points.colorFloat) && points.colorComponents != 3 && points.colorComponents != 4)
  {
    throw Error("octoray: colours need 3 (RGB) or 4 (RGBA) components, got " +
      std::to_string(points.colorComponents));
  }
  if (points.color8 && points.colorFloat)
  {
    throw Error("octoray: give colours as exactly one of 8-bit or float");
  }
}

void ValidateDepth(int depth)
{
  if (depth < 0 || depth > kMaxLevel)
  {
    throw Error("octoray: depth must be 0 (automatic) or 1.." + std::to_string(kMaxLevel) + ", got " +
      std::to_string(depth));
  }
}

void ValidateUpdate(
  const PositionsView& positions, std::size_t pointCount, bool discardedByUpdate, bool pointsKept)
{
  if (pointCount == 0 && discardedByUpdate)
  {
    throw Error("octoray: update after a failed update discarded the octree; build again");
  }
  if (pointCount == 0)
  {
    throw Error("octoray: update before any build");
  }
  if (!pointsKept)
  {
    throw Error("octoray: update of an octree built without its points (BuildOptions::keepPoints off); "
                "build again from the new positions");
  }
  if (!positions.xyzFloat == !positions.xyzDouble)
  {
    throw Error("octoray: give the new positions as exactly one of float or double xyz");
  }
  if (!positions.indices && positions.count != pointCount)
  {
    throw Error("octoray: an update without indices needs all " + std::to_string(pointCount) +
      " positions, got " + std::to_string(positions.count));
  }
  if (positions.indices)
  {
    // A point listed twice would get whichever position a backend wrote
    // last: refused, as the GPU gives no order.
    std::vector<bool> listed(pointCount, false);
    for (std::size_t k = 0; k < positions.count; ++k)
    {
      const std::uint32_t i = positions.indices[k];
      if (i >= pointCount)
      {
        throw Error("octoray: update index " + std::to_string(k) + " names point " + std::to_string(i) +
          " of an octree of " + std::to_string(pointCount) + " points");
      }
      if (listed[i])
      {
        throw Error("octoray: update index " + std::to_string(k) + " names point " + std::to_string(i) +
          " a second time");
      }
      listed[i] = true;
    }
  }
}

void ValidateRender(std::size_t pointCount, bool discardedByUpdate)
{
  if (pointCount == 0)
  {
    throw Error(discardedByUpdate ? "octoray: render after a failed update discarded the octree; build again"
                                  : "octoray: render before any build");
  }
}

std::string NonFinitePointMessage(std::size_t index, const Vec3d& p)
{
  std::ostringstream s;
  s << "octoray: point " << index << " has a non-finite coordinate (" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

std::string OutsideCubeMessage(std::size_t index, const Vec3d& p)
{
  std::ostringstream s;
  s << "octoray: point " << index << " (" << p.x << ", " << p.y << ", " << p.z << ") lies outside the root cube";
  return s.str();
}

std::string DiscardedByUpdateMessage(const std::string& error)
{
  return error + " (the update had begun: the octree was discarded; build again)";
}

std::string OutOfMemoryMessage(const char* what, std::size_t bytesNeeded, std::size_t bytesFree)
{
  std::ostringstream s;
  s << "octoray: out of memory for " << what << ": needs " << bytesNeeded << " bytes, " << bytesFree
    << " bytes free";
  return s.str();
}
}
