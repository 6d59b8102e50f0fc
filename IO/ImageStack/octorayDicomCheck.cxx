// The file-level rules of the structure check: the preamble and "DICM" (or
// a bare data set), the file meta group (0002) in explicit VR little endian
// with its group length and transfer syntax, the encoding the transfer
// syntax gives the data set, and what GDCM 3.0 cannot take even in a sound
// file. The bytes and element headers are in octorayDicomElements.h, the
// walk over the data set in octorayDicomWalker.h.
#include "octorayDicomCheck.h"

#include "octorayDicomElements.h"
#include "octorayDicomWalker.h"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace
{
using namespace octoray::dicom;

// What a transfer syntax says of the data set after the file meta group.
enum class Syntax
{
  Walk,     // walk it in the encoding found
  Deflated, // a zlib stream: nothing more to walk
  Failed    // the bytes could not be read
};

// Group 0002 at pos, always explicit VR little endian; the transfer syntax
// UID comes back in syntax (without its padding), pos after the group.
class MetaGroup
{
public:
  explicit MetaGroup(Elements& elements)
    : E(elements)
  {
  }

  bool Read(uint64_t& pos, std::string& syntax)
  {
    const uint64_t size = this->E.Size();
    const uint64_t start = pos;
    while (size - pos >= 2)
    {
      unsigned char g[2];
      if (!this->E.Get(pos, g, 2))
      {
        return false;
      }
      if (U16(g, false) != 0x0002)
      {
        break;
      }
      Header h;
      if (!this->E.ReadHeader(pos, size, Encoding(), h, " (file meta group)") ||
        !this->E.CheckFits(h, size, "DICOM file meta element") || !this->Element(h, syntax))
      {
        return false;
      }
      pos = h.ValueStart + h.Length;
    }
    // The group length is where GDCM stops reading the group: elements it
    // covers must end exactly there.
    if (this->HasLength && pos != this->End)
    {
      return this->E.Fail("the DICOM file meta group length (0002,0000) at byte " +
        std::to_string(this->LengthAt) + " says the group ends at byte " +
        std::to_string(this->End) + ", but its elements end at byte " + std::to_string(pos));
    }
    return pos == start || this->DataSetFollows(pos);
  }

private:
  // GDCM 3.0 reads the tag after a group without looking whether the file
  // has one, and asserts (aborts) where it has not.
  bool DataSetFollows(uint64_t pos)
  {
    const uint64_t left = this->E.Size() - pos;
    if (left >= 4)
    {
      return true;
    }
    if (left == 0)
    {
      return this->E.Fail("the DICOM file ends at byte " + std::to_string(pos) +
        " with its file meta group: no data set follows it");
    }
    return this->E.Fail("the DICOM file ends " + std::to_string(left) + " bytes after its file meta group (at byte " +
      std::to_string(pos) + "): no data set element fits there");
  }

  // The group length and the transfer syntax; the other elements are
  // skipped. GDCM 3.0 asserts on a sequence or an undefined length here.
  bool Element(const Header& h, std::string& syntax)
  {
    if (h.Length == UndefinedLength)
    {
      return this->E.Fail("DICOM file meta element " + h.Name() + " at byte " +
        std::to_string(h.Start) + " has an undefined length");
    }
    if (IsVR(h.VR, "SQ"))
    {
      return this->E.Fail("DICOM file meta element " + h.Name() + " at byte " + std::to_string(h.Start) +
        " is a sequence (SQ), which the file meta group cannot hold");
    }
    if (h.Element == 0x0000)
    {
      // GDCM 3.0 asserts (aborts) on a group length of another VR or size.
      if (std::string(h.VR, 2) != "UL" || h.Length != 4)
      {
        return this->E.Fail("the DICOM file meta group length (0002,0000) at byte " + std::to_string(h.Start) +
          " is a " + std::string(h.VR, 2) + " of " + std::to_string(h.Length) +
          " bytes; it must be a UL of 4 bytes");
      }
      return this->GroupLength(h);
    }
    if (h.Element == 0x0010)
    {
      return this->TransferSyntax(h, syntax);
    }
    return true;
  }

  bool GroupLength(const Header& h)
  {
    unsigned char v[4];
    if (!this->E.Get(h.ValueStart, v, 4))
    {
      return false;
    }
    this->HasLength = true;
    this->LengthAt = h.Start;
    this->End = h.ValueStart + 4 + U32(v, false);
    if (this->End > this->E.Size())
    {
      return this->E.Fail("the DICOM file meta group length (0002,0000) at byte " +
        std::to_string(h.Start) + " says the group ends at byte " + std::to_string(this->End) +
        ", the file has " + std::to_string(this->E.Size()));
    }
    return true;
  }

  bool TransferSyntax(const Header& h, std::string& syntax)
  {
    if (h.Length > 64)
    {
      return this->E.Fail("the DICOM transfer syntax UID (0002,0010) at byte " +
        std::to_string(h.Start) + " is " + std::to_string(h.Length) +
        " bytes long; a UID has at most 64");
    }
    std::string v(h.Length, '\0');
    if (!this->E.Get(h.ValueStart, &v[0], h.Length))
    {
      return false;
    }
    while (!v.empty() && (v.back() == '\0' || v.back() == ' '))
    {
      v.pop_back();
    }
    syntax = v;
    return true;
  }

  Elements& E;
  bool HasLength = false;
  uint64_t LengthAt = 0; // where the group length (0002,0000) is
  uint64_t End = 0;      // where it says the group ends
};

// The encoding of the data set at pos, from the transfer syntax and, where
// GDCM looks at them too, the data set's first bytes.
Syntax DataSetEncoding(Elements& e, const std::string& syntax, uint64_t pos, Encoding& enc)
{
  const bool room = e.Size() - pos >= 6;
  unsigned char b[6];
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
    return Syntax::Deflated;
  }
  else if (syntax.empty() && room)
  {
    // No file meta group, or one without a transfer syntax: like GDCM, take
    // the encoding from the first element (group 0008 is 08 00 in little
    // endian, 00 08 in big endian; explicit VR has a VR after it).
    if (!e.Get(pos, b, 6))
    {
      return Syntax::Failed;
    }
    enc.BigEndian = b[0] == 0 && b[1] != 0;
    const char vr[2] = { static_cast<char>(b[4]), static_cast<char>(b[5]) };
    enc.Explicit = IsShortVR(vr) || IsLongVR(vr);
  }
  else if (!syntax.empty() && room)
  {
    // A transfer syntax that says explicit VR over a data set written in
    // implicit VR is a common writer bug; GDCM sees it at the first element
    // and reads the data set as implicit VR, and so does this.
    if (!e.Get(pos, b, 6))
    {
      return Syntax::Failed;
    }
    const char vr[2] = { static_cast<char>(b[4]), static_cast<char>(b[5]) };
    enc.Explicit = IsShortVR(vr) || IsLongVR(vr) || U16(b, false) == 0xFFFE;
  }
  return Syntax::Walk;
}

std::string Check(Bytes& bytes)
{
  const uint64_t size = bytes.Size();
  unsigned char magic[4];
  const bool part10 =
    size >= 132 && bytes.Read(128, magic, 4) && std::memcmp(magic, "DICM", 4) == 0;
  if (!bytes.Error.empty())
  {
    return bytes.Error;
  }
  uint64_t pos = part10 ? 132 : 0;
  Elements e(bytes);
  std::string syntax;
  if (!MetaGroup(e).Read(pos, syntax))
  {
    return e.Error();
  }
  Encoding enc;
  const Syntax s = DataSetEncoding(e, syntax, pos, enc);
  if (s != Syntax::Walk)
  {
    return s == Syntax::Deflated ? std::string() : e.Error();
  }
  DataSetWalker walker(e, enc);
  if (!walker.Walk(pos, size))
  {
    return e.Error();
  }
  // Sound structure that GDCM 3.0 still cannot take: for an RT dose with a
  // grid frame offset vector it reads the number of frames without looking
  // whether there is one, and an assert() stops the process.
  if (walker.GridFrameOffsetAt && !walker.HasNumberOfFrames)
  {
    return "the DICOM grid frame offset vector (3004,000C) at byte " +
      std::to_string(walker.GridFrameOffsetAt) +
      " comes without a number of frames (0028,0008), which GDCM 3.0 cannot read";
  }
  return {};
}
} // namespace

namespace octoray
{
std::string CheckDicomStructure(const unsigned char* data, size_t size)
{
  Bytes bytes(data, size);
  return Check(bytes);
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
  std::string error = Check(bytes);
  ::close(fd);
  return error;
}
} // namespace octoray
