// The bytes of a DICOM file and the headers of its elements, for the
// structure check (octorayDicomCheck.h): a reader of bytes at offsets
// (through a window on the file, or from memory), the encodings (explicit or
// implicit VR, little or big endian), the VRs of PS3.5 table 7.1-1/2, and
// an element header read and checked against the bytes around it, with the
// texts that name what is wrong where. Only tags, VRs and lengths are read.
// Private to the module; not wrapped.
#ifndef octorayDicomElements_h
#define octorayDicomElements_h

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace octoray
{
namespace dicom
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
  bool Read(uint64_t off, void* dst, size_t n);

  std::string Error;

private:
  bool Fill(uint64_t off, size_t n);

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

inline uint16_t U16(const unsigned char* p, bool big)
{
  return big ? static_cast<uint16_t>(p[0] << 8 | p[1]) : static_cast<uint16_t>(p[1] << 8 | p[0]);
}

inline uint32_t U32(const unsigned char* p, bool big)
{
  return big ? (uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3])
             : (uint32_t(p[3]) << 24 | uint32_t(p[2]) << 16 | uint32_t(p[1]) << 8 | p[0]);
}

// VRs with a 2-byte length, and those with 2 reserved bytes and a 4-byte
// length; a VR by name.
bool IsShortVR(const char* v);
bool IsLongVR(const char* v);
inline bool IsVR(const char* v, const char* vr)
{
  return v[0] == vr[0] && v[1] == vr[1];
}

// "(0028,0010)".
std::string TagName(uint16_t g, uint16_t e);
// Bytes that should have been a VR, printable or as \xNN.
std::string Shown(const char* v);

struct Header
{
  uint64_t Start = 0;
  uint16_t Group = 0, Element = 0;
  char VR[2] = { 0, 0 }; // explicit VR only; not for items and delimiters
  bool HasVR = false;
  uint32_t Length = 0;
  uint64_t ValueStart = 0;

  std::string Name() const { return TagName(this->Group, this->Element); }
  bool Is(uint16_t g, uint16_t e) const { return this->Group == g && this->Element == e; }
};

// Element headers read from the bytes, each checked against the end of the
// file or of the item or sequence around it; the first error is kept.
class Elements
{
public:
  explicit Elements(Bytes& bytes)
    : B(bytes)
  {
  }
  uint64_t Size() const { return this->B.Size(); }
  const std::string& Error() const { return this->Message; }

  // Keeps message unless an error came first; false.
  bool Fail(const std::string& message);
  // n bytes at off.
  bool Get(uint64_t off, void* dst, size_t n);

  // The tag, VR and length at pos, which must fit before end; `where` is
  // added to the position in messages (" (file meta group)").
  bool ReadHeader(uint64_t pos, uint64_t end, Encoding enc, Header& h, const char* where);
  // The value of h must end by end: "<what> (gggg,eeee) at byte ... claims ...".
  bool CheckFits(const Header& h, uint64_t end, const char* what);

  // Where something that does not fit would have to end: "the file has N"
  // or "its enclosing item or sequence ends at byte N".
  std::string Limit(uint64_t end) const;
  // What something ran into before it ended: "the end of the file" or
  // "byte N".
  std::string Before(uint64_t end) const;

private:
  Bytes& B;
  std::string Message;
};
} // namespace dicom
} // namespace octoray

#endif
