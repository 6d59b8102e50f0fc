/**
 * @class   vtkOctreeVolumeRepresentation
 * @brief   ParaView's "Octree Volume" representation: point data or image
 *          data drawn by vtkOctreeVolumeMapper in the render view
 *
 * vtkOctreeVolumeRepresentation follows ParaView's own volume
 * representations (vtkImageVolumeRepresentation,
 * vtkUnstructuredGridVolumeRepresentation): RequestData keeps a shallow copy
 * of the input, REQUEST_UPDATE hands it to the render view as this
 * representation's piece, and REQUEST_RENDER connects the view's copy of the
 * piece to the mapper and pushes the colour array, the transfer functions
 * and the mapper's settings. The volume (a vtkPVLODVolume, from
 * vtkVolumeRepresentation) is added to the view's renderer.
 *
 * Data stays where it was produced: the piece is never gathered on the
 * client (SetRequiresDistributedRendering), so with N ranks every rank
 * builds and traces the octree of its own points and the view's compositor
 * (IceT) merges the pictures.
 *
 * - Every rank keeps the mapper on its volume, also a rank whose piece is
 *   empty (a reader that reads on rank 0 only, fewer pieces than ranks): it
 *   gives the mapper an empty vtkPolyData and draws nothing. (A vtkPVLODVolume
 *   without a mapper fails in vtkLODProp3D::SetAllocatedRenderTime: "You must
 *   give me a mapper!", then SIGSEGV.)
 * - The volume is a vtkPVLODVolume that lets the octree mapper draw without
 *   a scalar array ("Solid Color": the points' own colours or white), and
 *   whose bounds hold the voxels (vtkOctreeVolumeMapper::GetVoxelBounds), not
 *   only the points: IceT crops each rank's picture to its props' bounds.
 * - Surface blend mode (first hit, shaded or not: the "Phong" picture) is
 *   opaque: the mapper writes window depth, and IceT's depth compositing
 *   gives the same picture as one rank.
 * - The translucent blend modes (composite, maximum, minimum, average,
 *   additive) need the pieces blended back to front. The representation
 *   then asks the view for ordered compositing: the view redistributes the
 *   points into spatially disjoint pieces (a k-d tree over the ranks) and
 *   IceT blends them in visibility order. The piece it redistributes is an
 *   unstructured grid of one vertex per point (PointCloudPiece in the
 *   .cxx says why). Every rank's octree uses the cube of the global bounds,
 *   but a voxel that a cut crosses is drawn by two ranks, so pixels along
 *   the cuts can differ from the one-rank picture; a warning says so once.
 * - Composite data (multiblock, partitioned) whose blocks are point sets is
 *   drawn as one point set, as Merge Blocks would make it (MergedPointSets);
 *   a warning names the point arrays that some blocks lack, dropped so.
 * - Input the mapper cannot draw (anything but vtkPointSet, vtkImageData and
 *   composite data of point sets: tables, rectilinear grids, composite data
 *   holding an image, ...) is accepted by the pipeline and draws nothing; a
 *   warning names its type, what can be drawn and the filter that converts
 *   it, once per input type.
 *
 * The mapper is created with vtkOctreeVolumeMapper::New(): CUDA when the
 * server has a usable device, else the CPU backend; the first render logs
 * which backend drew (and the mapper itself warns when CUDA fails and it
 * falls back).
 *
 * @sa vtkOctreeVolumeMapper vtkVolumeRepresentation
 */
#ifndef vtkOctreeVolumeRepresentation_h
#define vtkOctreeVolumeRepresentation_h

#include "octorayViewsParaViewModule.h" // for export macro
#include "vtkVolumeRepresentation.h"

#include "vtkNew.h"                 // for vtkNew
#include "vtkOctreeVolumePresets.h" // for vtkNew<vtkOctreeVolumePresets>
#include "vtkVolumeProperty.h"      // for vtkNew<vtkVolumeProperty>
#include "vtkWeakPointer.h"         // for vtkWeakPointer

#include <string> // for std::string

class vtkCompositeDataSet;
class vtkDataSet;
class vtkOctreeVolumeMapper;
class vtkPointSet;
class vtkOctreeVolumePresets;
class vtkStringArray;
class vtkTrivialProducer;

class OCTORAYVIEWSPARAVIEW_EXPORT vtkOctreeVolumeRepresentation : public vtkVolumeRepresentation
{
public:
  static vtkOctreeVolumeRepresentation* New();
  vtkTypeMacro(vtkOctreeVolumeRepresentation, vtkVolumeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  int ProcessViewRequest(vtkInformationRequestKey* request_type, vtkInformation* inInfo,
    vtkInformation* outInfo) override;

  ///@{
  /**
   * Forwarded to vtkVolumeProperty (as vtkImageVolumeRepresentation does).
   */
  void SetAmbient(double);
  void SetDiffuse(double);
  void SetSpecular(double);
  void SetSpecularPower(double);
  void SetShade(bool);
  ///@}

  ///@{
  /**
   * Forwarded to vtkOctreeVolumeMapper; see its documentation. BlendMode
   * takes vtkVolumeMapper's values or vtkOctreeVolumeMapper::SURFACE_BLEND.
   */
  void SetBlendMode(int);
  void SetRequestedBackend(int);
  void SetLeafDepth(int);
  void SetLODPixelThreshold(double);
  void SetShadows(bool);
  void SetEstimateNormals(bool);
  void SetMaximumBounces(int);
  void SetDepthCue(double);
  void SetImageSampleDistance(double);
  void SetImageBackground(double);
  void SetFillBetweenSlices(bool);
  ///@}

  ///@{
  /**
   * Cropping, as ParaView's Volume representation of images does it (and
   * its properties UseCropping, CroppingOrigin, CroppingScale and box
   * widget): on, only what lies inside the box CroppingOrigin + the data's
   * bounds * CroppingScale, axis by axis, is drawn (the mapper's cropping
   * region planes, its central region kept). The bounds are every rank's
   * together, so that all ranks cut at the same planes.
   */
  void SetCropping(bool);
  vtkSetVector3Macro(CroppingOrigin, double);
  vtkGetVector3Macro(CroppingOrigin, double);
  vtkSetVector3Macro(CroppingScale, double);
  vtkGetVector3Macro(CroppingScale, double);
  ///@}

  ///@{
  /**
   * A CT transfer-function preset by name (vtkOctreeVolumePresets:
   * "ct-bone", "ct-skin", "ct-muscle"), or "none" (or empty, the default)
   * for ParaView's colour map and opacity function. A preset replaces them
   * for this representation (the shading stays the panel's) and sets the
   * mapper's ImageBackground to the preset's surface threshold, overriding
   * the ImageBackground property. An unknown name is an error and leaves
   * no preset. GetPresetNames lists the presets (the panel's choices).
   */
  void SetPreset(const char* name);
  const char* GetPreset() { return this->Preset.c_str(); }
  vtkStringArray* GetPresetNames();
  ///@}

  /**
   * The backend that drew the last picture on this process ("CUDA", "CPU"
   * or "none"), for scripts and tests.
   */
  const char* GetLastUsedBackendName();

  /**
   * The mapper (one per process).
   */
  vtkOctreeVolumeMapper* GetMapper() { return this->Mapper; }

protected:
  vtkOctreeVolumeRepresentation();
  ~vtkOctreeVolumeRepresentation() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  bool AddToView(vtkView* view) override;
  bool RemoveFromView(vtkView* view) override;

  /**
   * RequestData's part for a drawable input: keeps this rank's piece
   * (Cache), its bounds and size; reports an input the mapper cannot draw.
   */
  void CacheInput(vtkDataObject* data, int ranks);

  /**
   * REQUEST_UPDATE: hands the view this rank's piece and, for the
   * translucent blend modes, asks for ordered compositing where the view
   * can redistribute the points.
   */
  void DeliverPiece(vtkInformation* inInfo, vtkInformation* outInfo);

  /**
   * Why a translucent picture over several ranks may differ from a
   * one-rank one: pieces redistributed (points) or blended as they are
   * (images). Said once, on the first rank.
   */
  void WarnAboutBlendOrder(int ranks, bool redistributed);

  /**
   * REQUEST_RENDER: gives the mapper the view's piece, or the empty one
   * where this rank has nothing to draw.
   */
  void AttachPiece(vtkInformation* inInfo);

  /**
   * Colour array, scalar mode and component handling, as
   * vtkUnstructuredGridVolumeRepresentation::UpdateMapperParameters.
   */
  void UpdateMapperParameters();

  /**
   * The mapper's cropping region planes from CroppingOrigin, CroppingScale
   * and WholeBounds; cropping off where no rank has data.
   */
  void UpdateCropping();

  /**
   * True for the blend modes whose picture depends on the order in which
   * pieces are blended (everything but the opaque surface mode).
   */
  bool IsTranslucentBlendMode() const;

  /**
   * Whether the mapper can draw this data: a vtkPointSet or a vtkImageData.
   */
  static bool IsDrawable(vtkDataObject* data);

  /**
   * The point sets of composite data (multiblock or partitioned: a reader's
   * blocks) appended into one, as Merge Blocks makes them (vtkAppendDataSets:
   * polydata where every block is, else an unstructured grid; point arrays
   * that some blocks lack are dropped), or an empty vtkPolyData where this
   * rank holds no block. Null where a block is not a point set, whose class
   * goes to otherLeaf.
   */
  static vtkSmartPointer<vtkPointSet> MergedPointSets(vtkCompositeDataSet* composite, std::string& otherLeaf);

  /**
   * MergedPointSets of `composite`, made again only where the composite
   * data or a block changed since the last merge: an update that hands
   * over the same blocks (a blend mode or colour array chosen) keeps the
   * merged arrays, so the mapper keeps its octree, where a new append
   * copied every point and the mapper rebuilt from the copy.
   */
  vtkSmartPointer<vtkPointSet> MergedBlocks(vtkCompositeDataSet* composite, std::string& otherLeaf);

  /**
   * The latest modification time of `composite` and of its blocks (their
   * points and arrays).
   */
  static vtkMTimeType LatestBlockTime(vtkCompositeDataSet* composite);

  /**
   * Says, once for each set of names, which point arrays of the blocks of
   * `composite` the merged point set `merged` lacks (those some blocks do
   * not have, which Merge Blocks drops too): a colour map or a reflectivity
   * array among them would otherwise vanish without a word.
   */
  void ReportDroppedArrays(vtkCompositeDataSet* composite, vtkPointSet* merged);

  /**
   * The warning for an input the mapper cannot draw, naming its type (and
   * for composite data the block that is not a point set), what can be
   * drawn and the filter that converts it. Issued once per input type (and
   * on the first rank only): RequestData does not repeat it for property
   * changes or frames.
   */
  void ReportUndrawable(vtkDataObject* input, const std::string& otherLeaf = std::string());

  vtkNew<vtkOctreeVolumeMapper> Mapper;
  // This rank's piece (a shallow copy of the input); null when the input
  // cannot be drawn or there is none (the client of a client-server
  // session).
  vtkSmartPointer<vtkDataSet> Cache;
  // An empty vtkPolyData: the piece and the mapper's input where this rank
  // has nothing to draw, so that the volume always has its mapper (a
  // vtkPVLODVolume without one fails to render: "You must give me a
  // mapper!").
  vtkNew<vtkTrivialProducer> EmptyPiece;
  // The composite data last merged, when it or a block last changed then,
  // and the merged point set (MergedBlocks); null for other input.
  vtkWeakPointer<vtkCompositeDataSet> MergedInput;
  vtkMTimeType MergedInputTime = 0;
  vtkSmartPointer<vtkPointSet> Merged;
  std::string ReportedType;
  std::string ReportedDroppedArrays;
  // Every rank's bounds together (this rank's on one), for cropping.
  double WholeBounds[6];
  bool Cropping = false;
  double CroppingOrigin[3] = { 0, 0, 0 };
  double CroppingScale[3] = { 1, 1, 1 };
  bool OrderWarningIssued = false;

  // The preset (SetPreset): its own property, whose settings follow
  // this->Property and whose functions are the preset's.
  void UpdatePreset();
  std::string Preset;
  double ImageBackground = 0.0;
  vtkNew<vtkOctreeVolumePresets> Presets;
  vtkNew<vtkVolumeProperty> PresetProperty;
  vtkMTimeType PresetPropertyTime = 0;
  std::string PresetApplied;

private:
  vtkOctreeVolumeRepresentation(const vtkOctreeVolumeRepresentation&) = delete;
  void operator=(const vtkOctreeVolumeRepresentation&) = delete;
};

#endif
