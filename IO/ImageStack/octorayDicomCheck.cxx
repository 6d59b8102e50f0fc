#include "octorayDicomCheck.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace
{
constexpr uint32_t UndefinedLength = 0xFFFFFFFFu;

// The bytes of the file, read through a window (headers are small and mostly
// in order; values are skipped), or of a buffer.
class Bytes
{
public:
  Bytes(const unsigned char* data, uint64_t size)
    : Memory(data)
    , Length(size)
  {
  }
  Bytes(int fd, uint64_t size)
    : Fd(fd)
    , Length(size)
  {
  }
  uint64_t Size() const { return this->Length; }

  // n bytes at off (off + n <= Size(), checked by the caller); false and
  // Error set when the file cannot deliver them.
  bool Read(uint64_t off, void* dst, size_t n)
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
    if (off < this->WindowStart || off + n > this->WindowStart + this->Window.size())
    {
      const size_t want = static_cast<size_t>(std::min<uint64_t>(
        std::max<size_t>(n, size_t(1) << 16), this->Length - off));
      this->Window.resize(want);
      this->WindowStart = off;
      size_t got = 0;
      while (got < want)
      {
        const ssize_t r = ::pread(this->Fd, this->Window.data() + got, want - got,
          static_cast<off_t>(off + got));
        if (r < 0 && errno == EINTR)
        {
          continue;
        }
        if (r <= 0)
        {
          this->Error = r < 0 ? std::string("cannot read byte ") + std::to_string(off + got) +
              ": " + std::strerror(errno)
                              : "the file ends at byte " + std::to_string(off + got) +
              ", before the " + std::to_string(this->Length) +
              " bytes it had when it was opened (it changed while being read)";
          this->Window.clear();
          return false;
        }
        got += static_cast<size_t>(r);
      }
    }
    std::memcpy(dst, this->Window.data() + (off - this->WindowStart), n);
    return true;
  }

  std::string Error;

private:
  const unsigned char* Memory = nullptr;
  int Fd = -1;
  uint64_t Length = 0;
  std::vector<unsigned char> Window;
  uint64_t WindowStart = 0;
};

struct Encoding
{
  bool Explicit = true;
  bool BigEndian = false;
};

// PS3.5 table 7.1-1/2: VRs with a 2-byte length, and those with 2 reserved
// bytes and a 4-byte length.
bool IsShortVR(const char* v)
{
  static const char* const vrs[] = { "AE", "AS", "AT", "CS", "DA", "DS", "DT", "FL", "FD", "IS",
    "LO", "LT", "PN", "SH", "SL", "SS", "ST", "TM", "UI", "UL", "US" };
  for (const char* vr : vrs)
    if (v[0] == vr[0] && v[1] == vr[1])
      return true;
  return false;
}

bool IsLongVR(const char* v)
{
  static const char* const vrs[] = { "OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN",
    "UR", "UT", "UV" };
  for (const char* vr : vrs)
    if (v[0] == vr[0] && v[1] == vr[1])
      return true;
  return false;
}

bool IsVR(const char* v, const char* vr)
{
  return v[0] == vr[0] && v[1] == vr[1];
}

std::string Hex4(unsigned v)
{
  char buf[8];
  std::snprintf(buf, sizeof(buf), "%04X", v & 0xFFFFu);
  return buf;
}

std::string TagName(uint16_t g, uint16_t e)
{
  return "(" + Hex4(g) + "," + Hex4(e) + ")";
}

// Bytes that should have been a VR, printable or as \xNN.
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

struct Header
{
  uint64_t Start = 0;
  uint16_t Group = 0, Element = 0;
  char VR[2] = { 0, 0 }; // explicit VR only; not for items and delimiters
  bool HasVR = false;
  uint32_t Length = 0;
  uint64_t ValueStart = 0;
  std::string Name() const { return TagName(this->Group, this->Element); }
};

class Walker
{
public:
  explicit Walker(Bytes& bytes)
    : B(bytes)
  {
  }

  std::string Run()
  {
    const uint64_t size = this->B.Size();
    uint64_t pos = 0;
    unsigned char magic[4];
    const bool part10 = size >= 132 && this->B.Read(128, magic, 4) && std::memcmp(magic, "DICM", 4) == 0;
    if (!this->B.Error.empty())
    {
      return this->B.Error;
    }
    if (part10)
    {
      pos = 132;
    }
    std::string syntax;
    if (!this->MetaGroup(pos, syntax))
    {
      return this->Error;
    }
    Encoding enc;
    if (syntax == "1.2.840.10008.1.2")
    {
      enc.Explicit = false;
    }
    else if (syntax == "1.2.840.10008.1.2.2")
    {
      enc.BigEndian = true;
    }
    else if (syntax == "1.2.840.10008.1.2.1.99")
    {
      return {}; // deflated: the data set is a zlib stream
    }
    else if (syntax.empty())
    {
      // No file meta group, or one without a transfer syntax: like GDCM,
      // take the encoding from the first element (group 0008 is 08 00 in
      // little endian, 00 08 in big endian; explicit VR has a VR after it).
      unsigned char b[6];
      if (size - pos >= 6)
      {
        if (!this->Get(pos, b, 6))
        {
          return this->Error;
        }
        enc.BigEndian = b[0] == 0 && b[1] != 0;
        const char vr[2] = { static_cast<char>(b[4]), static_cast<char>(b[5]) };
        enc.Explicit = IsShortVR(vr) || IsLongVR(vr);
      }
    }
    else if (!enc.BigEndian && size - pos >= 6)
    {
      // A transfer syntax that says explicit VR over a data set written in
      // implicit VR is a common writer bug; GDCM sees it at the first
      // element and reads the data set as implicit VR, and so does this.
      unsigned char b[6];
      if (!this->Get(pos, b, 6))
      {
        return this->Error;
      }
      const char vr[2] = { static_cast<char>(b[4]), static_cast<char>(b[5]) };
      enc.Explicit = IsShortVR(vr) || IsLongVR(vr) || U16(b, false) == 0xFFFE;
    }
    this->DataSetEncoding = enc;
    if (!this->DataSet(pos, size, 0, 0, enc))
    {
      return this->Error;
    }
    // Sound structure that GDCM 3.0 still cannot take: for an RT dose with a
    // grid frame offset vector it reads the number of frames without looking
    // whether there is one, and an assert() stops the process.
    if (this->GridFrameOffsetAt && !this->HasNumberOfFrames)
    {
      return "the DICOM grid frame offset vector (3004,000C) at byte " +
        std::to_string(this->GridFrameOffsetAt) +
        " comes without a number of frames (0028,0008), which GDCM 3.0 cannot read";
    }
    return {};
  }

private:
  bool Fail(const std::string& message)
  {
    if (this->Error.empty())
    {
      this->Error = message;
    }
    return false;
  }

  bool Get(uint64_t off, void* dst, size_t n)
  {
    if (!this->B.Read(off, dst, n))
    {
      return this->Fail(this->B.Error);
    }
    return true;
  }

  static uint16_t U16(const unsigned char* p, bool big)
  {
    return big ? static_cast<uint16_t>(p[0] << 8 | p[1]) : static_cast<uint16_t>(p[1] << 8 | p[0]);
  }
  static uint32_t U32(const unsigned char* p, bool big)
  {
    return big ? (uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3])
               : (uint32_t(p[3]) << 24 | uint32_t(p[2]) << 16 | uint32_t(p[1]) << 8 | p[0]);
  }

  // Where a value or header that does not fit would have to end.
  std::string Limit(uint64_t end) const
  {
    return end == this->B.Size() ? "the file has " + std::to_string(end)
                                 : "its enclosing item or sequence ends at byte " +
        std::to_string(end);
  }

  // The tag, VR and length at pos, which must fit before end.
  bool ReadHeader(uint64_t pos, uint64_t end, Encoding enc, Header& h, const char* where)
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

  bool CheckFits(const Header& h, uint64_t end, const char* what)
  {
    if (h.Length > end - h.ValueStart)
    {
      return this->Fail(std::string(what) + " " + h.Name() + " at byte " + std::to_string(h.Start) +
        " claims " + std::to_string(h.Length) + " bytes, " + this->Limit(end));
    }
    return true;
  }

  // Group 0002 at pos, always explicit VR little endian; the transfer
  // syntax UID comes back in syntax (without its padding).
  bool MetaGroup(uint64_t& pos, std::string& syntax)
  {
    const uint64_t size = this->B.Size();
    const Encoding meta;
    bool haveLength = false;
    uint64_t metaEnd = 0;
    uint64_t lengthAt = 0;
    while (size - pos >= 2)
    {
      unsigned char g[2];
      if (!this->Get(pos, g, 2))
      {
        return false;
      }
      if (U16(g, false) != 0x0002)
      {
        break;
      }
      Header h;
      if (!this->ReadHeader(pos, size, meta, h, " (file meta group)") ||
        !this->CheckFits(h, size, "DICOM file meta element"))
      {
        return false;
      }
      if (h.Length == UndefinedLength)
      {
        return this->Fail("DICOM file meta element " + h.Name() + " at byte " +
          std::to_string(pos) + " has an undefined length");
      }
      if (h.Element == 0x0000 && h.Length == 4)
      {
        unsigned char v[4];
        if (!this->Get(h.ValueStart, v, 4))
        {
          return false;
        }
        haveLength = true;
        lengthAt = pos;
        metaEnd = h.ValueStart + 4 + U32(v, false);
        if (metaEnd > size)
        {
          return this->Fail("the DICOM file meta group length (0002,0000) at byte " +
            std::to_string(pos) + " says the group ends at byte " + std::to_string(metaEnd) +
            ", the file has " + std::to_string(size));
        }
      }
      else if (h.Element == 0x0010)
      {
        if (h.Length > 64)
        {
          return this->Fail("the DICOM transfer syntax UID (0002,0010) at byte " +
            std::to_string(pos) + " is " + std::to_string(h.Length) +
            " bytes long; a UID has at most 64");
        }
        std::string v(h.Length, '\0');
        if (!this->Get(h.ValueStart, &v[0], h.Length))
        {
          return false;
        }
        while (!v.empty() && (v.back() == '\0' || v.back() == ' '))
        {
          v.pop_back();
        }
        syntax = v;
      }
      pos = h.ValueStart + h.Length;
    }
    // The group length is where GDCM stops reading the group: elements it
    // covers must end exactly there.
    if (haveLength && pos != metaEnd)
    {
      return this->Fail("the DICOM file meta group length (0002,0000) at byte " +
        std::to_string(lengthAt) + " says the group ends at byte " + std::to_string(metaEnd) +
        ", but its elements end at byte " + std::to_string(pos));
    }
    return true;
  }

  // Elements from pos to end, or (itemStart > 0) up to and including the
  // item delimiter of an undefined-length item that starts at itemStart.
  bool DataSet(uint64_t& pos, uint64_t end, uint64_t itemStart, int depth, Encoding enc)
  {
    const char* where = depth == 0 ? "" : " (in a sequence item)";
    while (pos < end)
    {
      Header h;
      if (!this->ReadHeader(pos, end, enc, h, where))
      {
        return false;
      }
      if (h.Group == 0xFFFE)
      {
        if (h.Element == 0xE00D && itemStart > 0)
        {
          pos = h.ValueStart;
          return true;
        }
        return this->Fail("unexpected " +
          std::string(h.Element == 0xE000 ? "item"
              : h.Element == 0xE00D       ? "item delimiter"
              : h.Element == 0xE0DD       ? "sequence delimiter"
                                          : "element") +
          " " + h.Name() + " at byte " + std::to_string(pos) +
          (depth == 0 ? " in the data set" : " inside an item"));
      }
      const bool pixelData = h.Group == 0x7FE0 && h.Element == 0x0010;
      if (depth == 0)
      {
        this->HasNumberOfFrames |= h.Group == 0x0028 && h.Element == 0x0008;
        if (h.Group == 0x3004 && h.Element == 0x000C)
        {
          this->GridFrameOffsetAt = pos;
        }
      }
      if (h.Length == UndefinedLength)
      {
        if (pixelData && (!h.HasVR || IsVR(h.VR, "OB") || IsVR(h.VR, "OW")))
        {
          if (!this->Fragments(h, pos, end))
          {
            return false;
          }
        }
        else if (!h.HasVR || IsVR(h.VR, "SQ") || IsVR(h.VR, "UN"))
        {
          // An undefined-length UN is a sequence in implicit VR little
          // endian (PS3.5 6.2.2).
          Encoding inner = enc;
          if (h.HasVR && IsVR(h.VR, "UN"))
          {
            inner = Encoding{ false, false };
          }
          if (!this->Sequence(h, pos, end, depth + 1, inner))
          {
            return false;
          }
        }
        else
        {
          return this->Fail("DICOM element " + h.Name() + " at byte " + std::to_string(pos) +
            " has an undefined length, which VR " + Shown(h.VR) + " does not allow");
        }
        continue;
      }
      if (!this->CheckFits(h, end, "DICOM element"))
      {
        return false;
      }
      const uint64_t valueEnd = h.ValueStart + h.Length;
      // A defined-length sequence: SQ in explicit VR; in implicit VR (and
      // for UN, GDCM reads it as a sequence when its dictionary says SQ) any
      // value that starts with an item tag, as GDCM would parse it.
      bool sequence = h.HasVR && IsVR(h.VR, "SQ");
      Encoding inner = enc;
      if (!sequence && (!h.HasVR || IsVR(h.VR, "UN")) && h.Length >= 8 && !pixelData)
      {
        if (h.HasVR)
        {
          inner = Encoding{ false, false };
        }
        unsigned char t[4];
        if (!this->Get(h.ValueStart, t, 4))
        {
          return false;
        }
        sequence = U16(t, inner.BigEndian) == 0xFFFE && U16(t + 2, inner.BigEndian) == 0xE000;
      }
      if (sequence)
      {
        uint64_t p = pos;
        if (!this->Sequence(h, p, valueEnd, depth + 1, inner))
        {
          return false;
        }
      }
      pos = valueEnd;
    }
    if (itemStart > 0)
    {
      return this->Fail("the DICOM item at byte " + std::to_string(itemStart) +
        " has an undefined length and no item delimiter (FFFE,E00D) before " +
        (end == this->B.Size() ? "the end of the file" : "byte " + std::to_string(end)));
    }
    return true;
  }

  // The items of sequence seq (header at pos); pos ends after it. A
  // defined-length sequence ends at end (its value's end).
  bool Sequence(const Header& seq, uint64_t& pos, uint64_t end, int depth, Encoding enc)
  {
    if (depth > octoray::DicomMaximumDepth)
    {
      return this->Fail("DICOM sequence " + seq.Name() + " at byte " + std::to_string(seq.Start) +
        " is nested more than " + std::to_string(octoray::DicomMaximumDepth) + " levels deep");
    }
    const bool undefined = seq.Length == UndefinedLength;
    pos = seq.ValueStart;
    while (true)
    {
      if (!undefined && pos == end)
      {
        return true;
      }
      if (end - pos < 8)
      {
        return this->Fail("the DICOM sequence " + seq.Name() + " at byte " +
          std::to_string(seq.Start) + (undefined ? " has no sequence delimiter (FFFE,E0DD)"
                                                 : " ends inside an item header") +
          " before " +
          (end == this->B.Size() ? "the end of the file" : "byte " + std::to_string(end)));
      }
      unsigned char b[8];
      if (!this->Get(pos, b, 8))
      {
        return false;
      }
      const uint16_t g = U16(b, enc.BigEndian), e = U16(b + 2, enc.BigEndian);
      const uint32_t length = U32(b + 4, enc.BigEndian);
      if (g == 0xFFFE && e == 0xE0DD && undefined)
      {
        pos += 8;
        return true;
      }
      if (g != 0xFFFE || e != 0xE000)
      {
        return this->Fail("DICOM sequence " + seq.Name() + " at byte " + std::to_string(seq.Start) +
          " holds " + TagName(g, e) + " at byte " + std::to_string(pos) +
          " where an item (FFFE,E000)" + (undefined ? " or its delimiter (FFFE,E0DD)" : "") +
          " must be");
      }
      const uint64_t itemStart = pos;
      pos += 8;
      if (length == UndefinedLength)
      {
        if (!this->DataSet(pos, end, itemStart, depth, enc))
        {
          return false;
        }
        continue;
      }
      if (length > end - pos)
      {
        return this->Fail("the DICOM item at byte " + std::to_string(itemStart) + " of sequence " +
          seq.Name() + " claims " + std::to_string(length) + " bytes, " + this->Limit(end));
      }
      const uint64_t itemEnd = pos + length;
      if (!this->DataSet(pos, itemEnd, 0, depth, enc))
      {
        return false;
      }
    }
  }

  // Encapsulated pixel data: items of defined length (the basic offset
  // table, then the fragments) up to a sequence delimiter.
  bool Fragments(const Header& px, uint64_t& pos, uint64_t end)
  {
    pos = px.ValueStart;
    const bool big = this->DataSetEncoding.BigEndian;
    while (true)
    {
      if (end - pos < 8)
      {
        return this->Fail("the encapsulated pixel data " + px.Name() + " at byte " +
          std::to_string(px.Start) + " has no sequence delimiter (FFFE,E0DD) before " +
          (end == this->B.Size() ? "the end of the file" : "byte " + std::to_string(end)));
      }
      unsigned char b[8];
      if (!this->Get(pos, b, 8))
      {
        return false;
      }
      const uint16_t g = U16(b, big), e = U16(b + 2, big);
      const uint32_t length = U32(b + 4, big);
      if (g == 0xFFFE && e == 0xE0DD)
      {
        pos += 8;
        return true;
      }
      if (g != 0xFFFE || e != 0xE000)
      {
        return this->Fail("the encapsulated pixel data " + px.Name() + " at byte " +
          std::to_string(px.Start) + " holds " + TagName(g, e) + " at byte " +
          std::to_string(pos) + " where a fragment item (FFFE,E000) must be");
      }
      if (length == UndefinedLength || length > end - pos - 8)
      {
        return this->Fail("the pixel data fragment at byte " + std::to_string(pos) + " claims " +
          (length == UndefinedLength ? std::string("an undefined length")
                                     : std::to_string(length) + " bytes") +
          ", " + this->Limit(end));
      }
      pos += 8 + length;
    }
  }

  Bytes& B;
  Encoding DataSetEncoding;
  std::string Error;
  bool HasNumberOfFrames = false;
  uint64_t GridFrameOffsetAt = 0;
};
} // namespace

namespace octoray
{
std::string CheckDicomStructure(const unsigned char* data, size_t size)
{
  Bytes bytes(data, size);
  return Walker(bytes).Run();
}

std::string CheckDicomStructure(const std::string& fileName)
{
  const int fd = ::open(fileName.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
  {
    return std::string("cannot open the file: ") + std::strerror(errno);
  }
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
  {
    ::close(fd);
    return "not a regular file";
  }
  Bytes bytes(fd, static_cast<uint64_t>(st.st_size));
  std::string error = Walker(bytes).Run();
  ::close(fd);
  return error;
}
} // namespace octoray
