#include "octoraySliceFiles.h"

#include "octorayNaturalSort.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include <sys/stat.h>

namespace fs = std::filesystem;

namespace octoray
{
namespace slices
{
namespace
{
std::string Lower(std::string s)
{
  for (char& c : s)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return s;
}

// DICOM Part 10 files carry "DICM" after a 128-byte preamble.
bool HasDICMMarker(const std::string& name)
{
  std::ifstream f(name, std::ios::binary);
  char buf[132];
  if (!f.read(buf, sizeof(buf)))
  {
    return false;
  }
  return std::memcmp(buf + 128, "DICM", 4) == 0;
}

bool IsPictureExtension(const std::string& name)
{
  static const char* known[] = { ".png", ".tif", ".tiff", ".jpg", ".jpeg", ".bmp", ".exr",
    ".pgm", ".ppm", ".pnm", ".tga", ".hdr", ".gif", ".webp", ".jp2", ".sgi", ".rgb" };
  const std::string ext = Lower(fs::path(name).extension().string());
  return std::find(std::begin(known), std::end(known), ext) != std::end(known);
}

// The conversions a file pattern may hold: one integer, as in slice_%03d.png;
// %% for a percent sign. Anything else would make snprintf read an
// argument it is not given.
bool CheckPattern(const std::string& pattern, std::string& error)
{
  static const std::regex conversion("%[-+ 0#]*[0-9]*[diuxXo]");
  int integers = 0;
  for (std::size_t at = pattern.find('%'); at != std::string::npos; at = pattern.find('%', at))
  {
    std::smatch found;
    const std::string rest = pattern.substr(at);
    if (rest.compare(0, 2, "%%") == 0)
    {
      at += 2;
      continue;
    }
    if (!std::regex_search(rest, found, conversion, std::regex_constants::match_continuous))
    {
      const std::size_t end = rest.find_first_of("diouxXcsfFeEgGaApn", 1);
      error = "the file pattern '" + pattern + "' has '" + rest.substr(0, end == std::string::npos ? end : end + 1) +
        "'; it takes one integer conversion, such as %d or %03d (%% for a percent sign)";
      return false;
    }
    ++integers;
    at += found.length();
  }
  if (integers != 1)
  {
    error = "the file pattern '" + pattern + "' has " + std::to_string(integers) +
      " integer conversions; it takes one, such as %d or %03d, for the slice number";
    return false;
  }
  return true;
}

// The pattern filled with each number of the range: every file must exist.
bool FromPattern(
  const char* pattern, const int range[2], std::vector<std::string>& files, std::string& error)
{
  if (!CheckPattern(pattern, error))
  {
    return false;
  }
  const int first = range[0];
  const int last = range[1];
  std::vector<std::string> missing;
  for (int n = first; n <= last; ++n)
  {
    char buf[4096];
    std::snprintf(buf, sizeof(buf), pattern, n);
    std::error_code ec;
    (fs::is_regular_file(buf, ec) ? files : missing).emplace_back(buf);
  }
  if (files.empty())
  {
    error = std::string("the file pattern '") + pattern + "' with numbers " +
      std::to_string(first) + " to " + std::to_string(last) + " matches no file";
    return false;
  }
  if (!missing.empty())
  {
    error = "slice file '" + missing.front() + "' is missing (file pattern '" + pattern +
      "', numbers " + std::to_string(first) + " to " + std::to_string(last) + "; " +
      std::to_string(missing.size()) + " missing)";
    return false;
  }
  return true;
}

// The directory's pictures and DICOM files, in natural order.
bool FromDirectory(const char* directory, std::vector<std::string>& files, std::string& error)
{
  std::error_code ec;
  if (!fs::is_directory(directory, ec))
  {
    error = std::string("'") + directory + "' is not a directory";
    return false;
  }
  for (const auto& entry : fs::directory_iterator(directory, ec))
  {
    const std::string name = entry.path().filename().string();
    // DICOMDIR is an index of a DICOM media, not a slice.
    if (!entry.is_regular_file() || name.empty() || name[0] == '.' || name == "DICOMDIR")
    {
      continue;
    }
    const std::string path = entry.path().string();
    if (IsPictureExtension(path) || IsDICOMFile(path))
    {
      files.push_back(path);
    }
  }
  if (files.empty())
  {
    error = std::string("the directory '") + directory + "' has no image or DICOM files";
    return false;
  }
  std::sort(files.begin(), files.end(), octoray::NaturalLess);
  return true;
}

bool From(const SliceSource& source, std::vector<std::string>& files, std::string& error)
{
  if (source.Names && !source.Names->empty())
  {
    files = *source.Names;
    return true;
  }
  if (source.Pattern && *source.Pattern)
  {
    return FromPattern(source.Pattern, source.Range, files, error);
  }
  if (source.Directory && *source.Directory)
  {
    return FromDirectory(source.Directory, files, error);
  }
  error = "no slices given: set file names, a directory or a file pattern";
  return false;
}
} // namespace

//------------------------------------------------------------------------------
bool ListSliceFiles(const SliceSource& source, std::vector<std::string>& files, std::string& error)
{
  files.clear();
  if (!From(source, files, error))
  {
    return false;
  }
  for (const auto& f : files)
  {
    std::error_code ec;
    if (fs::is_directory(f, ec))
    {
      error = "slice '" + f + "' is a directory, not an image file";
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool IsDICOMFile(const std::string& name)
{
  return Lower(fs::path(name).extension().string()) == ".dcm" || HasDICMMarker(name);
}

//------------------------------------------------------------------------------
std::string FilesSignature(const char* directory, const std::vector<std::string>& names,
  const std::vector<std::string>& slices)
{
  std::string signature;
  auto add = [&](const std::string& name) {
    struct stat st;
    if (::stat(name.c_str(), &st) == 0)
    {
      signature += name + ":" + std::to_string(st.st_ino) + ":" + std::to_string(st.st_size) +
        ":" + std::to_string(st.st_mtim.tv_sec) + "." + std::to_string(st.st_mtim.tv_nsec) + ";";
    }
    else
    {
      signature += name + ":-;";
    }
  };
  if (directory && *directory)
  {
    add(directory);
  }
  for (const auto& f : names)
  {
    add(f);
  }
  for (const auto& f : slices)
  {
    add(f.substr(0, f.rfind('#') == std::string::npos ? f.size() : f.rfind('#')));
  }
  return signature;
}
} // namespace slices
} // namespace octoray
