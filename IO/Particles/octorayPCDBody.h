// The body of a PCD file, without VTK: whatever its DATA form, each field's
// values located as an array of its declared type (in the mapped file for
// binary, parsed or inflated into a buffer for ascii and binary_compressed),
// after checking the body against what the header promises. vtkPCDReader
// converts from there. Private to the module; not wrapped.
#ifndef octorayPCDBody_h
#define octorayPCDBody_h

#include "octorayLZF.h"
#include "octorayPCDAscii.h"
#include "octorayPCDHeader.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace octoray
{
namespace pcd
{
// Where the values of one field are: point i's first value at
// Base + i * Stride, its value c at + c * Size.
struct Source
{
  const unsigned char* Base = nullptr;
  size_t Stride = 0;
};

struct Body
{
  std::vector<Source> Sources; // one per field of the header
  // The ascii values, or the inflated block; not zero-filled (every byte is
  // written before it is read).
  std::unique_ptr<unsigned char[]> Buffer;
};

inline std::string Plural(uint64_t n, const char* one, const char* many)
{
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// PCL's writer leaves zeros after a compressed block (it reserves room for
// the block before it knows its size): those are no data left unread.
inline bool AllZero(const unsigned char* p, size_t n)
{
  for (size_t i = 0; i < n; ++i)
  {
    if (p[i])
    {
      return false;
    }
  }
  return true;
}

// The share of a read's progress that decoding the body takes (ascii
// parsing, LZF); converting the values takes the rest.
inline double DecodingShare(Encoding e)
{
  return e == Encoding::Ascii ? 0.7 : e == Encoding::BinaryCompressed ? 0.6 : 0.0;
}

// The ascii body [data + h.DataOffset, data + size) parsed into body.Buffer.
template <typename Progress>
inline bool ReadAsciiBody(const char* data, size_t size, const Header& h, const std::string& file,
  Body& body, std::string& error, std::vector<std::string>& warnings, Progress&& progress)
{
  const size_t n = static_cast<size_t>(h.Points);
  const size_t available = size - h.DataOffset;
  // Each value takes at least one character and a separator: a body too
  // short for that cannot hold the points (and the buffer is not made).
  uint64_t least = 0;
  if (n > 0 &&
    (!CheckedMultiply(n, 2 * static_cast<uint64_t>(h.ValuesPerPoint), least) ||
      available + 1 < least))
  {
    const size_t lines = CountNonBlankLines(data + h.DataOffset, data + size).Count;
    error = file + ": the ascii data after the DATA line (line " + std::to_string(h.DataLine) +
      ") has " + Plural(lines, "line", "lines") + " in " + Plural(available, "byte", "bytes") +
      "; the header promises POINTS " + std::to_string(n) + " of " +
      std::to_string(h.ValuesPerPoint) + " value(s) each";
    return false;
  }
  // The parse writes every value but those of padding fields, which
  // nothing reads.
  body.Buffer.reset(new unsigned char[std::max<size_t>(n * h.PointStep, 1)]);
  if (!ParseAscii(data + h.DataOffset, data + size, h.DataLine + 1, h, file, body.Buffer.get(),
        error, warnings, [&](uint64_t done) {
          return progress(static_cast<double>(done) / static_cast<double>(n));
        }))
  {
    return false;
  }
  for (size_t f = 0; f < h.Fields.size(); ++f)
  {
    body.Sources[f] = { body.Buffer.get() + h.Fields[f].Offset, h.PointStep };
  }
  return true;
}

// The binary body, read where it lies.
inline bool ReadBinaryBody(const unsigned char* begin, size_t available, const Header& h,
  const std::string& file, Body& body, std::string& error, std::vector<std::string>& warnings)
{
  const size_t n = static_cast<size_t>(h.Points);
  const size_t need = n * h.PointStep;
  if (available < need)
  {
    error = file + ": the binary data is shorter than the header promises: POINTS " +
      std::to_string(n) + " x " + std::to_string(h.PointStep) + " bytes = " +
      std::to_string(need) + " bytes after the header (from byte " +
      std::to_string(h.DataOffset) + "), the file has " + Plural(available, "byte", "bytes") +
      " (" + Plural(h.PointStep ? available / h.PointStep : 0, "whole point", "whole points") + ")";
    return false;
  }
  if (available > need && !AllZero(begin + need, available - need))
  {
    warnings.push_back(file + ": " + Plural(available - need, "byte", "bytes") +
      " (not all zero) after the binary data of the " + Plural(n, "point", "points") +
      " were ignored");
  }
  for (size_t f = 0; f < h.Fields.size(); ++f)
  {
    body.Sources[f] = { begin + h.Fields[f].Offset, h.PointStep };
  }
  return true;
}

// The 8-byte block header of a binary_compressed body (compressed and
// uncompressed sizes) checked against the file and the header. `sizes`
// describes it for messages.
inline bool CheckCompressedBlock(const unsigned char* begin, size_t available, const Header& h,
  const std::string& file, uint32_t& compressed, uint32_t& uncompressed, std::string& sizes,
  std::string& error)
{
  if (available < 8)
  {
    error = file + ": the binary_compressed data is cut off: its 8-byte block header "
                   "(compressed and uncompressed sizes) needs 8 bytes after the header, "
                   "the file has " +
      Plural(available, "byte", "bytes");
    return false;
  }
  std::memcpy(&compressed, begin, 4);
  std::memcpy(&uncompressed, begin + 4, 4);
  const size_t n = static_cast<size_t>(h.Points);
  const size_t expected = n * h.PackedStep;
  sizes = " (the block header at byte " + std::to_string(h.DataOffset) + " says " +
    std::to_string(compressed) + " bytes compressed, " + std::to_string(uncompressed) +
    " uncompressed)";
  if (compressed > available - 8)
  {
    error = file + ": the binary_compressed data is shorter than its block header says: " +
      std::to_string(compressed) + " bytes of LZF data expected after the 8-byte block "
                                   "header, the file has " +
      Plural(available - 8, "byte", "bytes") + sizes;
    return false;
  }
  if (uncompressed != expected)
  {
    error = file + ": the binary_compressed block does not match the header: it inflates to " +
      std::to_string(uncompressed) + " bytes, POINTS " + std::to_string(n) + " x " +
      std::to_string(h.PackedStep) + " bytes (the fields without padding) = " +
      std::to_string(expected) + sizes;
    return false;
  }
  if (uncompressed > static_cast<uint64_t>(compressed) * LzfMaximumExpansion)
  {
    error = file + ": the binary_compressed block is inconsistent: " +
      std::to_string(compressed) + " bytes of LZF cannot inflate to " +
      std::to_string(uncompressed) + " (at most " + std::to_string(LzfMaximumExpansion) +
      " times as many)" + sizes;
    return false;
  }
  return true;
}

// The binary_compressed body inflated into body.Buffer: one array per field.
template <typename Progress>
inline bool ReadCompressedBody(const unsigned char* begin, size_t available, const Header& h,
  const std::string& file, Body& body, std::string& error, std::vector<std::string>& warnings,
  Progress&& progress)
{
  uint32_t compressed = 0, uncompressed = 0;
  std::string sizes;
  if (!CheckCompressedBlock(begin, available, h, file, compressed, uncompressed, sizes, error))
  {
    return false;
  }
  if (available - 8 > compressed && !AllZero(begin + 8 + compressed, available - 8 - compressed))
  {
    warnings.push_back(file + ": " + Plural(available - 8 - compressed, "byte", "bytes") +
      " (not all zero) after the compressed block were ignored");
  }
  body.Buffer.reset(new unsigned char[std::max<size_t>(uncompressed, 1)]);
  if (!LzfDecompress(begin + 8, compressed, body.Buffer.get(), uncompressed, error,
        [&](size_t done) {
          return progress(static_cast<double>(done) / static_cast<double>(uncompressed));
        }))
  {
    if (!error.empty()) // empty: stopped by progress
    {
      error = file + ": corrupt binary_compressed data (LZF): " + error + sizes;
    }
    return false;
  }
  const size_t n = static_cast<size_t>(h.Points);
  for (size_t f = 0; f < h.Fields.size(); ++f)
  {
    const Field& fd = h.Fields[f];
    // Padding fields are not in the block; nothing reads them.
    body.Sources[f] = { fd.Padding() ? nullptr : body.Buffer.get() + n * fd.PackedOffset,
      fd.Bytes() };
  }
  return true;
}

// Reads the body of a file whose header h was read from data: the values of
// each field located in body.Sources. progress(fraction of the decoding
// done) is called while ascii is parsed or LZF inflated; when it returns
// false the reading stops (false, error left empty). Errors name the file
// and say what the header promises against what the body holds.
template <typename Progress>
inline bool ReadBody(const char* data, size_t size, const Header& h, const std::string& file,
  Body& body, std::string& error, std::vector<std::string>& warnings, Progress&& progress)
{
  body.Sources.assign(h.Fields.size(), Source());
  const unsigned char* const begin = reinterpret_cast<const unsigned char*>(data) + h.DataOffset;
  const size_t available = size - h.DataOffset;
  switch (h.Data)
  {
    case Encoding::Ascii:
      return ReadAsciiBody(data, size, h, file, body, error, warnings, progress);
    case Encoding::Binary:
      return ReadBinaryBody(begin, available, h, file, body, error, warnings);
    default:
      return ReadCompressedBody(begin, available, h, file, body, error, warnings, progress);
  }
}

} // namespace pcd
} // namespace octoray

#endif
