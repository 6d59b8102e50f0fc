#include "Octree.h"

namespace octoray
{
OctreeView HostOctree::View()
{
  return MakeOctreeView(*this, depth, levelBegin.data(), levelBegin.size(), attributes, cube, scalarRange);
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
