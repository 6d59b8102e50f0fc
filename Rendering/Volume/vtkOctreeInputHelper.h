/**
 * @class   vtkOctreeInputHelper
 * @brief   a vtkOctreeVolumeMapper's input as the octree engine's arrays,
 *          and what changed since the octree was built
 *
 * A private helper of vtkOctreeVolumeMapper (not wrapped, not installed),
 * in the role vtkVolumeInputHelper plays for VTK's GPU ray caster. It finds
 * which arrays play which part (colours or scalars, reflectivity,
 * refraction, normals), turns them into an octoray::PointCloudView (the
 * caller's arrays where their layout allows, converted host copies
 * otherwise; image voxels above the background become points, with the
 * planes between slices filled as octorayLattice.h says), knows the lattice
 * the points lie on where there is one (an image; a point set whose field
 * data names it and whose points lie on it), and compares the input with
 * what the current octree was built from: nothing changed, only the point
 * positions moved (an in-place update), or anything else (a build).
 */
#ifndef vtkOctreeInputHelper_h
#define vtkOctreeInputHelper_h

#include "vtkType.h" // for vtkIdType, vtkMTimeType

#include <octoray/PointCloud.h> // for the views
#include <octorayLattice.h>      // for octoray::lattice::Lattice

#include <array>      // for std::array
#include <cstdint>    // for std::uint8_t
#include <functional> // for std::function
#include <string>     // for std::string
#include <vector>     // for std::vector

class vtkDataArray;
class vtkDataSet;
class vtkOctreeVolumeMapper;
class vtkVolumeProperty;

class vtkOctreeInputHelper
{
public:
  /**
   * The point arrays read for reflectivity and refraction unless the mapper
   * names others: as vtkParticleTextReader names them. Most inputs have
   * neither, so these two missing are nothing to say.
   */
  static constexpr const char* DefaultReflectivityArrayName = "Reflectivity";
  static constexpr const char* DefaultRefractionArrayName = "Refraction";

  enum class Change
  {
    None,      // the octree is up to date
    Positions, // only the points' positions moved: Engine::Update
    All        // anything else: Engine::Build
  };

  /**
   * What the octree is made of this frame: the input, the arrays in their
   * roles and the mapper settings that shape the octree.
   */
  struct Request
  {
    vtkDataSet* Input = nullptr;
    vtkDataArray* Scalars = nullptr; // active scalars: point data, or an image's cell data
    bool CellCentred = false;        // an image's cell data: each cell a voxel at its centre
    bool Colours = false;            // Scalars are RGB(A) colours, not through the transfer function
    // Which value of multi-component Scalars the transfer functions read:
    // a component, or kMagnitude (ScalarComponentOf).
    int ScalarComponent = 0;
    vtkDataArray* Reflectivity = nullptr;
    vtkDataArray* Refraction = nullptr;
    vtkDataArray* Normals = nullptr;
    bool CellScalars = false; // the selected scalars are a point set's cell data, which the octree cannot use
    double ImageBackground = 0.0;
    bool FillBetweenSlices = true; // image input: fill between slices (octorayLattice.h)
    bool ImageGradientNormals = true; // image input: normals from the scalar gradient
    vtkDataArray* Lattice = nullptr; // point set input: the field-data array naming its lattice
    int LeafDepth = 0;
    std::array<double, 6> RootBounds{};
    unsigned long EngineGeneration = 0; // a new engine holds no octree
    // Why the input cannot be drawn as it is (a selected point array with
    // fewer tuples than points, which the engine would read past); "" where
    // it can.
    std::string Problem;
    // What the frame goes on without or draws otherwise than VTK's mappers
    // would, each said once for an input (an array the mapper names that
    // the input lacks, scalar components the octree does not draw).
    std::vector<std::string> Notices;
  };

  /**
   * Request::ScalarComponent for the length of each tuple.
   */
  static constexpr int kMagnitude = -1;

  /**
   * The request for `input` as `mapper` and `property` select its arrays.
   */
  static Request MakeRequest(vtkDataSet* input, vtkOctreeVolumeMapper* mapper, vtkVolumeProperty* property,
    unsigned long engineGeneration);

  /**
   * What changed since Remember() was last called.
   */
  Change Compare(const Request& request) const;

  /**
   * The engine's view of the points (valid until the next call). Empty
   * (count 0) when an image has no voxel above the background.
   */
  octoray::PointCloudView PointCloud(const Request& request, const std::function<void(double)>& progress);

  /**
   * The moved positions for Engine::Update (Change::Positions).
   */
  octoray::PositionsView Positions(const Request& request);

  /**
   * The octree now reflects `request` (after a successful build or update).
   */
  void Remember(const Request& request);

  /**
   * The octree is gone (a failed build, a new engine).
   */
  void Forget() { this->Built = false; }

  /**
   * A build of `request` failed (its error said): FailedBefore() is true
   * for the same input and settings, so that frames do not build it again
   * and repeat the error, until something changes.
   */
  void RememberFailure(const Request& request);
  bool FailedBefore(const Request& request) const;

  /**
   * The lattice the points of the last PointCloud() lie on, and their
   * bounds: false when they lie on none (scattered points, a point set
   * without the field-data array, or one whose points left the lattice).
   */
  bool PointLattice(octoray::lattice::Lattice& lattice, double bounds[6]) const;

  bool HasOctree() const { return this->Built; }
  bool HasScalar() const { return this->ScalarPresent; }
  const double* ScalarRange() const { return this->Range; }

  /**
   * The signature of an array as the octree used it: a change of contents
   * (MTime) or of the array itself means a rebuild.
   */
  struct ArrayStamp
  {
    const void* Array = nullptr;
    vtkMTimeType MTime = 0;
    bool operator==(const ArrayStamp& o) const { return this->Array == o.Array && this->MTime == o.MTime; }
  };

private:
  struct Signature
  {
    const void* Input = nullptr;
    vtkIdType Count = 0;
    std::string Layout; // which arrays play which role
    std::array<ArrayStamp, 5> Arrays{}; // scalars, reflectivity, refraction, normals, lattice
    ArrayStamp Points;
    int LeafDepth = 0;
    std::array<double, 6> RootBounds{};
    unsigned long EngineGeneration = 0;
    bool SameExceptPoints(const Signature& o) const;
    bool operator==(const Signature& o) const { return this->SameExceptPoints(o) && this->Points == o.Points; }
  };
  static Signature Sign(const Request& request);

  void PointSetView(const Request& request, octoray::PointCloudView& view);
  void ImageView(const Request& request, octoray::PointCloudView& view, const std::function<void(double)>& progress);
  void RememberImageLattice(const octoray::lattice::Lattice& lattice);
  void FindScalarRange(const octoray::PointCloudView& view);

  bool Built = false;
  Signature Current;
  bool Failed = false;
  Signature FailedBuild;
  bool HasLattice = false;
  octoray::lattice::Lattice Lattice;
  double LatticeBounds[6] = { 0, 0, 0, 0, 0, 0 };
  bool ScalarPresent = false;
  double Range[2] = { 0.0, 1.0 };

  // Host copies the engine reads during a build (converted types, image voxels).
  std::vector<double> Xyz;
  std::vector<float> Scalar, Reflectivity, Refraction, Normal, ColorFloat;
  std::vector<std::uint8_t> Color8;
};

#endif
// VTK-HeaderTest-Exclude: vtkOctreeInputHelper.h
