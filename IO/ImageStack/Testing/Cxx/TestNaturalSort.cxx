// The natural order in which vtkSliceStackReader lists a directory's
// slices (octorayNaturalSort.h): numbers by value, leading zeros and
// numbers longer than 64 bits included.
#include "octorayNaturalSort.h"
#include "octorayTestCheck.h"

#include <algorithm>
#include <string>
#include <vector>

int TestNaturalSort(int, char*[])
{
  std::vector<std::string> names = { "s10.png", "s2.png", "s1.png", "s02.png",
    "s100000000000000000000.png", "s99999999999999999999.png", "a.png", "s.png" };
  std::sort(names.begin(), names.end(), octoray::NaturalLess);
  const std::vector<std::string> expected = { "a.png", "s.png", "s1.png", "s2.png", "s02.png",
    "s10.png", "s99999999999999999999.png", "s100000000000000000000.png" };
  CHECK(names == expected);
  return octoray_test::Result();
}
