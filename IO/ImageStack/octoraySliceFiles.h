// Which files form a slice stack and in which order they are listed: an
// explicit list (in the order given), a printf-style pattern over a range
// of numbers, or every picture and DICOM file of a directory in natural
// order (octorayNaturalSort.h). DICOM slices are put in order later, by
// position (octoraySliceChecks.h). Also which files are DICOM, and the
// files' signature that makes the reader read again when one changes on
// disk. Private to the module; not wrapped.
#ifndef octoraySliceFiles_h
#define octoraySliceFiles_h

#include <string>
#include <vector>

namespace octoray
{
namespace slices
{
// Where the slices come from, as vtkSliceStackReader's properties say; the
// first that is set is used: names, pattern, directory.
struct SliceSource
{
  const std::vector<std::string>* Names = nullptr;
  const char* Pattern = nullptr;
  int Range[2] = { 0, 0 }; // the numbers the pattern is filled with, inclusive
  const char* Directory = nullptr;
};

// The slice files of source into files; false, with the reason in error,
// when there are none, one of a pattern is missing, or one is a directory.
bool ListSliceFiles(const SliceSource& source, std::vector<std::string>& files, std::string& error);

// A DICOM file: the extension .dcm, or "DICM" after the 128-byte preamble.
bool IsDICOMFile(const std::string& name);

// Names, inodes, sizes and modification times of the directory, the given
// names and the slices last read (a page "file#n" counts as its file).
std::string FilesSignature(const char* directory, const std::vector<std::string>& names,
  const std::vector<std::string>& slices);
} // namespace slices
} // namespace octoray

#endif
