// What the module's two text formats, particle text and PCD, share: which
// bytes are blanks, and how a message names a place and shows a token.
// VTK-free, like the format headers that include it (the fuzz targets call
// them without VTK). Private to the module; not wrapped.
#ifndef octorayTextScan_h
#define octorayTextScan_h

#include <cstddef>
#include <cstdio>
#include <string>

namespace octoray
{
// Field separators of both formats; '\r' too, so CRLF line ends read as LF.
inline bool IsBlank(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// Whether `n` bytes from p start with gzip's magic number.
inline bool StartsGzip(const void* p, std::size_t n)
{
  const unsigned char* b = static_cast<const unsigned char*>(p);
  return n >= 2 && b[0] == 0x1f && b[1] == 0x8b;
}

// Whether `n` bytes from p start with UTF-8's byte order mark, which
// spreadsheets write before a "CSV UTF-8" file.
inline bool StartsUtf8Mark(const void* p, std::size_t n)
{
  const unsigned char* b = static_cast<const unsigned char*>(p);
  return n >= 3 && b[0] == 0xef && b[1] == 0xbb && b[2] == 0xbf;
}

// The first byte of [p, e) that no text line holds (a control byte other
// than the blanks, or one past ASCII), or e.
inline const char* FirstBinaryByte(const char* p, const char* e)
{
  for (; p < e; ++p)
  {
    const unsigned char c = static_cast<unsigned char>(*p);
    if ((c < 0x20 && !IsBlank(*p)) || c >= 0x7f)
    {
      return p;
    }
  }
  return e;
}

// The first byte of [p, e) that is no blank, or e.
inline const char* SkipBlanks(const char* p, const char* e)
{
  while (p < e && IsBlank(*p))
  {
    ++p;
  }
  return p;
}

// "file:line:column: ", the start of a message about a byte of a file.
inline std::string Where(const std::string& file, long long line, long long column)
{
  return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": ";
}

// [b, e) for a message: at most 40 characters (longer ones end in "..."),
// bytes that are not printable ASCII written as \xNN, so that binary garbage
// gives a readable, bounded message.
inline std::string Printable(const char* b, const char* e)
{
  const bool cut = e - b > 40;
  const char* stop = cut ? b + 37 : e;
  std::string t;
  for (const char* c = b; c < stop; ++c)
  {
    const unsigned char u = static_cast<unsigned char>(*c);
    if (u >= 0x20 && u < 0x7f)
    {
      t += *c;
    }
    else
    {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\x%02x", u);
      t += buf;
    }
  }
  if (cut)
  {
    t += "...";
  }
  return t;
}

inline std::string Printable(const std::string& s)
{
  return Printable(s.data(), s.data() + s.size());
}
} // namespace octoray

#endif
