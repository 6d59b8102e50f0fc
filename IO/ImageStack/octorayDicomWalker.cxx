#include "octorayDicomWalker.h"

#include "octorayDicomCheck.h"

namespace octoray
{
namespace dicom
{
namespace
{
bool IsPixelData(const Header& h)
{
  return h.Is(0x7FE0, 0x0010);
}

const char* DelimiterName(uint16_t element)
{
  return element == 0xE000 ? "item"
    : element == 0xE00D    ? "item delimiter"
    : element == 0xE0DD    ? "sequence delimiter"
                           : "element";
}

// The image elements GDCM 3.0 reads through gdcm::Attribute, with the VR
// the standard gives each: an Attribute asserts (stops the process) when the
// VR a file states is another (a fuzzed Columns stated as IS did).
struct ImageElement
{
  uint16_t Group;
  uint16_t Element;
  const char* VR;
};
constexpr ImageElement ImageElements[] = {
  { 0x0020, 0x0032, "DS" }, // image position (patient)
  { 0x0020, 0x0037, "DS" }, // image orientation (patient)
  { 0x0028, 0x0002, "US" }, // samples per pixel
  { 0x0028, 0x0006, "US" }, // planar configuration
  { 0x0028, 0x0008, "IS" }, // number of frames
  { 0x0028, 0x0010, "US" }, // rows
  { 0x0028, 0x0011, "US" }, // columns
  { 0x0028, 0x0030, "DS" }, // pixel spacing
  { 0x0028, 0x0100, "US" }, // bits allocated
  { 0x0028, 0x0101, "US" }, // bits stored
  { 0x0028, 0x0102, "US" }, // high bit
  { 0x0028, 0x0103, "US" }, // pixel representation
  { 0x0028, 0x1052, "DS" }, // rescale intercept
  { 0x0028, 0x1053, "DS" }, // rescale slope
};

// The VR the standard gives h's element where GDCM needs it, else null.
const char* RequiredImageVR(const Header& h)
{
  for (const ImageElement& e : ImageElements)
  {
    if (h.Is(e.Group, e.Element))
    {
      return e.VR;
    }
  }
  return nullptr;
}
} // namespace

//------------------------------------------------------------------------------
bool DataSetWalker::Walk(uint64_t pos, uint64_t end)
{
  return this->DataSet(pos, end, 0, 0, this->DataSetEncoding);
}

//------------------------------------------------------------------------------
// Elements from pos to end, or (itemStart > 0) up to and including the item
// delimiter of an undefined-length item that starts at itemStart.
bool DataSetWalker::DataSet(
  uint64_t& pos, uint64_t end, uint64_t itemStart, int depth, Encoding enc)
{
  const char* where = depth == 0 ? "" : " (in a sequence item)";
  while (pos < end)
  {
    Header h;
    if (!this->E.ReadHeader(pos, end, enc, h, where))
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
      return this->E.Fail("unexpected " + std::string(DelimiterName(h.Element)) + " " +
        h.Name() + " at byte " + std::to_string(pos) +
        (depth == 0 ? " in the data set" : " inside an item"));
    }
    const uint64_t start = pos;
    if (depth == 0)
    {
      this->HasNumberOfFrames |= h.Is(0x0028, 0x0008);
      if (h.Is(0x3004, 0x000C))
      {
        this->GridFrameOffsetAt = pos;
      }
    }
    if (h.Length == UndefinedLength)
    {
      if (!this->UndefinedLengthValue(h, pos, end, depth, enc))
      {
        return false;
      }
    }
    else
    {
      if (!this->E.CheckFits(h, end, "DICOM element") || !this->DefinedLengthValue(h, depth, enc))
      {
        return false;
      }
      pos = h.ValueStart + h.Length;
    }
    // A sound element that GDCM still cannot take.
    const char* required = depth == 0 && enc.Explicit ? RequiredImageVR(h) : nullptr;
    if (required && std::string(h.VR, 2) != required)
    {
      return this->E.Fail("DICOM element " + h.Name() + " at byte " + std::to_string(start) + " has VR " +
        std::string(h.VR, 2) + " where the standard gives " + required + ", which GDCM 3.0 cannot read");
    }
  }
  if (itemStart > 0)
  {
    return this->E.Fail("the DICOM item at byte " + std::to_string(itemStart) +
      " has an undefined length and no item delimiter (FFFE,E00D) before " + this->E.Before(end));
  }
  return true;
}

//------------------------------------------------------------------------------
// A value of undefined length: encapsulated pixel data or a sequence, which
// pos then ends after; any other VR allows none.
bool DataSetWalker::UndefinedLengthValue(
  const Header& h, uint64_t& pos, uint64_t end, int depth, Encoding enc)
{
  if (IsPixelData(h) && (!h.HasVR || IsVR(h.VR, "OB") || IsVR(h.VR, "OW")))
  {
    return this->Fragments(h, pos, end);
  }
  if (!h.HasVR || IsVR(h.VR, "SQ") || IsVR(h.VR, "UN"))
  {
    // An undefined-length UN is a sequence in implicit VR little endian
    // (PS3.5 6.2.2).
    const Encoding inner = h.HasVR && IsVR(h.VR, "UN") ? Encoding{ false, false } : enc;
    return this->Sequence(h, pos, end, depth + 1, inner);
  }
  return this->E.Fail("DICOM element " + h.Name() + " at byte " + std::to_string(h.Start) +
    " has an undefined length, which VR " + Shown(h.VR) + " does not allow");
}

//------------------------------------------------------------------------------
// A value of defined length, which fits: walked when it is a sequence. That
// is SQ in explicit VR; in implicit VR (and for UN, which GDCM reads as a
// sequence when its dictionary says SQ) any value that starts with an item
// tag, as GDCM would parse it.
bool DataSetWalker::DefinedLengthValue(const Header& h, int depth, Encoding enc)
{
  bool sequence = h.HasVR && IsVR(h.VR, "SQ");
  Encoding inner = enc;
  if (!sequence && (!h.HasVR || IsVR(h.VR, "UN")) && h.Length >= 8 && !IsPixelData(h))
  {
    if (h.HasVR)
    {
      inner = Encoding{ false, false };
    }
    unsigned char t[4];
    if (!this->E.Get(h.ValueStart, t, 4))
    {
      return false;
    }
    sequence = U16(t, inner.BigEndian) == 0xFFFE && U16(t + 2, inner.BigEndian) == 0xE000;
  }
  uint64_t pos = h.Start;
  return !sequence || this->Sequence(h, pos, h.ValueStart + h.Length, depth + 1, inner);
}

//------------------------------------------------------------------------------
// The items of sequence seq; pos ends after it. A defined-length sequence
// ends at end (its value's end).
bool DataSetWalker::Sequence(
  const Header& seq, uint64_t& pos, uint64_t end, int depth, Encoding enc)
{
  if (depth > octoray::DicomMaximumDepth)
  {
    return this->E.Fail("DICOM sequence " + seq.Name() + " at byte " + std::to_string(seq.Start) +
      " is nested more than " + std::to_string(octoray::DicomMaximumDepth) + " levels deep");
  }
  const bool undefined = seq.Length == UndefinedLength;
  pos = seq.ValueStart;
  while (undefined || pos != end)
  {
    if (end - pos < 8)
    {
      return this->E.Fail("the DICOM sequence " + seq.Name() + " at byte " +
        std::to_string(seq.Start) +
        (undefined ? " has no sequence delimiter (FFFE,E0DD)" : " ends inside an item header") +
        " before " + this->E.Before(end));
    }
    unsigned char b[8];
    if (!this->E.Get(pos, b, 8))
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
      return this->E.Fail("DICOM sequence " + seq.Name() + " at byte " +
        std::to_string(seq.Start) + " holds " + TagName(g, e) + " at byte " +
        std::to_string(pos) + " where an item (FFFE,E000)" +
        (undefined ? " or its delimiter (FFFE,E0DD)" : "") + " must be");
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
      return this->E.Fail("the DICOM item at byte " + std::to_string(itemStart) +
        " of sequence " + seq.Name() + " claims " + std::to_string(length) + " bytes, " +
        this->E.Limit(end));
    }
    if (!this->DataSet(pos, pos + length, 0, depth, enc))
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
// Encapsulated pixel data: items of defined length (the basic offset table,
// then the fragments) up to a sequence delimiter.
bool DataSetWalker::Fragments(const Header& px, uint64_t& pos, uint64_t end)
{
  pos = px.ValueStart;
  const bool big = this->DataSetEncoding.BigEndian;
  while (true)
  {
    if (end - pos < 8)
    {
      return this->E.Fail("the encapsulated pixel data " + px.Name() + " at byte " +
        std::to_string(px.Start) + " has no sequence delimiter (FFFE,E0DD) before " +
        this->E.Before(end));
    }
    unsigned char b[8];
    if (!this->E.Get(pos, b, 8))
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
      return this->E.Fail("the encapsulated pixel data " + px.Name() + " at byte " +
        std::to_string(px.Start) + " holds " + TagName(g, e) + " at byte " +
        std::to_string(pos) + " where a fragment item (FFFE,E000) must be");
    }
    if (length == UndefinedLength || length > end - pos - 8)
    {
      return this->E.Fail("the pixel data fragment at byte " + std::to_string(pos) + " claims " +
        (length == UndefinedLength ? std::string("an undefined length")
                                   : std::to_string(length) + " bytes") +
        ", " + this->E.Limit(end));
    }
    pos += 8 + length;
  }
}
} // namespace dicom
} // namespace octoray
