// The walk over a DICOM data set for the structure check
// (octorayDicomCheck.h): every element in the data set's encoding, into
// sequences and their items (defined or undefined length, nesting bounded by
// DicomMaximumDepth) and the fragments of encapsulated pixel data. Values
// are skipped; a header or value that does not fit where it stands, a
// missing delimiter or a stray item stops the walk with a message. Private
// to the module; not wrapped.
#ifndef octorayDicomWalker_h
#define octorayDicomWalker_h

#include "octorayDicomElements.h"

namespace octoray
{
namespace dicom
{
class DataSetWalker
{
public:
  DataSetWalker(Elements& elements, Encoding encoding)
    : E(elements)
    , DataSetEncoding(encoding)
  {
  }

  // The elements from pos to end; false with the message in the Elements.
  bool Walk(uint64_t pos, uint64_t end);

  // Seen in the top-level data set, for what GDCM cannot take.
  bool HasNumberOfFrames = false;   // (0028,0008)
  uint64_t GridFrameOffsetAt = 0;   // (3004,000C), where; 0 when absent

private:
  bool DataSet(uint64_t& pos, uint64_t end, uint64_t itemStart, int depth, Encoding enc);
  bool UndefinedLengthValue(const Header& h, uint64_t& pos, uint64_t end, int depth, Encoding enc);
  bool DefinedLengthValue(const Header& h, int depth, Encoding enc);
  bool Sequence(const Header& seq, uint64_t& pos, uint64_t end, int depth, Encoding enc);
  bool Fragments(const Header& px, uint64_t& pos, uint64_t end);

  Elements& E;
  Encoding DataSetEncoding;
};
} // namespace dicom
} // namespace octoray

#endif
