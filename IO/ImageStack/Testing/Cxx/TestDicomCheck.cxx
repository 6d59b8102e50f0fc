// The structural check that vtkSliceStackReader runs on a DICOM file before
// GDCM sees it (octorayDicomCheck.h): files built here byte by byte, sound
// and damaged, each damage with the message it must give, and the bundled
// series. The fuzz findings that made GDCM 3.0 abort are
// TestDicomFindings.cxx.
#include "octorayDicomCheck.h"
#include "octorayTestCheck.h"

#include "vtkTestUtilities.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace
{
namespace fs = std::filesystem;
const uint32_t Undefined = 0xFFFFFFFFu;

// A DICOM file written element by element.
struct Dicom
{
  std::vector<unsigned char> Bytes;
  bool Big = false;
  bool Explicit = true;

  size_t Size() const { return this->Bytes.size(); }
  void U16(uint16_t v)
  {
    const unsigned char b[2] = { static_cast<unsigned char>(this->Big ? v >> 8 : v),
      static_cast<unsigned char>(this->Big ? v : v >> 8) };
    this->Bytes.insert(this->Bytes.end(), b, b + 2);
  }
  void U32(uint32_t v)
  {
    if (this->Big)
    {
      this->U16(static_cast<uint16_t>(v >> 16));
      this->U16(static_cast<uint16_t>(v));
    }
    else
    {
      this->U16(static_cast<uint16_t>(v));
      this->U16(static_cast<uint16_t>(v >> 16));
    }
  }
  void Raw(const std::string& s) { this->Bytes.insert(this->Bytes.end(), s.begin(), s.end()); }
  // An element's header: explicit VR (2- or 4-byte length by VR) or implicit.
  void Head(uint16_t g, uint16_t e, const char* vr, uint32_t length)
  {
    this->U16(g);
    this->U16(e);
    if (!this->Explicit)
    {
      this->U32(length);
      return;
    }
    this->Raw(std::string(vr, 2));
    static const std::string longVRs = "OB OD OF OL OV OW SQ SV UC UN UR UT UV";
    if (longVRs.find(std::string(vr, 2)) != std::string::npos)
    {
      this->U16(0);
      this->U32(length);
    }
    else
    {
      this->U16(static_cast<uint16_t>(length));
    }
  }
  void Element(uint16_t g, uint16_t e, const char* vr, const std::string& value)
  {
    this->Head(g, e, vr, static_cast<uint32_t>(value.size()));
    this->Raw(value);
  }
  void Item(uint32_t length)
  {
    this->U16(0xFFFE);
    this->U16(0xE000);
    this->U32(length);
  }
  void ItemEnd()
  {
    this->U16(0xFFFE);
    this->U16(0xE00D);
    this->U32(0);
  }
  void SequenceEnd()
  {
    this->U16(0xFFFE);
    this->U16(0xE0DD);
    this->U32(0);
  }
  std::string Check() const { return octoray::CheckDicomStructure(this->Bytes.data(), this->Size()); }
};

const char* const ExplicitLE = "1.2.840.10008.1.2.1";
const char* const ImplicitLE = "1.2.840.10008.1.2";
const char* const ExplicitBE = "1.2.840.10008.1.2.2";
const char* const JPEGBaseline = "1.2.840.10008.1.2.4.50";

// Preamble, "DICM" and a file meta group (always explicit VR little endian)
// naming the transfer syntax; the data set then in that encoding.
Dicom Part10(const std::string& syntax)
{
  Dicom meta;
  const std::string uid = syntax.size() % 2 ? syntax + '\0' : syntax;
  meta.Element(0x0002, 0x0001, "OB", std::string("\0\1", 2));
  meta.Element(0x0002, 0x0010, "UI", uid);
  Dicom d;
  d.Bytes.assign(128, 0);
  d.Raw("DICM");
  d.Element(0x0002, 0x0000, "UL", std::string(4, '\0'));
  const uint32_t n = static_cast<uint32_t>(meta.Size());
  std::memcpy(&d.Bytes[d.Size() - 4], &n, 4);
  d.Bytes.insert(d.Bytes.end(), meta.Bytes.begin(), meta.Bytes.end());
  d.Explicit = syntax != ImplicitLE;
  d.Big = syntax == ExplicitBE;
  return d;
}

// A small image's header and its 2x2 16-bit pixels.
void Image(Dicom& d)
{
  d.Element(0x0008, 0x0060, "CS", "CT");
  d.Element(0x0028, 0x0010, "US", std::string("\2\0", 2));
  d.Element(0x0028, 0x0011, "US", std::string("\2\0", 2));
  d.Element(0x7FE0, 0x0010, "OW", std::string(8, '\x7'));
}

#define CHECK_SOUND(dicom)                                                                         \
  do                                                                                               \
  {                                                                                                \
    const std::string e_ = (dicom).Check();                                                        \
    if (!e_.empty())                                                                               \
    {                                                                                              \
      octoray_test::Report(__FILE__, __LINE__, "sound file rejected: " + e_);                      \
    }                                                                                              \
  } while (0)

// Every transfer syntax's encoding, sequences and items of both lengths,
// encapsulated pixel data, an undefined-length UN, a bare data set.
void TestSoundFiles()
{
  for (const char* syntax : { ExplicitLE, ImplicitLE, ExplicitBE })
  {
    Dicom d = Part10(syntax);
    Image(d);
    CHECK_SOUND(d);
  }
  {
    // Sequences: undefined length with an undefined-length item holding a
    // defined-length sequence of one defined-length item, and an empty one.
    for (const char* syntax : { ExplicitLE, ImplicitLE })
    {
      Dicom d = Part10(syntax);
      d.Element(0x0008, 0x0060, "CS", "CT");
      d.Head(0x0008, 0x1115, "SQ", Undefined);
      d.Item(Undefined);
      d.Element(0x0008, 0x1150, "UI", "1.2\0");
      Dicom inner;
      inner.Explicit = d.Explicit;
      inner.Element(0x0008, 0x0100, "SH", "AB");
      d.Head(0x0040, 0xA043, "SQ", static_cast<uint32_t>(8 + inner.Size()));
      d.Item(static_cast<uint32_t>(inner.Size()));
      d.Bytes.insert(d.Bytes.end(), inner.Bytes.begin(), inner.Bytes.end());
      d.ItemEnd();
      d.SequenceEnd();
      d.Head(0x0008, 0x1140, "SQ", 0);
      Image(d);
      CHECK_SOUND(d);
    }
  }
  {
    // Encapsulated pixel data: an empty offset table, two fragments.
    Dicom d = Part10(JPEGBaseline);
    d.Element(0x0028, 0x0010, "US", std::string("\2\0", 2));
    d.Head(0x7FE0, 0x0010, "OB", Undefined);
    d.Item(0);
    d.Item(4);
    d.Raw("\xFF\xD8\xFF\xD9");
    d.Item(2);
    d.Raw("ab");
    d.SequenceEnd();
    CHECK_SOUND(d);
  }
  {
    // An undefined-length UN: a sequence in implicit VR little endian.
    Dicom d = Part10(ExplicitLE);
    d.Head(0x0009, 0x1010, "UN", Undefined);
    d.Explicit = false;
    d.Item(Undefined);
    d.Element(0x0009, 0x1001, "", "ab");
    d.ItemEnd();
    d.SequenceEnd();
    d.Explicit = true;
    Image(d);
    CHECK_SOUND(d);
  }
  {
    // No preamble or file meta group: a bare implicit VR data set; and
    // explicit VR announced over an implicit VR data set (read as implicit,
    // as GDCM does).
    Dicom bare;
    bare.Explicit = false;
    Image(bare);
    CHECK_SOUND(bare);
    Dicom liar = Part10(ExplicitLE);
    liar.Explicit = false;
    Image(liar);
    CHECK_SOUND(liar);
  }
}

void TestBundledSeries(const std::string& data)
{
  for (const auto& e : fs::directory_iterator(data + "/DICOM/CT5N"))
  {
    CHECK_EQ_STR(octoray::CheckDicomStructure(e.path().string()), "");
  }
  CHECK_EQ_STR(octoray::CheckDicomStructure(data + "/DICOM/CT_small/CT_small.dcm"), "");
}

// Lengths past the end of the file, and undefined where none may be.
void TestLengths()
{
  {
    // The length of a value runs past the end of the file.
    Dicom d = Part10(ImplicitLE);
    const size_t at = d.Size();
    d.Head(0x0028, 0x0010, "US", 2600000000u);
    d.Raw("\2\0");
    CHECK_EQ_STR(d.Check(),
      "DICOM element (0028,0010) at byte " + std::to_string(at) +
        " claims 2600000000 bytes, the file has " + std::to_string(d.Size()));
  }
  {
    // Undefined lengths: a sequence and an item that never end, a VR that
    // allows none, a pixel data fragment.
    Dicom s = Part10(ExplicitLE);
    const size_t sat = s.Size();
    s.Head(0x0008, 0x1115, "SQ", Undefined);
    s.Item(0);
    CHECK_EQ_STR(s.Check(),
      "the DICOM sequence (0008,1115) at byte " + std::to_string(sat) +
        " has no sequence delimiter (FFFE,E0DD) before the end of the file");
    Dicom i = Part10(ExplicitLE);
    i.Head(0x0008, 0x1115, "SQ", Undefined);
    const size_t iat = i.Size();
    i.Item(Undefined);
    i.Element(0x0008, 0x1150, "UI", "1.2\0");
    CHECK_EQ_STR(i.Check(),
      "the DICOM item at byte " + std::to_string(iat) +
        " has an undefined length and no item delimiter (FFFE,E00D) before the end of the file");
    Dicom v = Part10(ExplicitLE);
    const size_t vat = v.Size();
    v.Head(0x0028, 0x0010, "OD", Undefined);
    CHECK_EQ_STR(v.Check(),
      "DICOM element (0028,0010) at byte " + std::to_string(vat) +
        " has an undefined length, which VR OD does not allow");
    Dicom f = Part10(JPEGBaseline);
    f.Head(0x7FE0, 0x0010, "OB", Undefined);
    const size_t fat = f.Size();
    f.Item(Undefined);
    CHECK_EQ_STR(f.Check(),
      "the pixel data fragment at byte " + std::to_string(fat) +
        " claims an undefined length, the file has " + std::to_string(f.Size()));
  }
}

// Bytes that are no VR; headers cut short.
void TestHeaders()
{
  {
    Dicom d = Part10(ExplicitLE);
    d.Element(0x0008, 0x0060, "CS", "CT");
    const size_t at = d.Size();
    d.Element(0x0028, 0x0010, "Q\x01", "ab");
    CHECK_EQ_STR(d.Check(),
      "DICOM element (0028,0010) at byte " + std::to_string(at) +
        " has no valid VR: found 'Q\\x01' where explicit VR little endian expects one");
  }
  {
    // Headers cut short: 5 bytes of a tag, and a long-VR header of 10 bytes.
    Dicom d = Part10(ExplicitLE);
    Image(d);
    const size_t at = d.Size();
    d.Raw(std::string("\x08\x00\x10\x00\x00", 5));
    CHECK_EQ_STR(d.Check(),
      "a DICOM element header at byte " + std::to_string(at) +
        " is cut short: it needs 8 bytes, the file has " + std::to_string(d.Size()));
    Dicom l = Part10(ExplicitLE);
    const size_t lat = l.Size();
    l.Head(0x7FE0, 0x0010, "OW", 8);
    l.Bytes.resize(l.Size() - 2);
    CHECK_EQ_STR(l.Check(),
      "the header of DICOM element (7FE0,0010) at byte " + std::to_string(lat) +
        " is cut short: it needs 12 bytes, the file has " + std::to_string(l.Size()));
  }
}

// Items and elements longer than what encloses them, stray delimiters,
// nesting too deep.
void TestEnclosing()
{
  {
    // An item longer than its defined-length sequence; an element longer
    // than its item.
    Dicom d = Part10(ExplicitLE);
    d.Head(0x0008, 0x1115, "SQ", 8 + 10);
    const size_t iat = d.Size();
    d.Item(40);
    d.Element(0x0008, 0x1150, "UI", "1.2\0");
    d.Raw("xx");
    Image(d);
    CHECK_EQ_STR(d.Check(),
      "the DICOM item at byte " + std::to_string(iat) +
        " of sequence (0008,1115) claims 40 bytes, its enclosing item or sequence ends at byte " +
        std::to_string(iat + 18));
    Dicom e = Part10(ExplicitLE);
    e.Head(0x0008, 0x1115, "SQ", 8 + 12);
    e.Item(12);
    const size_t eat = e.Size();
    e.Element(0x0008, 0x1150, "UI", "1.2.3.45");
    Image(e);
    CHECK_EQ_STR(e.Check(),
      "DICOM element (0008,1150) at byte " + std::to_string(eat) +
        " claims 8 bytes, its enclosing item or sequence ends at byte " + std::to_string(eat + 12));
  }
  {
    // Stray delimiters and items; something else than an item in a sequence.
    Dicom d = Part10(ExplicitLE);
    Image(d);
    const size_t at = d.Size();
    d.ItemEnd();
    CHECK_EQ_STR(d.Check(),
      "unexpected item delimiter (FFFE,E00D) at byte " + std::to_string(at) + " in the data set");
    Dicom s = Part10(ExplicitLE);
    const size_t sat = s.Size();
    s.Head(0x0008, 0x1115, "SQ", Undefined);
    const size_t xat = s.Size();
    s.Element(0x0008, 0x1150, "UI", "1.2\0");
    s.SequenceEnd();
    CHECK_EQ_STR(s.Check(),
      "DICOM sequence (0008,1115) at byte " + std::to_string(sat) + " holds (0008,1150) at byte " +
        std::to_string(xat) + " where an item (FFFE,E000) or its delimiter (FFFE,E0DD) must be");
  }
  {
    // Nesting: 40 undefined-length sequences in each other's items.
    Dicom d = Part10(ExplicitLE);
    size_t at = 0;
    for (int k = 0; k < 40; ++k)
    {
      if (k == octoray::DicomMaximumDepth)
      {
        at = d.Size();
      }
      d.Head(0x0008, 0x1115, "SQ", Undefined);
      d.Item(Undefined);
    }
    CHECK_EQ_STR(d.Check(),
      "DICOM sequence (0008,1115) at byte " + std::to_string(at) + " is nested more than " +
        std::to_string(octoray::DicomMaximumDepth) + " levels deep");
  }
}

// The file meta group: its length past the end of the file, a length
// that does not end where its elements end, a group length that is not a
// 4-byte UL, a transfer syntax UID longer than a UID can be, no data set
// after it, a sequence in it.
void TestFileMeta()
{
  Dicom d = Part10(ExplicitLE);
  Image(d);
  d.Bytes[140] = 0xFF;
  d.Bytes[141] = 0xFF;
  const uint32_t claimed = 0xFFFF;
  CHECK_EQ_STR(d.Check(),
    "the DICOM file meta group length (0002,0000) at byte 132 says the group ends at byte " +
      std::to_string(144 + claimed) + ", the file has " + std::to_string(d.Size()));
  Dicom m = Part10(ExplicitLE);
  const size_t metaEnd = m.Size();
  Image(m);
  m.Bytes[140] -= 2;
  CHECK_EQ_STR(m.Check(),
    "the DICOM file meta group length (0002,0000) at byte 132 says the group ends at byte " +
      std::to_string(metaEnd - 2) + ", but its elements end at byte " + std::to_string(metaEnd));
  // A group length of another size or VR, on which GDCM 3.0 asserts (a
  // fuzzer's find: Testing/Fuzz/regressions/slice_stack/dicom_meta_length_assert).
  Dicom l = Part10(ExplicitLE);
  Image(l);
  l.Bytes[138] = 8;
  CHECK_EQ_STR(l.Check(),
    "the DICOM file meta group length (0002,0000) at byte 132 is a UL of 8 bytes; it must be a UL of 4 bytes");
  Dicom v = Part10(ExplicitLE);
  Image(v);
  v.Bytes[136] = 'U';
  v.Bytes[137] = 'S';
  CHECK_EQ_STR(v.Check(),
    "the DICOM file meta group length (0002,0000) at byte 132 is a US of 4 bytes; it must be a UL of 4 bytes");
  Dicom u = Part10(std::string(70, '1'));
  CHECK_EQ_STR(u.Check().substr(0, 52), "the DICOM transfer syntax UID (0002,0010) at byte 15");
  CHECK_CONTAINS(u.Check(), "is 70 bytes long; a UID has at most 64");
  // GDCM 3.0 asserts where the file ends with the group or too soon after
  // it, and on a sequence in the group (a fuzzer's find:
  // Testing/Fuzz/regressions/slice_stack/dicom_meta_end_assert).
  Dicom e = Part10(ExplicitLE);
  const std::string metaEnds = std::to_string(e.Size());
  CHECK_EQ_STR(e.Check(), "the DICOM file ends at byte " + metaEnds + " with its file meta group: no data set follows it");
  e.Raw(std::string("\x08\0", 2));
  CHECK_EQ_STR(e.Check(),
    "the DICOM file ends 2 bytes after its file meta group (at byte " + metaEnds + "): no data set element fits there");
  Dicom q;
  q.Bytes.assign(128, 0);
  q.Raw("DICM");
  q.Element(0x0002, 0x0001, "OB", std::string("\0\1", 2));
  q.Element(0x0002, 0x0002, "SQ", "");
  Image(q);
  CHECK_EQ_STR(q.Check(),
    "DICOM file meta element (0002,0002) at byte 146 is a sequence (SQ), which the file meta group cannot hold");
}

// Sound structure on which GDCM 3.0 still stops the process (seen with
// pydicom's rtdose_1frame.dcm).
void TestGdcmRules()
{
  Dicom g = Part10(ImplicitLE);
  g.Element(0x0008, 0x0016, "UI", "1.2.840.10008.5.1.4.1.1.481.2");
  g.Element(0x0028, 0x0010, "US", std::string("\2\0", 2));
  const size_t offsetAt = g.Size();
  g.Element(0x3004, 0x000C, "DS", "0\\1 ");
  g.Element(0x7FE0, 0x0010, "OW", std::string(8, '\x7'));
  CHECK_EQ_STR(g.Check(),
    "the DICOM grid frame offset vector (3004,000C) at byte " + std::to_string(offsetAt) +
      " comes without a number of frames (0028,0008), which GDCM 3.0 cannot read");
  g.Element(0x0028, 0x0008, "IS", "2 ");
  CHECK_SOUND(g);

  // An image element that GDCM reads as an attribute, stated with another
  // VR than the standard's (a fuzzed file had columns as IS): GDCM asserts.
  for (const std::string vr : { "US", "IS" })
  {
    const bool standard = vr == "US";
    Dicom e = Part10(ExplicitLE);
    const size_t columnsAt = e.Size();
    e.Element(0x0028, 0x0011, vr.c_str(), standard ? std::string("\2\0", 2) : std::string("2 "));
    e.Element(0x7FE0, 0x0010, "OW", std::string(8, '\x7'));
    if (standard)
    {
      CHECK_SOUND(e);
    }
    else
    {
      CHECK_EQ_STR(e.Check(),
        "DICOM element (0028,0011) at byte " + std::to_string(columnsAt) +
          " has VR IS where the standard gives US, which GDCM 3.0 cannot read");
    }
  }
}
} // namespace

int TestDicomCheck(int argc, char* argv[])
{
  char* data = vtkTestUtilities::ExpandDataFileName(argc, argv, "Data");
  TestSoundFiles();
  TestBundledSeries(data);
  delete[] data;
  TestLengths();
  TestHeaders();
  TestEnclosing();
  TestFileMeta();
  TestGdcmRules();
  return octoray_test::Result();
}
