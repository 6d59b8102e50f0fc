// What reading the slices of a stack reports back to vtkSliceStackReader:
// the slice files in the order they were stacked, the first error, and, as
// they happen, progress and warnings. The parts of the read
// (octoraySlicePictures.h, octoraySliceDicom.h) say what failed; the reader
// reports it as VTK errors are reported. Private to the module; not wrapped.
#ifndef octoraySliceRead_h
#define octoraySliceRead_h

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace octoray
{
namespace slices
{
struct SliceRead
{
  // Progress of the whole update (0..1) and warnings, reported by the
  // reader as VTK reports them (UpdateProgress, vtkWarningMacro).
  std::function<void(double)> Progress = [](double) {};
  std::function<void(const std::string&)> Warn = [](const std::string&) {};
  // In stack order; a page of a multi-page file after the first as "file#page".
  std::vector<std::string> SliceFiles;
  std::string Error;

  bool Fail(std::string message)
  {
    this->Error = std::move(message);
    return false;
  }
};
} // namespace slices
} // namespace octoray

#endif
