/**
 * @class   vtkPCDReader
 * @brief   Reads PCL's PCD point cloud files (ascii, binary, binary_compressed) into vtkPolyData.
 *
 * PCD v0.7 headers, and the v0.5 / v0.6 headers PCL still accepts (COLUMNS
 * for FIELDS, no WIDTH / HEIGHT / VIEWPOINT / COUNT); the keywords in any
 * order, `#` comment lines anywhere in the header. Value types I, U
 * (sizes 1, 2, 4, 8) and F (4, 8), fields of COUNT > 1, padding fields
 * named `_`. All three bodies: `ascii`, `binary` (interleaved), and
 * `binary_compressed` (LZF, one array per field), decoded by the module
 * itself: no PCL, no third-party library.
 *
 * Output (each only where the file has it):
 * - points from x y z (float, or double with SetOutputPointsPrecision);
 *   one vertex cell per point (GenerateVertices);
 * - `Colors`: unsigned char RGB from a packed `rgb` field, RGBA from
 *   `rgba` (4 bytes, float or uint32, 0xAARRGGBB), the active scalars;
 * - `Normals`: from `normal_x normal_y normal_z`, the active normals;
 * - `Intensity`: from `intensity`, the active scalars when there are no
 *   colours;
 * - every other field (`curvature`, `label`, a descriptor such as `fpfh`
 *   with COUNT 33, ...) as an array of its own name with COUNT components;
 *   padding fields `_` are skipped. `Intensity` and these keep the type the
 *   file stores (F8 a double array, U4 an unsigned int one, ...);
 * - field data: `SkippedPointCount`, `PCDWidth`, `PCDHeight` and
 *   `PCDViewpoint` (tx ty tz qw qx qy qz).
 *
 * Points whose x, y or z is NaN or infinite (the empty cells of an
 * organised cloud) are left out and counted: one warning names the file and
 * the count, and the field data keep it (`SkippedPointCount`). Non-finite
 * values of other fields are kept as they are.
 *
 * Errors name the file, and the line for the header and the ascii body
 * (`scan.pcd:5: TYPE lists 3 value(s), FIELDS (line 3) lists 4 field(s)`,
 * `scan.pcd:14:7: expected a number for value 2 (y), found 'abc'`); a body
 * shorter than the header promises says how much was expected and found; a
 * damaged compressed block says where. A failed update leaves the output of
 * the last successful one in place (empty when there was none).
 *
 * The file is memory-mapped (gzip-compressed files are inflated); progress
 * events and SetAbortExecute are honoured while decoding.
 */
#ifndef vtkPCDReader_h
#define vtkPCDReader_h

#include "octorayIOParticlesModule.h" // for export macro
#include "vtkPointFileReader.h"

#include <string> // for std::string

class OCTORAYIOPARTICLES_EXPORT vtkPCDReader : public vtkPointFileReader
{
public:
  static vtkPCDReader* New();
  vtkTypeMacro(vtkPCDReader, vtkPointFileReader);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Points left out by the last update because a coordinate was NaN or
  /// infinite.
  vtkGetMacro(NumberOfSkippedPoints, vtkIdType);

  /// The fields of the file read last, as its FIELDS line lists them, and
  /// its DATA form ("ascii", "binary", "binary_compressed").
  const char* GetFieldNames() { return this->FieldNames.c_str(); }
  const char* GetDataEncoding() { return this->DataEncoding.c_str(); }

protected:
  vtkPCDReader();
  ~vtkPCDReader() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  bool ReadPoints(const char* data, size_t size, vtkPolyData* output) override;

  vtkIdType NumberOfSkippedPoints = 0;
  std::string FieldNames;
  std::string DataEncoding;

private:
  vtkPCDReader(const vtkPCDReader&) = delete;
  void operator=(const vtkPCDReader&) = delete;
};

#endif
