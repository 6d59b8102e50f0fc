// Test hooks that make the CUDA backend fail the way a GPU can, so that the
// error paths are exercised by tests rather than trusted (issue 8). The
// memory budget (Engine::SetMemoryBudget) covers out-of-memory; this covers
// kernel launches.
#pragma once

#include <string>

namespace octoray
{
// The next launch of the CUDA kernel named `kernel` (e.g. "RenderKernel") is
// made with an empty grid, which the CUDA runtime refuses with "invalid
// configuration argument": the engine's real check of that launch reports it.
// One shot; an empty name cancels. No effect on the CPU backend.
void InjectCudaLaunchFailure(const std::string& kernel);

// For the CUDA backend: true, once, for the kernel named above.
bool TakeInjectedLaunchFailure(const char* kernel);
}
