// A minimal loader of whitespace- or comma-separated particle files for the
// engine's command-line tool (which must build without VTK). Columns: xyz,
// xyz + scalar, xyz + rgb, or the thesis's xyz rgb reflectivity refraction.
// The VTK reader (vtkParticleReader) is the full-featured one.
#pragma once

#include <octoray/PointCloud.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace octoray
{
struct PointFile
{
  std::vector<double> xyz;
  std::vector<std::uint8_t> rgb;
  std::vector<float> scalar, reflectivity, refraction;

  PointCloudView View() const
  {
    PointCloudView v;
    v.count = xyz.size() / 3;
    v.xyzDouble = xyz.data();
    if (!rgb.empty())
    {
      v.color8 = rgb.data();
      v.colorComponents = 3;
    }
    v.scalar = scalar.empty() ? nullptr : scalar.data();
    v.reflectivity = reflectivity.empty() ? nullptr : reflectivity.data();
    v.refraction = refraction.empty() ? nullptr : refraction.data();
    return v;
  }

  // Throws octoray::Error naming the file and line of the first bad line.
  static PointFile Load(const std::string& path)
  {
    std::ifstream in(path);
    if (!in)
    {
      throw Error(path + ": cannot open the file");
    }
    RefuseGzip(path, in);
    PointFile f;
    std::string line;
    std::size_t lineNumber = 0;
    std::size_t columns = 0; // the first line's, which every line must have
    std::vector<double> values;
    while (std::getline(in, line))
    {
      const std::string where = path + ":" + std::to_string(++lineNumber);
      const std::size_t bad = ParseLine(line, values);
      if (bad)
      {
        throw Error(where + (IsPcdHeader(line) ? kPcdHeader : ": column " + std::to_string(bad) + " is not a number"));
      }
      if (values.empty())
      {
        continue;
      }
      if (!columns)
      {
        columns = values.size();
        if (columns != 3 && columns != 4 && columns != 6 && columns != 8)
        {
          throw Error(where + ": expected 3, 4, 6 or 8 columns, got " + std::to_string(columns));
        }
      }
      else if (values.size() != columns)
      {
        throw Error(where + ": expected " + std::to_string(columns) + " columns like the first line, got " +
          std::to_string(values.size()));
      }
      f.Add(values);
    }
    if (f.xyz.empty())
    {
      throw Error(path + ": no points in the file");
    }
    return f;
  }

private:
  static constexpr const char* kPcdHeader =
    ": a PCD file's header; the octoray tool reads particle text files (vtkPCDReader reads PCD, in Python and "
    "ParaView)";

  // A gzip file would fail on its first line as "not a number".
  static void RefuseGzip(const std::string& path, std::ifstream& in)
  {
    const int first = in.get(), second = in.get();
    if (first == 0x1f && second == 0x8b)
    {
      throw Error(path + ": gzip-compressed; the octoray tool reads plain text (gunzip it first; vtkParticleReader "
                         "reads it as it is)");
    }
    in.clear();
    in.seekg(0);
  }

  // The header lines PCL's PCD files begin with (after comments).
  static bool IsPcdHeader(const std::string& line)
  {
    return line.rfind("VERSION", 0) == 0 || line.rfind("FIELDS", 0) == 0;
  }

  // The numbers of one line into `values` (commas, tabs and spaces apart;
  // '#' starts a comment); 0, or the column of the first that is not one.
  static std::size_t ParseLine(const std::string& text, std::vector<double>& values)
  {
    std::string line = text.substr(0, text.find('#'));
    for (char& c : line)
    {
      if (c == ',' || c == '\t' || c == '\r')
      {
        c = ' ';
      }
    }
    values.clear();
    for (const char* s = line.c_str();;)
    {
      while (*s == ' ')
      {
        ++s;
      }
      if (!*s)
      {
        return 0;
      }
      char* end = nullptr;
      const double v = std::strtod(s, &end);
      if (end == s || (*end && *end != ' '))
      {
        return values.size() + 1;
      }
      values.push_back(v);
      s = end;
    }
  }

  // One point of 3, 4, 6 or 8 columns.
  void Add(const std::vector<double>& values)
  {
    xyz.insert(xyz.end(), values.begin(), values.begin() + 3);
    if (values.size() == 4)
    {
      scalar.push_back(static_cast<float>(values[3]));
    }
    if (values.size() >= 6)
    {
      for (int c = 3; c < 6; ++c)
      {
        const double v = values[c] < 0 ? 0 : (values[c] > 255 ? 255 : values[c]);
        rgb.push_back(static_cast<std::uint8_t>(v + 0.5));
      }
    }
    if (values.size() == 8)
    {
      reflectivity.push_back(static_cast<float>(values[6]));
      refraction.push_back(static_cast<float>(values[7]));
    }
  }
};
}
