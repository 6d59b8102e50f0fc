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
// The farthest a slice lies from where evenly spaced slices put it.
double MisplacedBy(const std::vector<DicomSlice>& slices, double spacing)
{
  double worst = 0.0;
  for (size_t k = 0; k < slices.size(); ++k)
  {
    worst = std::max(worst, std::abs(slices[k].Position - slices.front().Position - k * spacing));
  }
  return worst;
}

// The distance between neighbouring slices, once they are in order: the
// mean (a warning naming the slices around the widest and the narrowest
// gap when the gaps vary: a missing slice leaves a gap of two), or false
// when two coincide.
bool SliceSpacing(const std::vector<DicomSlice>& slices, double& spacing, SliceRead& read)
{
  size_t widest = 1, narrowest = 1;
  auto gap = [&](size_t k) { return slices[k].Position - slices[k - 1].Position; };
  for (size_t k = 1; k < slices.size(); ++k)
  {
    if (gap(k) < 1e-6)
    {
      return read.Fail("DICOM slices '" + slices[k - 1].File + "' and '" + slices[k].File +
        "' are at the same position");
    }
    widest = gap(k) > gap(widest) ? k : widest;
    narrowest = gap(k) < gap(narrowest) ? k : narrowest;
  }
  spacing = (slices.back().Position - slices.front().Position) / (slices.size() - 1);
  if (gap(widest) - gap(narrowest) > 0.01 * spacing)
  {
    std::ostringstream warning;
    warning << "DICOM slice spacing varies from " << gap(narrowest) << " (between '" << slices[narrowest - 1].File
            << "' and '" << slices[narrowest].File << "') to " << gap(widest) << " (between '"
            << slices[widest - 1].File << "' and '" << slices[widest].File
            << "': a slice missing there?); the volume uses the mean, " << spacing
            << ", which puts slices up to " << MisplacedBy(slices, spacing) << " from their positions";
    read.Warn(warning.str());
  }
  return true;
}

// What every slice of a series shares with the first: the series, a
// position (without which its place in the stack is unknown; GDCM puts it
// at 0) and the pixel spacing.
bool SameSeries(const std::vector<DicomSlice>& slices, SliceRead& read)
{
  const DicomSlice& s0 = slices[0];
  for (const DicomSlice& s : slices)
  {
    if (s.Series != s0.Series)
    {
      return read.Fail("DICOM slices '" + s0.File + "' and '" + s.File + "' belong to two series (Series Instance UID '" +
        s0.Series + "' and '" + s.Series + "'); a stack is one series: give the reader the files of one");
    }
    if (!s.HasOrigin && slices.size() > 1)
    {
      return read.Fail("DICOM slice '" + s.File +
        "' has no Image Position (Patient) (0020,0032), so its place in the stack is unknown");
    }
    if (std::abs(s.Spacing[0] - s0.Spacing[0]) > 1e-4 * s0.Spacing[0] ||
      std::abs(s.Spacing[1] - s0.Spacing[1]) > 1e-4 * s0.Spacing[1])
    {
      std::ostringstream text;
      text << "DICOM slice '" << s.File << "' has a pixel spacing of " << s.Spacing[0] << " x " << s.Spacing[1]
           << " but slice '" << s0.File << "' has " << s0.Spacing[0] << " x " << s0.Spacing[1]
           << "; a stack needs one pixel spacing";
      return read.Fail(text.str());
    }
  }
  return true;
}
} // namespace

//------------------------------------------------------------------------------
bool OrderDicomSlices(std::vector<DicomSlice>& slices, double fallbackSpacing, double normal[3],
  double& spacing, SliceRead& read)
{
  if (!SameSeries(slices, read))
  {
    return false;
  }
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
