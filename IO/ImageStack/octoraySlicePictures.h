// Picture slices through OpenImageIO: PNG, TIFF (one slice per page), JPEG,
// BMP, EXR, ... with 8- or 16-bit grey, grey + alpha, RGB or RGBA; other
// pixel types are read as float. Private to the module; not wrapped.
#ifndef octoraySlicePictures_h
#define octoraySlicePictures_h

#include "octoraySliceRead.h"

#include <string>
#include <vector>

class vtkImageData;

namespace octoray
{
namespace slices
{
// The stack's dimensions from the headers alone: the first picture's size,
// and the pages of all pictures.
bool PictureStackDimensions(const std::vector<std::string>& files, int dims[3], std::string& error);

// Every page of files, in order, as the slices of image (its dimensions and
// scalars "Scalars" of the pictures' type; not its spacing or origin), rows
// flipped so that j grows upwards as in VTK's own image readers. Progress
// up to 0.8.
bool ReadPictureStack(const std::vector<std::string>& files, vtkImageData* image, SliceRead& read);
} // namespace slices
} // namespace octoray

#endif
