#include "Octree.h"

namespace octoray
{
void HostOctree::Allocate(std::size_t nodes, unsigned attributeBits)
{
  attributes = attributeBits;
  key.resize(nodes);
  childMask.resize(nodes);
  firstChild.resize(nodes);
  parent.resize(nodes);
  pointCount.resize(nodes);
  color.resize(attributeBits & kHasColor ? nodes : 0);
  scalar.resize(attributeBits & kHasScalar ? nodes : 0);
  reflectivity.resize(attributeBits & kHasReflectivity ? nodes : 0);
  refraction.resize(attributeBits & kHasRefraction ? nodes : 0);
  normal.resize(attributeBits & kHasNormal ? nodes : 0);
}

OctreeView HostOctree::View()
{
  OctreeView v;
  v.depth = depth;
  v.nodeCount = static_cast<std::uint32_t>(key.size());
  for (std::size_t l = 0; l < levelBegin.size() && l < kMaxLevel + 2; ++l)
  {
    v.levelBegin[l] = levelBegin[l];
  }
  v.attributes = attributes;
  v.cube = cube;
  v.key = key.data();
  v.childMask = childMask.data();
  v.firstChild = firstChild.data();
  v.parent = parent.data();
  v.pointCount = pointCount.data();
  v.color = color.empty() ? nullptr : color.data();
  v.scalar = scalar.empty() ? nullptr : scalar.data();
  v.reflectivity = reflectivity.empty() ? nullptr : reflectivity.data();
  v.refraction = refraction.empty() ? nullptr : refraction.data();
  v.normal = normal.empty() ? nullptr : normal.data();
  return v;
}

const char* ToString(UpdateStats::Path path)
{
  switch (path)
  {
    case UpdateStats::Path::Unchanged:
      return "unchanged";
    case UpdateStats::Path::InPlace:
      return "in place";
    case UpdateStats::Path::Relevel:
      return "re-sorted";
    case UpdateStats::Path::NewCube:
      return "new cube";
  }
  return "?";
}
}
