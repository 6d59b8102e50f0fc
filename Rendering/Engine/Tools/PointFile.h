// Particle text files for the engine's command-line tool and benchmarks,
// which build without VTK: read with the format's VTK-free core from
// IO/Particles (octorayParticleTextFormat.h), so that comments, a header
// line naming the columns, the layouts of 3, 4, 6 or 8 columns, the numbers
// and the messages for bad lines are vtkParticleTextReader's. Colours,
// scalars, reflectivity and refraction become the engine's arrays; other
// named columns are read and left out. Gzip-compressed files and PCD files
// are named and refused (the VTK readers read them).
#pragma once

#include "octorayPCDHeader.h"
#include "octorayParticleTextFormat.h"

#include <octoray/PointCloud.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
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
    std::error_code notAFolder;
    if (std::filesystem::is_directory(path, notAFolder))
    {
      throw Error(path + ": a folder, not a particle file (the VTK slice readers read folders of slices)");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in)
    {
      throw Error(path + ": cannot open the file");
    }
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    RefuseOtherFormats(path, text);
    const ptext::Prologue prologue = ptext::ParsePrologue(text.data(), text.size(), path);
    if (!prologue.Ok)
    {
      throw Error(prologue.Error);
    }
    PointFile f;
    std::vector<double> values(prologue.Columns.size());
    ptext::Problem problem;
    long long line = prologue.FirstDataLine;
    ptext::ForEachDataLine(text.data() + prologue.FirstData, text.data() + text.size(), line,
      [&](const char* lineStart, const char* q, const char* e) {
        if (!ptext::ParseFields(prologue, lineStart, q, e, values.data(), problem))
        {
          throw Error(ptext::LineMessage(path, line, lineStart, problem));
        }
        f.Add(prologue.Columns, values);
        return true;
      });
    return f;
  }

private:
  // A gzip file and PCL's PCD would fail as a bad layout or a binary
  // file: name them for what they are, as the VTK readers know them (a PCD
  // file is one whose header vtkPCDReader's parser reads).
  static void RefuseOtherFormats(const std::string& path, const std::string& text)
  {
    if (StartsGzip(text.data(), text.size()))
    {
      throw Error(path + ": gzip-compressed; the octoray tool reads plain text (gunzip it first; vtkParticleReader "
                         "reads it as it is)");
    }
    pcd::Header header;
    std::string notPcd;
    if (pcd::ParseHeader(text.data(), text.size(), path, header, notPcd))
    {
      throw Error(path + ": a PCD file; the octoray tool reads particle text files (vtkPCDReader reads PCD, in "
                         "Python and ParaView)");
    }
  }

  // One point from its columns' values, each where its column goes.
  void Add(const std::vector<ptext::Column>& columns, const std::vector<double>& values)
  {
    double position[3] = {}, colour[3] = {};
    bool hasColour = false;
    for (std::size_t c = 0; c < columns.size(); ++c)
    {
      const double v = values[c];
      switch (const ptext::Sink target = columns[c].Target)
      {
        case ptext::Sink::X:
        case ptext::Sink::Y:
        case ptext::Sink::Z:
          position[static_cast<int>(target) - static_cast<int>(ptext::Sink::X)] = v;
          break;
        case ptext::Sink::R:
        case ptext::Sink::G:
        case ptext::Sink::B:
          colour[static_cast<int>(target) - static_cast<int>(ptext::Sink::R)] = v;
          hasColour = true;
          break;
        case ptext::Sink::Scalar:
          scalar.push_back(static_cast<float>(v));
          break;
        case ptext::Sink::Reflectivity:
          reflectivity.push_back(static_cast<float>(v));
          break;
        case ptext::Sink::Refraction:
          refraction.push_back(static_cast<float>(v));
          break;
        case ptext::Sink::Extra:
          break;
      }
    }
    xyz.insert(xyz.end(), position, position + 3);
    if (hasColour)
    {
      for (double v : colour)
      {
        rgb.push_back(static_cast<std::uint8_t>(v + 0.5)); // 0-255: ParseFields checks the range
      }
    }
  }
};
}
