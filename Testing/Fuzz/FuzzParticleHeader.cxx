// libFuzzer target: the particle text format without VTK (the prologue:
// comments, header line, first data line; CanReadFile's sniffer; and every
// token through the number parser). Invariants are checked with abort(),
// which the fuzzer reports as a crash.
#include "octorayParticleTextFormat.h"

#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* bytes, size_t size)
{
  using namespace octoray::ptext;
  const char* data = reinterpret_cast<const char*>(bytes);
  const Prologue p = ParsePrologue(data, size, "fuzz.txt");
  if (p.Ok)
  {
    if (p.Columns.size() < 3 || p.FirstData >= size || p.Layout.empty() || !p.Error.empty())
    {
      std::abort();
    }
  }
  else if (p.Error.compare(0, 9, "fuzz.txt:") != 0)
  {
    std::abort(); // every error names the file and line
  }
  // The sniffer of CanReadFile: a yes implies a prologue the reader
  // accepts; on a cut-off start it never reads past the bytes given.
  if (LooksLikeParticleText(data, size, true) && !p.Ok)
  {
    std::abort();
  }
  LooksLikeParticleText(data, size, false);
  // Every token of the first line through both number parsers and the
  // error-message token (bounded, printable).
  const char* e = data + size;
  for (const auto& t : SplitTokens(data, e))
  {
    double d;
    float f;
    ParseNumber(t.first.data(), t.first.data() + t.first.size(), d);
    ParseNumber(t.first.data(), t.first.data() + t.first.size(), f);
    const std::string shown = TokenAt(t.first.data(), t.first.data() + t.first.size());
    if (shown.size() > 40 * 4 + 3)
    {
      std::abort();
    }
    for (char c : shown)
    {
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f)
      {
        std::abort();
      }
    }
  }
  return 0;
}
