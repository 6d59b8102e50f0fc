#pragma once

#include "CpuDevice.h"
#include "OctreeEngine.h"

namespace octoray
{
// The CPU backend: the reference for the CUDA one and the fallback where no
// GPU is usable.
class CpuEngine final : public OctreeEngine<CpuDevice>
{
public:
  Backend Kind() const override { return Backend::CPU; }
  std::string Description() const override;
  RenderStats Render(const RenderSettings& settings, Image& image) override;
  void SetThreadCount(int threads) override;
  int ThreadCount() const { return Dev.threads; }
};
}
