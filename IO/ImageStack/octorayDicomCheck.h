// A structural check of a DICOM file before GDCM parses it. Private to the
// module; not wrapped.
//
// Debian's GDCM 3.0 is built with assertions, and some damaged files make it
// abort the process (a damaged file meta element, a meta group cut short)
// or allocate an element's value at the length the file claims before
// comparing it with the file (2.6 GB for a 2.6 kB file). The reader must
// fail with a message instead, so every DICOM file is walked here first:
// the 128-byte preamble and "DICM" (or a bare data set without them), the
// file meta group (0002) in explicit VR little endian, then every element of
// the data set in the encoding the transfer syntax names, into sequences
// and items (defined or undefined length, nesting bounded) and the fragments
// of encapsulated pixel data. Only tags, VRs and lengths are read; values
// are skipped (the transfer syntax UID excepted), so a large file costs a
// few reads per element, not a second read of its pixels.
//
// Rejected: a header or value that runs past the end of the file or of the
// item or sequence around it, bytes that are not a VR where explicit VR is
// expected, an undefined length where the standard allows none, a sequence
// or item without its delimiter, stray items or delimiters, nesting deeper
// than DicomMaximumDepth, and an image element that GDCM reads as an
// attribute (rows, columns, bits, spacing, position...) stated with another
// VR than the standard's, on which GDCM asserts too. Not checked: the values
// themselves (GDCM reads them; what it cannot decode it reports), a deflated
// data set (only its file meta group is walked).
#ifndef octorayDicomCheck_h
#define octorayDicomCheck_h

#include <cstddef>
#include <string>

namespace octoray
{
// Sequences and items nested deeper than this are rejected: a chain of
// nested undefined-length items would otherwise recurse as deep as the file
// is long (here and in GDCM).
constexpr int DicomMaximumDepth = 32;

// Empty when the file's structure is sound; otherwise what is wrong and
// where, e.g. "DICOM element (0028,0010) at byte 1234 claims 2600000000
// bytes, the file has 2600" (without the file's name: the caller adds it).
std::string CheckDicomStructure(const std::string& fileName);

// The same for bytes in memory (the unit tests).
std::string CheckDicomStructure(const unsigned char* data, size_t size);
} // namespace octoray

#endif
