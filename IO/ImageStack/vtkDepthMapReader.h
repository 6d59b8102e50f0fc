/**
 * @class   vtkDepthMapReader
 * @brief   Reads a depth image with pinhole intrinsics as a point cloud.
 *
 * The depth image (16-bit PNG such as the TUM/Kinect convention, or an EXR or
 * TIFF of float depths; read through OpenImageIO, first channel, or the
 * channel named Z/depth when there is one) is back-projected with the pinhole
 * model of a camera looking down +z, y down (OpenCV's convention):
 *
 *     z = depth * DepthScale,  x = (u - cx) * z / fx,  y = (v - cy) * z / fy
 *
 * where (u, v) is the pixel (column, row from the top). Pixels whose depth is
 * 0, not finite, or outside [MinimumDepth, MaximumDepth] (after scaling) give
 * no point; their number is GetNumberOfInvalidPixels(). An optional colour
 * image of the same size gives `Colors`; `Depth` holds z.
 */
#ifndef vtkDepthMapReader_h
#define vtkDepthMapReader_h

#include "octorayIOImageStackModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"

#include <string> // for std::string

class OCTORAYIOIMAGESTACK_EXPORT vtkDepthMapReader : public vtkPolyDataAlgorithm
{
public:
  static vtkDepthMapReader* New();
  vtkTypeMacro(vtkDepthMapReader, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The depth image, and an optional colour image of the same size.
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  vtkSetStringMacro(ColorFileName);
  vtkGetStringMacro(ColorFileName);
  ///@}

  ///@{
  /// Pinhole intrinsics in pixels: focal lengths fx, fy and principal point cx, cy.
  vtkSetMacro(FocalLengthX, double);
  vtkGetMacro(FocalLengthX, double);
  vtkSetMacro(FocalLengthY, double);
  vtkGetMacro(FocalLengthY, double);
  vtkSetMacro(PrincipalPointX, double);
  vtkGetMacro(PrincipalPointX, double);
  vtkSetMacro(PrincipalPointY, double);
  vtkGetMacro(PrincipalPointY, double);
  /// All four at once: fx, fy, cx, cy.
  void SetIntrinsics(double fx, double fy, double cx, double cy);
  ///@}

  ///@{
  /// Stored depth value times DepthScale is the depth in output units
  /// (e.g. 0.001 for millimetres to metres). Default 1.
  vtkSetMacro(DepthScale, double);
  vtkGetMacro(DepthScale, double);
  ///@}

  ///@{
  /// Valid depth range after scaling (defaults: (0, +inf)).
  vtkSetMacro(MinimumDepth, double);
  vtkGetMacro(MinimumDepth, double);
  vtkSetMacro(MaximumDepth, double);
  vtkGetMacro(MaximumDepth, double);
  ///@}

  ///@{
  /// Use every n-th pixel in u and v (default 1).
  vtkSetClampMacro(Stride, int, 1, VTK_INT_MAX);
  vtkGetMacro(Stride, int);
  ///@}

  ///@{
  /// One VTK_VERTEX per point (default on).
  vtkSetMacro(GenerateVertices, bool);
  vtkGetMacro(GenerateVertices, bool);
  vtkBooleanMacro(GenerateVertices, bool);
  ///@}

  /// Pixels of the last update that gave no point (no depth or out of range).
  vtkGetMacro(NumberOfInvalidPixels, vtkIdType);

  const char* GetErrorMessage() { return this->ErrorMessage.c_str(); }

protected:
  vtkDepthMapReader();
  ~vtkDepthMapReader() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* FileName = nullptr;
  char* ColorFileName = nullptr;
  double FocalLengthX = 0;
  double FocalLengthY = 0;
  double PrincipalPointX = 0;
  double PrincipalPointY = 0;
  double DepthScale = 1;
  double MinimumDepth = 0;
  double MaximumDepth = VTK_DOUBLE_MAX;
  int Stride = 1;
  bool GenerateVertices = true;
  vtkIdType NumberOfInvalidPixels = 0;
  std::string ErrorMessage;

private:
  vtkDepthMapReader(const vtkDepthMapReader&) = delete;
  void operator=(const vtkDepthMapReader&) = delete;
  void Fail(const std::string& message);
  void MakePoints(const float* depth, int width, int height, const unsigned char* rgb,
    vtkPolyData* output);
};

#endif
