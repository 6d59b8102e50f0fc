// A minimal loader of whitespace- or comma-separated particle files for the
// engine's command-line tool (which must build without VTK). Columns: xyz,
// xyz + scalar, xyz + rgb, or the thesis's xyz rgb reflectivity refraction.
// The VTK reader (vtkParticleReader) is the full-featured one.
#pragma once

#include <octoray/PointCloud.h>

#include <cerrno>
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
    PointFile f;
    std::string line;
    std::size_t lineNumber = 0;
    std::size_t columns = 0;
    std::vector<double> values;
    while (std::getline(in, line))
    {
      ++lineNumber;
      for (char& c : line)
      {
        if (c == ',' || c == '\t' || c == '\r')
        {
          c = ' ';
        }
      }
      const std::size_t hash = line.find('#');
      if (hash != std::string::npos)
      {
        line.resize(hash);
      }
      values.clear();
      const char* s = line.c_str();
      while (true)
      {
        while (*s == ' ')
        {
          ++s;
        }
        if (!*s)
        {
          break;
        }
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(s, &end);
        if (end == s || (*end && *end != ' '))
        {
          throw Error(path + ":" + std::to_string(lineNumber) + ": column " + std::to_string(values.size() + 1) +
            " is not a number");
        }
        values.push_back(v);
        s = end;
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
          throw Error(path + ":" + std::to_string(lineNumber) + ": expected 3, 4, 6 or 8 columns, got " +
            std::to_string(columns));
        }
      }
      else if (values.size() != columns)
      {
        throw Error(path + ":" + std::to_string(lineNumber) + ": expected " + std::to_string(columns) +
          " columns like the first line, got " + std::to_string(values.size()));
      }
      f.xyz.insert(f.xyz.end(), values.begin(), values.begin() + 3);
      if (columns == 4)
      {
        f.scalar.push_back(static_cast<float>(values[3]));
      }
      if (columns >= 6)
      {
        for (int c = 3; c < 6; ++c)
        {
          const double v = values[c] < 0 ? 0 : (values[c] > 255 ? 255 : values[c]);
          f.rgb.push_back(static_cast<std::uint8_t>(v + 0.5));
        }
      }
      if (columns == 8)
      {
        f.reflectivity.push_back(static_cast<float>(values[6]));
        f.refraction.push_back(static_cast<float>(values[7]));
      }
    }
    if (f.xyz.empty())
    {
      throw Error(path + ": no points in the file");
    }
    return f;
  }
};
}
