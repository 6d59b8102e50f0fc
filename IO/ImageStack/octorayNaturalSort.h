// Natural order of file names: runs of digits compare by value, so that
// "slice2.png" comes before "slice10.png". Private to the module.
#ifndef octorayNaturalSort_h
#define octorayNaturalSort_h

#include <cctype>
#include <string>

namespace octoray
{
inline bool NaturalLess(const std::string& a, const std::string& b)
{
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size())
  {
    const bool da = std::isdigit(static_cast<unsigned char>(a[i])) != 0;
    const bool db = std::isdigit(static_cast<unsigned char>(b[j])) != 0;
    if (da && db)
    {
      size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie])))
        ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je])))
        ++je;
      // Compare by value without overflow: skip leading zeros, then length, then digits.
      size_t ia = i, jb = j;
      while (ia + 1 < ie && a[ia] == '0')
        ++ia;
      while (jb + 1 < je && b[jb] == '0')
        ++jb;
      if (ie - ia != je - jb)
        return ie - ia < je - jb;
      const int c = a.compare(ia, ie - ia, b, jb, je - jb);
      if (c != 0)
        return c < 0;
      // Equal values: fewer leading zeros first, for a total order.
      if (ie - i != je - j)
        return ie - i < je - j;
      i = ie;
      j = je;
    }
    else
    {
      if (a[i] != b[j])
        return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}
} // namespace octoray

#endif
