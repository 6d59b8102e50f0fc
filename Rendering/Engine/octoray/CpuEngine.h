#pragma once

#include "Engine.h"
#include "PointArrays.h"

#include <vector>

namespace octoray
{
class CpuEngine final : public Engine
{
public:
  CpuEngine();

  Backend Kind() const override { return Backend::CPU; }
  std::string Description() const override;
  BuildStats Build(const PointCloudView& points, const BuildOptions& options) override;
  UpdateStats Update(const PositionsView& positions) override;
  RenderStats Render(const RenderSettings& settings, Image& image) override;
  std::size_t PointCount() const override { return Count; }
  void CopyToHost(HostOctree& out) const override;
  MemoryReport Memory() const override;
  void SetThreadCount(int threads) override;

  // The octree in place, for the CPU renderer.
  OctreeView View() { return Tree.View(); }
  int ThreadCount() const { return Threads; }

private:
  PointArraysView PointsView() const;
  // Keys, sort and levels from the stored points, inside `cube`.
  BuildStats BuildFromPointState(const RootCube& cube, int requestedDepth);
  int ChooseDepth() const;
  // Node arrays from the sorted leaf keys.
  void BuildLevels(const RootCube& cube, int depth);

  int Threads;

  // The points, as given to Build (colours widened to RGBA, normals unit).
  std::size_t Count = 0;
  unsigned Attributes = 0;
  std::vector<float> XyzFloat;
  std::vector<double> XyzDouble;
  std::vector<std::uint8_t> Color8;
  std::vector<Rgba> ColorFloat;
  std::vector<float> Scalar, Reflectivity, Refraction;
  std::vector<Vec3f> Normal;
  std::vector<std::uint64_t> PointKey; // full-depth key of each point

  // (leaf key, point) sorted by key, and the radix sort's scratch; kept so
  // that later builds and updates reuse the allocations.
  std::vector<std::uint64_t> SortedKey, ScratchKey;
  std::vector<std::uint32_t> SortedIndex, ScratchIndex;

  HostOctree Tree;
};
}
