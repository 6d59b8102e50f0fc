/**
 * @class   vtkParticleTextReader
 * @brief   Reads particle text files (the thesis format and its subsets) into vtkPolyData.
 *
 * One particle a line. Without a header the column count decides the layout:
 *
 * | columns | meaning |
 * | --- | --- |
 * | 3 | x y z |
 * | 4 | x y z scalar |
 * | 6 | x y z r g b (colour 0-255) |
 * | 8 | x y z r g b reflectivity refraction (the thesis format) |
 *
 * An optional header line names the columns in any order, e.g.
 * `# x y z r g b reflectivity refraction` or `x,y,z,intensity`; the names
 * x, y, z are required, r/g/b (or red/green/blue) become `Colors`,
 * `reflectivity`, `refraction` and `scalar(s)` the arrays of those names and
 * any other named column a point array of its own name.
 *
 * Fields are separated by spaces, tabs or one comma; `#` starts a comment;
 * blank lines and CRLF line ends are accepted; a gzip file (by its magic
 * bytes) is read as the text it holds.
 *
 * Output: points (float, or double with SetOutputPointsPrecision), one
 * vertex cell per point (GenerateVertices), and the arrays `Colors`
 * (unsigned char RGB), `Reflectivity`, `Refraction`, `Scalars` and the named
 * extras, each only where the file has it.
 *
 * Errors name the file, line and column and what was expected:
 * `particles.txt:12:9: expected a number for column 3 (z), found 'abc'`.
 * Strict (the default): the first bad line (lowest line number) is an error
 * and the output is empty. Lenient: bad lines are skipped and counted; a
 * warning gives the count and the first line numbers, and so does the field
 * data (`SkippedLineCount`, `SkippedLineNumbers`). Nothing is dropped silently.
 *
 * Large files are memory-mapped and parsed by several threads; progress
 * events come from the calling thread.
 *
 * The C++ name differs from VTK's own vtkParticleReader (IOGeometry, a
 * different format) so both can live in one process; the Python package
 * `octoray` offers it as `octoray.vtkParticleReader` too.
 */
#ifndef vtkParticleTextReader_h
#define vtkParticleTextReader_h

#include "octorayIOParticlesModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"
#include "vtkSmartPointer.h" // for vtkSmartPointer

#include <string> // for std::string

class OCTORAYIOPARTICLES_EXPORT vtkParticleTextReader : public vtkPolyDataAlgorithm
{
public:
  static vtkParticleTextReader* New();
  vtkTypeMacro(vtkParticleTextReader, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The file to read (plain text or gzip-compressed text).
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /// vtkAlgorithm::SINGLE_PRECISION (default) or DOUBLE_PRECISION for the
  /// points and the floating-point arrays.
  vtkSetClampMacro(OutputPointsPrecision, int, SINGLE_PRECISION, DOUBLE_PRECISION);
  vtkGetMacro(OutputPointsPrecision, int);
  ///@}

  ///@{
  /// Make one VTK_VERTEX cell per point (default on), so that ordinary VTK
  /// mappers draw the points.
  vtkSetMacro(GenerateVertices, bool);
  vtkGetMacro(GenerateVertices, bool);
  vtkBooleanMacro(GenerateVertices, bool);
  ///@}

  ///@{
  /// Skip bad lines instead of failing (default off: strict).
  vtkSetMacro(Lenient, bool);
  vtkGetMacro(Lenient, bool);
  vtkBooleanMacro(Lenient, bool);
  ///@}

  ///@{
  /// Threads used for parsing; 0 (default) means all hardware threads.
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /// How many line numbers of skipped lines are reported (default 10).
  vtkSetClampMacro(MaximumReportedLines, int, 0, 100000);
  vtkGetMacro(MaximumReportedLines, int);
  ///@}

  /// Lines skipped in lenient mode by the last update.
  vtkGetMacro(NumberOfSkippedLines, vtkIdType);

  /// The message of the last error (strict mode) or of the first skipped line
  /// (lenient mode); empty when the last update read everything.
  const char* GetErrorMessage() { return this->ErrorMessage.c_str(); }

  /// Numeric column layout found by the last update, e.g. "x y z r g b".
  const char* GetColumnNames() { return this->ColumnNames.c_str(); }

  /// Includes the file's modification time, size and inode: when the file
  /// changes on disk, the next Update() reads it again.
  vtkMTimeType GetMTime() override;

  /// Whether this reader reads the file, for a reader factory choosing among
  /// the readers of one extension (ParaView's File › Open calls it on each
  /// reader that claims the file's extension). 1 for a file named
  /// `.particles` or `.particles.gz` that can be opened (the extension is
  /// this reader's own, and reading it reports what is wrong, with line and
  /// column). For any other name (`.txt`, `.csv`, `.xyz`, ...; gzip or not)
  /// the content decides, by the format code the reader parses with: the
  /// first 64 KiB must hold a prologue the reader accepts (comments, a
  /// header line naming x, y and z, or 3, 4, 6 or 8 columns) and first data
  /// lines of as many numbers as the layout has columns (up to 16 lines);
  /// anything else (text columns, other column counts, binary data, an
  /// empty or unreadable file) is 0.
  static int CanReadFile(VTK_FILEPATH const char* filename);

protected:
  vtkParticleTextReader();
  ~vtkParticleTextReader() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* FileName = nullptr;
  int OutputPointsPrecision = SINGLE_PRECISION;
  bool GenerateVertices = true;
  bool Lenient = false;
  int NumberOfThreads = 0;
  int MaximumReportedLines = 10;
  vtkIdType NumberOfSkippedLines = 0;
  std::string ErrorMessage;
  std::string ColumnNames;
  // What the file looked like when GetMTime() last looked, and when that
  // changed; the output of the last successful update, which a failed
  // update leaves in place.
  std::string FileSignature;
  vtkTimeStamp FileChangeTime;
  vtkSmartPointer<vtkPolyData> LastOutput;

private:
  vtkParticleTextReader(const vtkParticleTextReader&) = delete;
  void operator=(const vtkParticleTextReader&) = delete;

  template <typename Real>
  bool Parse(const char* data, size_t size, vtkPolyData* output);
  void Fail(const std::string& message);
};

#endif
