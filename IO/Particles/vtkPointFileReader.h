/**
 * @class   vtkPointFileReader
 * @brief   Superclass of the readers that turn one point file into vtkPolyData.
 *
 * What vtkParticleTextReader and vtkPCDReader share: the file (memory-mapped,
 * or inflated when gzip-compressed), the precision of the points, one vertex
 * cell per point, the message of the last error, re-reading a file that
 * changed on disk, and what a failed update leaves: the output of the last
 * successful one (empty when there was none), never a half-read file.
 *
 * A subclass reads the bytes in ReadPoints(): points, point data and field
 * data into the polydata it is given, or false after Fail(). The errors
 * that any file can give are reported here: no file name, a file that
 * cannot be opened, memory running out, a file truncated or written to
 * while it was read.
 */
#ifndef vtkPointFileReader_h
#define vtkPointFileReader_h

#include "octorayIOParticlesModule.h" // for export macro
#include "vtkAbstractPolyDataReader.h"
#include "vtkSmartPointer.h" // for vtkSmartPointer

#include <string> // for std::string

class vtkCellArray;

class OCTORAYIOPARTICLES_EXPORT vtkPointFileReader : public vtkAbstractPolyDataReader
{
public:
  vtkTypeMacro(vtkPointFileReader, vtkAbstractPolyDataReader);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// vtkAlgorithm::SINGLE_PRECISION (default) or DOUBLE_PRECISION for the
  /// points.
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

  /// The message of the last error; empty when the last update read
  /// everything.
  const char* GetErrorMessage() { return this->ErrorMessage.c_str(); }

  /// Includes the file's modification time, size and inode: when the file
  /// changes on disk, the next Update() reads it again.
  vtkMTimeType GetMTime() override;

protected:
  vtkPointFileReader();
  ~vtkPointFileReader() override;

  /// Opens the file, calls ReadPoints and keeps or restores the output.
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  /// Reads the file's bytes [data, data + size) into output (which is
  /// empty): points, point data, field data; the vertex cells are added
  /// here. False after Fail() when the file cannot be read.
  virtual bool ReadPoints(const char* data, size_t size, vtkPolyData* output) = 0;

  /// Keeps message as the error message and reports it as VTK errors are.
  void Fail(const std::string& message);
  /// "<file>: reading was aborted", for a read stopped through SetAbortExecute.
  void FailAborted();
  /// "<file>: the file changed while it was being read; ...".
  void FailChanged();

  /// Reports progress; false when a stop was asked for (SetAbortExecute).
  /// Progress events must come from the thread that called Update().
  bool ContinueReading(double progress);

  /// 0, 1, ..., n - 1 as n VTK_VERTEX cells.
  static vtkSmartPointer<vtkCellArray> MakeVertices(vtkIdType n);

  int OutputPointsPrecision = SINGLE_PRECISION;
  bool GenerateVertices = true;
  std::string ErrorMessage;

private:
  vtkPointFileReader(const vtkPointFileReader&) = delete;
  void operator=(const vtkPointFileReader&) = delete;

  vtkSmartPointer<vtkPolyData> ReadFile();

  // What the file looked like when GetMTime() last looked, and when that
  // changed; the output of the last successful update, which a failed
  // update leaves in place.
  std::string FileSignature;
  vtkTimeStamp FileChangeTime;
  vtkSmartPointer<vtkPolyData> LastOutput;
};

#endif
