#include "octoraySliceChecks.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace octoray
{
namespace slices
{
//------------------------------------------------------------------------------
std::string MismatchMessage(const std::string& what, const std::string& name,
  const std::string& description, const std::string& firstName,
  const std::string& firstDescription)
{
  return what + " '" + name + "' is " + description + " but slice '" + firstName + "' is " +
    firstDescription + "; all slices must have one size and type";
}

namespace
{
// The distance between neighbouring slices, once they are in order: the
// mean (a warning when the gaps vary), or false when two coincide.
bool SliceSpacing(const std::vector<DicomSlice>& slices, double& spacing, SliceRead& read)
{
  double minGap = HUGE_VAL, maxGap = 0;
  for (size_t k = 1; k < slices.size(); ++k)
  {
    const double gap = slices[k].Position - slices[k - 1].Position;
    minGap = std::min(minGap, gap);
    maxGap = std::max(maxGap, gap);
    if (gap < 1e-6)
    {
      return read.Fail("DICOM slices '" + slices[k - 1].File + "' and '" + slices[k].File +
        "' are at the same position");
    }
  }
  spacing = (slices.back().Position - slices.front().Position) / (slices.size() - 1);
  if (maxGap - minGap > 0.01 * spacing)
  {
    std::ostringstream warning;
    warning << "DICOM slice spacing varies from " << minGap << " to " << maxGap
            << "; the volume uses the mean, " << spacing;
    read.Warn(warning.str());
  }
  return true;
}
} // namespace

//------------------------------------------------------------------------------
bool OrderDicomSlices(std::vector<DicomSlice>& slices, double fallbackSpacing, double normal[3],
  double& spacing, SliceRead& read)
{
  const DicomSlice& s0 = slices[0];
  normal[0] = s0.Row[1] * s0.Col[2] - s0.Row[2] * s0.Col[1];
  normal[1] = s0.Row[2] * s0.Col[0] - s0.Row[0] * s0.Col[2];
  normal[2] = s0.Row[0] * s0.Col[1] - s0.Row[1] * s0.Col[0];
  for (auto& s : slices)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (std::abs(s.Row[a] - s0.Row[a]) > 1e-4 || std::abs(s.Col[a] - s0.Col[a]) > 1e-4)
      {
        return read.Fail("DICOM slice '" + s.File + "' has another orientation than slice '" +
          s0.File + "'; a stack needs parallel slices");
      }
    }
    s.Position = s.Origin[0] * normal[0] + s.Origin[1] * normal[1] + s.Origin[2] * normal[2];
  }
  std::stable_sort(slices.begin(), slices.end(),
    [](const DicomSlice& a, const DicomSlice& b) { return a.Position < b.Position; });
  if (slices.size() == 1)
  {
    spacing = slices[0].Spacing[2] > 0 ? slices[0].Spacing[2] : fallbackSpacing;
    return true;
  }
  return SliceSpacing(slices, spacing, read);
}
} // namespace slices
} // namespace octoray
