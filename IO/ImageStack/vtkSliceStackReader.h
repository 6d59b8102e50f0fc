/**
 * @class   vtkSliceStackReader
 * @brief   Reads a stack of image slices (incl. a DICOM series) as particles and as a volume.
 *
 * The slices come from a list of files (AddFileName), a directory
 * (SetDirectoryName: every image or DICOM file in it, sorted naturally so
 * that 2 comes before 10), or a printf-style pattern with a range of numbers
 * (SetFilePattern + SetFileNameRange, as vtkImageReader2::SetFilePattern).
 * A multi-page TIFF gives one slice per page.
 *
 * Pictures (PNG, TIFF, JPEG, BMP, EXR, ... with 8- or 16-bit grey, grey +
 * alpha, RGB or RGBA) are read through OpenImageIO; their rows are flipped
 * so that j grows upwards, as VTK's own image readers do. DICOM files
 * (recognised by the "DICM" marker or the .dcm extension) are read through
 * GDCM, because OpenImageIO's DICOM plugin does not report the image position
 * and orientation: slices are ordered by their position along the slice
 * normal (not by file name), the slice spacing is the distance between
 * neighbouring positions, the pixel spacing, the first slice's position and
 * the orientation become the spacing, origin and direction of the output,
 * and the rescale slope/intercept are applied (output values are then float).
 *
 * Output 0 (vtkPolyData): one particle per pixel that is not background,
 * at origin + direction * (i*sx, j*sy, k*sz), with a vertex cell each,
 * `Scalars` (the pixel intensity: the grey value, or the mean of R, G, B),
 * for colour images `Colors` (unsigned char RGB), and for grey ones with
 * GradientNormals on `Normals`, the intensities' gradient. A pixel is
 * background when its intensity lies in BackgroundRange (default [0, 0]) or
 * its alpha is 0.
 * A region of interest (in pixel indices of the stack) and a stride pick the
 * pixels that are looked at.
 *
 * Closed volume (FillBetweenSlices, on by default). The slices of a stack
 * are usually farther apart than its pixels (1.5 mm against 0.96 mm in a
 * typical head CT, 3-5 times in many clinical CTs); particles on the slices
 * alone, drawn as octree voxels of the pixel size, are plates with
 * see-through gaps between them. So the reader fills the space between
 * neighbouring (selected) slices with planes of particles whose values are
 * interpolated linearly from the two slices, as many as make the particles
 * no farther apart along the slice axis than across it (more precisely:
 * the coarsest axis is filled down to the second-coarsest spacing; see
 * octorayLattice.h, the rule the octree mapper follows for a vtkImageData
 * too). The background test applies to the interpolated values, so an
 * object's surface between two slices lies where its interpolated intensity
 * crosses BackgroundRange. The particles of the slices themselves are the
 * same as without filling (same positions and values); the others lie
 * between them, in plane order. Filling multiplies the number of particles
 * by about the ratio of slice to pixel spacing (2 for the head CT), at most
 * by 32. Off, the particles are those of the slices only (the reader's
 * output before filling existed).
 *
 * Either way, output 0 names the lattice its particles lie on in a
 * field-data array "PointLattice" (15 doubles: origin, the three step
 * vectors, the sample counts; octorayLattice.h). vtkOctreeVolumeMapper,
 * with LeafDepth 0 (automatic), then makes its leaves exactly as large as
 * the largest step and aligns them with the lattice, so that no leaf inside
 * an object is empty: with filling the leaves are the pixel size; without,
 * the slice spacing (closed too, but coarser). A filter that moves the
 * points keeps the array, but the mapper checks the points against it and
 * ignores it when they are off the lattice.
 *
 * Output 1 (vtkImageData): the whole stack with the slices' own pixel type
 * (or float for rescaled DICOM), so VTK's volume mappers can draw the same data.
 * Its whole extent is announced in RequestInformation (from the headers).
 *
 * Each output is made where it is asked for. An update of output 1 alone
 * (a volume mapper on GetOutputPort(1), Update(1)) makes no particles:
 * output 0 keeps what it held, and an update of it later makes them from
 * the volume already read. The volume is read again only when what it
 * depends on changes (the files, on disk too, Spacing, Origin,
 * UseMetadata): a change of a particle option (BackgroundRange, Stride,
 * ...) makes the particles again from it.
 *
 * Errors name the slice: a missing or unreadable file, slices of different
 * size or type (both named, with both sizes), an empty directory, a pattern
 * that matches no file. Progress is reported per slice.
 */
#ifndef vtkSliceStackReader_h
#define vtkSliceStackReader_h

#include "octorayIOImageStackModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"
#include "vtkSmartPointer.h" // for vtkSmartPointer

#include <string> // for std::string
#include <vector> // for std::vector

class vtkImageData;
class vtkStringArray;

class OCTORAYIOIMAGESTACK_EXPORT vtkSliceStackReader : public vtkPolyDataAlgorithm
{
public:
  static vtkSliceStackReader* New();
  vtkTypeMacro(vtkSliceStackReader, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// An explicit list of slice files, in the order given.
  void AddFileName(const char* name);
  void ClearFileNames();
  int GetNumberOfFileNames() const { return static_cast<int>(this->FileNames.size()); }
  const char* GetFileName(int i) const;
  void SetFileNames(vtkStringArray* names);
  ///@}

  ///@{
  /// A directory whose image (or DICOM) files form the stack, in natural order.
  vtkSetStringMacro(DirectoryName);
  vtkGetStringMacro(DirectoryName);
  ///@}

  ///@{
  /// A printf-style pattern (e.g. "/data/slice_%03d.png") and the inclusive
  /// range of numbers it is filled with.
  vtkSetStringMacro(FilePattern);
  vtkGetStringMacro(FilePattern);
  vtkSetVector2Macro(FileNameRange, int);
  vtkGetVector2Macro(FileNameRange, int);
  ///@}

  ///@{
  /// Pixel spacing (x, y) and slice spacing (z); DICOM tags override them
  /// when UseMetadata is on (default). A spacing that is not finite and
  /// above zero, or an origin that is not finite, fails the update, naming
  /// the property.
  vtkSetVector3Macro(Spacing, double);
  vtkGetVector3Macro(Spacing, double);
  vtkSetVector3Macro(Origin, double);
  vtkGetVector3Macro(Origin, double);
  vtkSetMacro(UseMetadata, bool);
  vtkGetMacro(UseMetadata, bool);
  vtkBooleanMacro(UseMetadata, bool);
  ///@}

  ///@{
  /// Intensities in [min, max] (inclusive) are background (default [0, 0]).
  vtkSetVector2Macro(BackgroundRange, double);
  vtkGetVector2Macro(BackgroundRange, double);
  ///@}

  ///@{
  /// Region of interest as pixel indices (imin, imax, jmin, jmax, kmin, kmax)
  /// of the stack (after ordering; j counted upwards for pictures); -1 for a
  /// bound means "to the edge". Only the particles use it. A bound past the
  /// stack, a minimum above its maximum or a stride below 1 fails the
  /// update, naming the property and the axis.
  vtkSetVector6Macro(RegionOfInterest, int);
  vtkGetVector6Macro(RegionOfInterest, int);
  vtkSetVector3Macro(Stride, int);
  vtkGetVector3Macro(Stride, int);
  ///@}

  ///@{
  /// Fill the space between slices with particles interpolated from the two
  /// neighbouring slices, so that the particles draw as a closed volume
  /// (default on; see the class description).
  vtkSetMacro(FillBetweenSlices, bool);
  vtkGetMacro(FillBetweenSlices, bool);
  vtkBooleanMacro(FillBetweenSlices, bool);
  ///@}

  ///@{
  /// Make output 0's particles (default on). Off, output 0 has no points
  /// even where it is asked for, and the particle options are not looked
  /// at: for a view that updates every output but draws the volume alone
  /// (ParaView's Apply updates both): the particles' time and memory are
  /// saved (the head CT's 14 M particles above the default background are
  /// most of its read). A pipeline that asks for output 1 alone needs no
  /// switch (see the class description).
  vtkSetMacro(GenerateParticles, bool);
  vtkGetMacro(GenerateParticles, bool);
  vtkBooleanMacro(GenerateParticles, bool);
  ///@}

  ///@{
  /// Particles of a grey stack carry `Normals` (default off): the negated
  /// gradient of the intensities by central differences, interpolated
  /// between slices like the values (octorayLattice.h's GradientNormal), the
  /// normals vtkOctreeVolumeMapper gives image input (ImageGradientNormals)
  /// and VTK's volume mappers shade by. Shaded, the particles then draw as
  /// the tissue's surface, not as the voxels' faces. Colour stacks have none.
  /// Off by default: the normals cost a gradient and 12 bytes a particle
  /// (the head CT's particles took 2.0 s with them against 0.8 s), which
  /// unshaded drawing does not use.
  vtkSetMacro(GradientNormals, bool);
  vtkGetMacro(GradientNormals, bool);
  vtkBooleanMacro(GradientNormals, bool);
  ///@}

  ///@{
  /// One VTK_VERTEX per particle (default on).
  vtkSetMacro(GenerateVertices, bool);
  vtkGetMacro(GenerateVertices, bool);
  vtkBooleanMacro(GenerateVertices, bool);
  ///@}

  /// The stack as a volume (output port 1).
  vtkImageData* GetImageOutput();

  /// The message of the last error; empty after a successful update.
  const char* GetErrorMessage() { return this->ErrorMessage.c_str(); }

  /// The slice files in the order they were stacked by the last update
  /// (for DICOM: by position along the slice normal).
  int GetNumberOfSlices() const { return static_cast<int>(this->SliceFiles.size()); }
  const char* GetSliceFileName(int k) const;

  /// Includes the modification times and sizes of the slice files (and of
  /// the directory): when a slice changes on disk, the next Update() reads
  /// the stack again.
  vtkMTimeType GetMTime() override;

  /// True when the last update read a DICOM series.
  vtkGetMacro(IsDICOM, bool);

protected:
  vtkSliceStackReader();
  ~vtkSliceStackReader() override;

  int FillOutputPortInformation(int port, vtkInformation* info) override;
  vtkTypeBool ProcessRequest(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  std::vector<std::string> FileNames;
  char* DirectoryName = nullptr;
  char* FilePattern = nullptr;
  int FileNameRange[2] = { 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
  double Origin[3] = { 0, 0, 0 };
  bool UseMetadata = true;
  double BackgroundRange[2] = { 0, 0 };
  int RegionOfInterest[6] = { -1, -1, -1, -1, -1, -1 };
  int Stride[3] = { 1, 1, 1 };
  bool GenerateVertices = true;
  bool FillBetweenSlices = true;
  bool GradientNormals = false;
  bool GenerateParticles = true;
  bool IsDICOM = false;
  std::string ErrorMessage;
  // The last error said and the reader's MTime then: ParaView asks for the
  // information and the data of one update, and each failed alike.
  std::string SaidError;
  vtkMTimeType SaidErrorMTime = 0;
  std::vector<std::string> SliceFiles;
  // The files' signature when GetMTime() last looked and when it changed;
  // the outputs of the last successful update, which a failed update leaves
  // in place (never a half-read stack), and what the volume was read from
  // (ImageSignature), so that an update whose volume it still is does not
  // read it again.
  std::string FileSignature;
  vtkTimeStamp FileChangeTime;
  vtkSmartPointer<vtkPolyData> LastOutput;
  vtkSmartPointer<vtkImageData> LastImage;
  std::string LastImageSignature;
  std::vector<std::string> LastSliceFiles;
  bool LastIsDICOM = false;

private:
  vtkSliceStackReader(const vtkSliceStackReader&) = delete;
  void operator=(const vtkSliceStackReader&) = delete;

  bool ListSlices(std::vector<std::string>& files);
  bool ReadStack(const std::vector<std::string>& files, vtkImageData* image);
  std::string ImageSignature(const std::vector<std::string>& files) const;
  vtkSmartPointer<vtkImageData> CurrentImage(
    const std::vector<std::string>& files, const std::string& signature);
  bool MakeParticles(vtkImageData* image, vtkPolyData* particles);
  int KeepLastOutputs(vtkPolyData* output, vtkImageData* image);
  void Fail(const std::string& message);
};

#endif
