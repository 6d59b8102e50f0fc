// The LZF decoder of PCD's binary_compressed bodies, without VTK:
// vtkPCDReader inflates with it, and the fuzz target in Testing/Fuzz calls it
// directly on any bytes. Private to the module; not wrapped.
//
// LZF (Marc Lehmann's format, as PCL's PCD writer uses it) is a sequence of
// instructions, each starting with a control byte c:
//   c < 32          a literal run: the next c + 1 bytes are copied to the output
//   c >= 32         a back-reference: length L = c >> 5 (1 to 6, or 7 + the next
//                   byte when it is 7), distance D = ((c & 31) << 8) + the next
//                   byte + 1; L + 2 bytes are copied from D bytes before the
//                   current end of the output, byte by byte, so that a copy may
//                   overlap what it writes (D = 1 repeats one byte)
// The decoder below is written from that description and checks every length
// and distance against both buffers.
#ifndef octorayLZF_h
#define octorayLZF_h

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>

namespace octoray
{
namespace pcd
{
// The most bytes one compressed byte can become: a 3-byte back-reference
// copies at most 264.
constexpr size_t LzfMaximumExpansion = 88;

// GCC 12 warns of the fixed 32-byte moves below when it inlines a call
// with a small constant output (a test's): they are taken only where both
// buffers have 32 bytes of room, which it does not follow.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstringop-overflow"
#endif
// Inflates in[0, inSize) into exactly outSize bytes at out. progress(bytes
// written so far) is called about every megabyte; when it returns false the
// decoding stops (aborted; error left empty). On a corrupt stream, error says
// what is wrong and at which compressed and uncompressed byte.
template <typename Progress>
inline bool LzfDecompress(const unsigned char* in, size_t inSize, unsigned char* out,
  size_t outSize, std::string& error, Progress&& progress)
{
  size_t ip = 0, op = 0;
  size_t nextReport = size_t(1) << 20;
  auto where = [&](size_t at) {
    return " (instruction at compressed byte " + std::to_string(at) + ", output byte " +
      std::to_string(op) + ")";
  };
  while (ip < inSize)
  {
    const size_t at = ip;
    const unsigned ctrl = in[ip++];
    if (ctrl < 32)
    {
      const size_t run = ctrl + 1;
      if (run > inSize - ip)
      {
        error = "a literal run of " + std::to_string(run) + " bytes goes past the end of the " +
          "compressed data (" + std::to_string(inSize - ip) + " byte(s) left)" + where(at);
        return false;
      }
      if (run > outSize - op)
      {
        error = "a literal run of " + std::to_string(run) + " bytes goes past the " +
          std::to_string(outSize) + " bytes the block should inflate to" + where(at);
        return false;
      }
      // A fixed 32-byte copy where both buffers have the room (the bytes
      // past the run are written again by what follows): one wide move
      // instead of a call for a few bytes.
      if (inSize - ip >= 32 && outSize - op >= 32)
      {
        std::memcpy(out + op, in + ip, 32);
      }
      else
      {
        std::memcpy(out + op, in + ip, run);
      }
      ip += run;
      op += run;
    }
    else
    {
      size_t len = ctrl >> 5;
      if (len == 7)
      {
        if (ip >= inSize)
        {
          error = "a back-reference is cut off by the end of the compressed data" + where(at);
          return false;
        }
        len += in[ip++];
      }
      if (ip >= inSize)
      {
        error = "a back-reference is cut off by the end of the compressed data" + where(at);
        return false;
      }
      const size_t distance = ((static_cast<size_t>(ctrl & 31) << 8) | in[ip++]) + 1;
      len += 2;
      if (distance > op)
      {
        error = "a back-reference reaches " + std::to_string(distance) +
          " bytes back, before the start of the output" + where(at);
        return false;
      }
      if (len > outSize - op)
      {
        error = "a back-reference of " + std::to_string(len) + " bytes goes past the " +
          std::to_string(outSize) + " bytes the block should inflate to" + where(at);
        return false;
      }
      if (distance >= 32 && len <= 32 && outSize - op >= 32)
      {
        // Source and destination 32 bytes apart or more: one fixed move.
        std::memcpy(out + op, out + op - distance, 32);
        op += len;
      }
      // In pieces of at most `distance` bytes: each piece reads bytes that
      // are already written (a copy longer than its distance repeats them).
      else for (size_t left = len; left > 0;)
      {
        const size_t piece = std::min(left, distance);
        std::memcpy(out + op, out + op - distance, piece);
        op += piece;
        left -= piece;
      }
    }
    if (op >= nextReport)
    {
      nextReport = op + (size_t(1) << 20);
      if (!progress(op))
      {
        error.clear();
        return false;
      }
    }
  }
  if (op != outSize)
  {
    error = "the compressed data ends after " + std::to_string(op) + " of the " +
      std::to_string(outSize) + " bytes it should inflate to";
    return false;
  }
  return true;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

} // namespace pcd
} // namespace octoray

#endif
