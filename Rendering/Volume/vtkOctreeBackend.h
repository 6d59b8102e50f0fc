/**
 * @class   vtkOctreeBackend
 * @brief   which octree engine a vtkOctreeVolumeMapper draws with, and the
 *          fall back from CUDA to the CPU
 *
 * A private helper of vtkOctreeVolumeMapper (not wrapped, not installed).
 * Acquire() makes the engine of the requested backend: AUTO takes CUDA where
 * a device is usable; a CUDA that cannot be had, or that failed before,
 * gives the CPU engine. Failed() is called with the error of any engine
 * call: a CUDA failure replaces the engine by a CPU one for good, a CPU
 * failure is final. Both say what happened as a Status and leave the words
 * in Message() for the mapper to warn or err with, once.
 */
#ifndef vtkOctreeBackend_h
#define vtkOctreeBackend_h

#include <memory> // for std::unique_ptr
#include <string> // for std::string

namespace octoray
{
class Engine;
}

class vtkOctreeBackend
{
public:
  enum class Status
  {
    Ready,         // the engine is the one asked for (or AUTO's choice)
    SwitchedToCPU, // CUDA could not be had or failed: a CPU engine took over (warn)
    KeptCPU,       // CUDA was asked for but cannot be had: the CPU engine drawing stays, octree and all (warn)
    Failed         // no engine at all, or the CPU engine failed (error)
  };

  vtkOctreeBackend();
  ~vtkOctreeBackend();

  /**
   * Ensures an engine for `requested` (vtkOctreeVolumeMapper::Backend) on
   * CUDA device `cudaDevice` (-1: chosen by the process's rank on its host,
   * DeviceChoice.h). A new engine holds no octree.
   */
  Status Acquire(int requested, int cudaDevice);

  /**
   * After an engine call (`what`: "build", "update", "render") threw
   * `error`: CUDA gives way to the CPU, the CPU fails.
   */
  Status Failed(const char* what, const std::string& error);

  octoray::Engine* Engine() const { return this->Current.get(); }
  int Kind() const { return this->Backend; } // BACKEND_CUDA, BACKEND_CPU, or -1
  int CudaDevice() const { return this->Device; }
  const std::string& Description() const { return this->EngineDescription; }
  const std::string& Message() const { return this->LastMessage; }

  /**
   * Bumped whenever the engine is replaced: an octree built on the old one
   * is gone.
   */
  unsigned long Generation() const { return this->Replacements; }

private:
  void Make(int backend, int cudaDevice); // throws when the engine cannot be had
  Status ToCPU(const std::string& why);

  std::unique_ptr<octoray::Engine> Current;
  int Backend = -1;
  int Device = -1;
  bool CudaFailed = false; // a CUDA failure sends the mapper to the CPU for good
  unsigned long Replacements = 0;
  std::string EngineDescription;
  std::string LastMessage;
};

#endif
// VTK-HeaderTest-Exclude: vtkOctreeBackend.h
