// What the slices of a stack must have in common: one size and type (the
// message both kinds of slice give), and for DICOM one orientation and
// distinct positions, from which come their order and the slice spacing.
// Private to the module; not wrapped.
#ifndef octoraySliceChecks_h
#define octoraySliceChecks_h

#include "octoraySliceDicom.h"
#include "octoraySliceRead.h"

#include <string>
#include <vector>

namespace octoray
{
namespace slices
{
// "<what> '<name>' is <description> but slice '<first>' is <description>;
// all slices must have one size and type".
std::string MismatchMessage(const std::string& what, const std::string& name,
  const std::string& description, const std::string& firstName,
  const std::string& firstDescription);

// Sorts slices along their normal (the first slice's row x column
// direction) by image position: the file names say nothing about it. Fails
// when a slice has another orientation than the first, or two lie at the
// same position. spacing: the mean distance between neighbouring slices (a
// warning when the distances vary by more than 1 %), or for one slice its
// own spacing, or fallbackSpacing when it has none.
bool OrderDicomSlices(std::vector<DicomSlice>& slices, double fallbackSpacing, double normal[3],
  double& spacing, SliceRead& read);
} // namespace slices
} // namespace octoray

#endif
