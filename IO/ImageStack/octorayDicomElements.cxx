#include "octorayDicomElements.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include <unistd.h>

namespace octoray
{
namespace dicom
{
//------------------------------------------------------------------------------
bool Bytes::Read(uint64_t off, void* dst, size_t n)
{
  if (off > this->Length || n > this->Length - off)
  {
    this->Error = "cannot read " + std::to_string(n) + " bytes at byte " + std::to_string(off) +
      ": the file has " + std::to_string(this->Length);
    return false;
  }
  if (this->Memory)
  {
    std::memcpy(dst, this->Memory + off, n);
    return true;
  }
  if ((off < this->WindowStart || off + n > this->WindowStart + this->Window.size()) &&
    !this->Fill(off, n))
  {
    return false;
  }
  std::memcpy(dst, this->Window.data() + (off - this->WindowStart), n);
  return true;
}

//------------------------------------------------------------------------------
// The window moved to off: 64 KiB (or n bytes, if more) from the file.
bool Bytes::Fill(uint64_t off, size_t n)
{
  const size_t want = static_cast<size_t>(
    std::min<uint64_t>(std::max<size_t>(n, size_t(1) << 16), this->Length - off));
  this->Window.resize(want);
  this->WindowStart = off;
  size_t got = 0;
  while (got < want)
  {
    const ssize_t r =
      ::pread(this->Fd, this->Window.data() + got, want - got, static_cast<off_t>(off + got));
    if (r < 0 && errno == EINTR)
    {
      continue;
    }
    if (r <= 0)
    {
      this->Error = r < 0 ? std::string("cannot read byte ") + std::to_string(off + got) + ": " +
          std::strerror(errno)
                          : "the file ends at byte " + std::to_string(off + got) + ", before the " +
          std::to_string(this->Length) +
          " bytes it had when it was opened (it changed while being read)";
      this->Window.clear();
      return false;
    }
    got += static_cast<size_t>(r);
  }
  return true;
}

//------------------------------------------------------------------------------
// PS3.5 table 7.1-1/2.
bool IsShortVR(const char* v)
{
  static const char* const vrs[] = { "AE", "AS", "AT", "CS", "DA", "DS", "DT", "FL", "FD", "IS",
    "LO", "LT", "PN", "SH", "SL", "SS", "ST", "TM", "UI", "UL", "US" };
  return std::any_of(std::begin(vrs), std::end(vrs), [&](const char* vr) { return IsVR(v, vr); });
}

//------------------------------------------------------------------------------
bool IsLongVR(const char* v)
{
  static const char* const vrs[] = { "OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN",
    "UR", "UT", "UV" };
  return std::any_of(std::begin(vrs), std::end(vrs), [&](const char* vr) { return IsVR(v, vr); });
}

//------------------------------------------------------------------------------
std::string TagName(uint16_t g, uint16_t e)
{
  char buf[16];
  std::snprintf(buf, sizeof(buf), "(%04X,%04X)", g, e);
  return buf;
}

//------------------------------------------------------------------------------
std::string Shown(const char* v)
{
  std::string s;
  for (int i = 0; i < 2; ++i)
  {
    const unsigned char c = static_cast<unsigned char>(v[i]);
    if (c >= 0x20 && c < 0x7F && c != '\\')
    {
      s += static_cast<char>(c);
    }
    else
    {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\x%02X", c);
      s += buf;
    }
  }
  return s;
}

//------------------------------------------------------------------------------
bool Elements::Fail(const std::string& message)
{
  if (this->Message.empty())
  {
    this->Message = message;
  }
  return false;
}

//------------------------------------------------------------------------------
bool Elements::Get(uint64_t off, void* dst, size_t n)
{
  return this->B.Read(off, dst, n) || this->Fail(this->B.Error);
}

//------------------------------------------------------------------------------
std::string Elements::Limit(uint64_t end) const
{
  return end == this->B.Size() ? "the file has " + std::to_string(end)
                               : "its enclosing item or sequence ends at byte " +
      std::to_string(end);
}

//------------------------------------------------------------------------------
std::string Elements::Before(uint64_t end) const
{
  return end == this->B.Size() ? "the end of the file" : "byte " + std::to_string(end);
}

//------------------------------------------------------------------------------
bool Elements::ReadHeader(uint64_t pos, uint64_t end, Encoding enc, Header& h, const char* where)
{
  h = Header();
  h.Start = pos;
  unsigned char b[12];
  if (end - pos < 8)
  {
    return this->Fail("a DICOM element header at byte " + std::to_string(pos) + where +
      " is cut short: it needs 8 bytes, " + this->Limit(end));
  }
  if (!this->Get(pos, b, 8))
  {
    return false;
  }
  h.Group = U16(b, enc.BigEndian);
  h.Element = U16(b + 2, enc.BigEndian);
  if (h.Group == 0xFFFE || !enc.Explicit)
  {
    // Items and delimiters never have a VR.
    h.Length = U32(b + 4, enc.BigEndian);
    h.ValueStart = pos + 8;
    return true;
  }
  h.VR[0] = static_cast<char>(b[4]);
  h.VR[1] = static_cast<char>(b[5]);
  h.HasVR = true;
  if (IsShortVR(h.VR))
  {
    h.Length = U16(b + 6, enc.BigEndian);
    h.ValueStart = pos + 8;
    return true;
  }
  if (!IsLongVR(h.VR))
  {
    return this->Fail("DICOM element " + h.Name() + " at byte " + std::to_string(pos) + where +
      " has no valid VR: found '" + Shown(h.VR) + "' where explicit VR " +
      (enc.BigEndian ? "big" : "little") + " endian expects one");
  }
  if (end - pos < 12)
  {
    return this->Fail("the header of DICOM element " + h.Name() + " at byte " +
      std::to_string(pos) + where + " is cut short: it needs 12 bytes, " + this->Limit(end));
  }
  if (!this->Get(pos + 8, b + 8, 4))
  {
    return false;
  }
  h.Length = U32(b + 8, enc.BigEndian);
  h.ValueStart = pos + 12;
  return true;
}

//------------------------------------------------------------------------------
bool Elements::CheckFits(const Header& h, uint64_t end, const char* what)
{
  if (h.Length > end - h.ValueStart)
  {
    return this->Fail(std::string(what) + " " + h.Name() + " at byte " + std::to_string(h.Start) +
      " claims " + std::to_string(h.Length) + " bytes, " + this->Limit(end));
  }
  return true;
}
} // namespace dicom
} // namespace octoray
