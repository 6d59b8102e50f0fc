// DICOM slices through GDCM, which, unlike OpenImageIO's DICOM plugin,
// reports each slice's position and orientation. Every file's structure is
// checked before GDCM parses it (octorayDicomCheck.h): Debian's GDCM 3.0
// aborts the process on some damaged files. Private to the module; not
// wrapped.
#ifndef octoraySliceDicom_h
#define octoraySliceDicom_h

#include "octoraySliceRead.h"

#include <string>
#include <vector>

class vtkImageData;

namespace octoray
{
namespace slices
{
// One DICOM file of a stack: its pixels and where it lies.
struct DicomSlice
{
  std::string File;
  unsigned int Width = 0, Height = 0;
  int Samples = 0;                // 1 (grey) or 3 (RGB)
  unsigned int Frames = 1;        // a single file may hold a whole stack
  std::vector<float> Values;      // grey: stored value * slope + intercept
  std::vector<unsigned char> RGB; // or 8-bit colour
  double Origin[3], Row[3], Col[3], Spacing[3];
  bool HasOrigin = false; // Image Position (Patient), (0020,0032): GDCM gives 0 where it is missing
  std::string Series;     // Series Instance UID, (0020,000E); "" where missing
  double Position = 0;    // along the stack's normal (octoraySliceChecks.h)
};

// The stack's dimensions from the first file's header alone (reading stops
// before the pixel data): its size, and the number of files, or of frames
// of a single file.
bool DicomStackDimensions(const std::vector<std::string>& files, int dims[3], std::string& error);

// Every file, in order along the slice normal, as the slices of image:
// float values rescaled by the modality LUT (e.g. CT numbers in HU), or
// 8-bit RGB. With useMetadata, the image's spacing, origin and direction
// are the series' (the slice spacing from the slices' positions; for a
// single slice its own, or fallbackSliceSpacing); without, they are left
// alone. Progress up to 0.8.
bool ReadDicomStack(const std::vector<std::string>& files, double fallbackSliceSpacing,
  bool useMetadata, vtkImageData* image, SliceRead& read);
} // namespace slices
} // namespace octoray

#endif
