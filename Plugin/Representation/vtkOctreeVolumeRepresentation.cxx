#include "vtkOctreeVolumeRepresentation.h"

#include "vtkAlgorithmOutput.h"
#include "vtkAppendDataSets.h"
#include "vtkBoundingBox.h"
#include "vtkCellArray.h"
#include "vtkColorTransferFunction.h"
#include "vtkCommunicator.h"
#include "vtkCompositeDataSet.h"
#include "vtkCompositeDataSetRange.h"
#include "vtkDataSet.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkLODProp3D.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkOctreeVolumeMapper.h"
#include "vtkOutputWindow.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPointSet.h"
#include "vtkPolyData.h"
#include "vtkOctreeLODVolume.h"
#include "octorayParallelPieces.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPVRenderView.h"
#include "vtkRenderer.h"
#include "vtkTable.h"
#include "vtkTrivialProducer.h"
#include "vtkUnstructuredGrid.h"
#include "vtkVolumeProperty.h"
#include "vtkWeakPointer.h"

#include <algorithm> // for std::copy, std::copy_n
#include <set>
#include <string>


vtkStandardNewMacro(vtkOctreeVolumeRepresentation);

// A warning said by the first rank only: every rank runs the representation
// with the same settings and data types, and the first rank's messages are
// the ones a ParaView client shows (pvbatch prints every rank's).
#define vtkWarningOnFirstRankMacro(x)                                                              \
  do                                                                                               \
  {                                                                                                \
    vtkMultiProcessController* firstRankController =                                               \
      vtkMultiProcessController::GetGlobalController();                                            \
    if (!firstRankController || firstRankController->GetLocalProcessId() == 0)                     \
    {                                                                                              \
      vtkWarningMacro(x);                                                                          \
    }                                                                                              \
  } while (false)

//----------------------------------------------------------------------------
vtkOctreeVolumeRepresentation::vtkOctreeVolumeRepresentation()
{
  this->Actor = vtkSmartPointer<vtkOctreeLODVolume>::New();
  this->Actor->SetProperty(this->Property);
  // The volume keeps its mapper on every rank, whatever the rank holds
  // (ParaView's volume representations do the same): vtkPVLODVolume reports
  // "You must give me a mapper!" and vtkLODProp3D then crashes when a
  // visible volume has none. Where there is nothing to draw, the mapper's
  // input is an empty vtkPolyData.
  vtkNew<vtkPolyData> empty;
  this->EmptyPiece->SetOutput(empty);
  this->Mapper->SetInputConnection(this->EmptyPiece->GetOutputPort());
  // The mapper's own level of detail (LODPixelThreshold) replaces ParaView's
  // outline LOD: the octree is cheap to draw coarsely, so no LOD mapper.
  this->Actor->SetMapper(this->Mapper);
  this->Actor->SetEnableLOD(0);
  // Every pipeline update hands the mapper a new data set (RequestData's
  // copy), never the same points moved in place, so the mapper rebuilds and
  // never updates: points kept for updates would only hold memory, about
  // two thirds of the engine's for a static scene.
  this->Mapper->KeepPointsForUpdatesOff();
  vtkMath::UninitializeBounds(this->DataBounds);
  vtkMath::UninitializeBounds(this->WholeBounds);
}

//----------------------------------------------------------------------------
vtkOctreeVolumeRepresentation::~vtkOctreeVolumeRepresentation() = default;

//----------------------------------------------------------------------------
int vtkOctreeVolumeRepresentation::FillInputPortInformation(int, vtkInformation* info)
{
  // Any data object: the representation is offered for whatever the
  // render view shows (composite data, rectilinear grids, ...), and says
  // itself, once, when the mapper cannot draw it (see ReportUndrawable). A
  // narrower type here would leave the pipeline to fail with a message that
  // names neither the representation nor a remedy ("Can not execute simple
  // algorithm ... without output ports" for composite data).
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObject");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

//----------------------------------------------------------------------------
bool vtkOctreeVolumeRepresentation::IsDrawable(vtkDataObject* data)
{
  // What the mapper draws: the points of any point set, or the voxels of an
  // image above ImageBackground.
  return vtkPointSet::SafeDownCast(data) || vtkImageData::SafeDownCast(data);
}

//----------------------------------------------------------------------------
vtkSmartPointer<vtkPointSet> vtkOctreeVolumeRepresentation::MergedPointSets(
  vtkCompositeDataSet* composite, std::string& otherLeaf)
{
  vtkNew<vtkAppendDataSets> append;
  bool polyData = true;
  for (vtkDataObject* leaf : vtk::Range(composite))
  {
    auto* points = vtkPointSet::SafeDownCast(leaf);
    if (!points)
    {
      otherLeaf = leaf->GetClassName();
      return nullptr;
    }
    polyData = polyData && vtkPolyData::SafeDownCast(points);
    append->AddInputData(points);
  }
  if (append->GetNumberOfInputConnections(0) == 0)
  {
    return vtkSmartPointer<vtkPolyData>::New(); // no block on this rank: an empty piece
  }
  append->SetOutputDataSetType(polyData ? VTK_POLY_DATA : VTK_UNSTRUCTURED_GRID);
  append->SetOutputPointsPrecision(vtkAlgorithm::DEFAULT_PRECISION);
  append->Update();
  return vtkPointSet::SafeDownCast(append->GetOutputDataObject(0));
}

//----------------------------------------------------------------------------
vtkMTimeType vtkOctreeVolumeRepresentation::LatestBlockTime(vtkCompositeDataSet* composite)
{
  // A composite data set's own time does not follow its blocks: a script
  // that moves a block's points in place modifies only that block.
  vtkMTimeType latest = composite->GetMTime();
  for (vtkDataObject* leaf : vtk::Range(composite))
  {
    latest = std::max(latest, leaf->GetMTime());
  }
  return latest;
}

//----------------------------------------------------------------------------
vtkSmartPointer<vtkPointSet> vtkOctreeVolumeRepresentation::MergedBlocks(
  vtkCompositeDataSet* composite, std::string& otherLeaf)
{
  const vtkMTimeType changed = LatestBlockTime(composite);
  if (this->Merged && composite == this->MergedInput && changed == this->MergedInputTime)
  {
    return this->Merged;
  }
  this->Merged = MergedPointSets(composite, otherLeaf);
  this->MergedInput = composite;
  this->MergedInputTime = changed;
  if (this->Merged)
  {
    this->ReportDroppedArrays(composite, this->Merged);
  }
  return this->Merged;
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::ReportDroppedArrays(vtkCompositeDataSet* composite, vtkPointSet* merged)
{
  std::set<std::string> dropped;
  for (vtkDataObject* leaf : vtk::Range(composite))
  {
    vtkPointData* arrays = vtkDataSet::SafeDownCast(leaf)->GetPointData();
    for (int i = 0; i < arrays->GetNumberOfArrays(); ++i)
    {
      const char* name = arrays->GetArrayName(i);
      if (name && !merged->GetPointData()->HasArray(name))
      {
        dropped.insert(name);
      }
    }
  }
  std::string names;
  for (const std::string& name : dropped)
  {
    names += (names.empty() ? "" : ", ") + ("'" + name + "'");
  }
  if (names == this->ReportedDroppedArrays)
  {
    return;
  }
  this->ReportedDroppedArrays = names;
  if (!names.empty())
  {
    vtkWarningMacro("Octree Volume draws the blocks of this "
      << composite->GetClassName() << " as one point set with the point arrays every block has, as Merge "
      << "Blocks makes it: " << names << (dropped.size() == 1 ? " is" : " are")
      << " not in every block, so not drawn.");
  }
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::ReportUndrawable(vtkDataObject* input, const std::string& otherLeaf)
{
  const std::string type = input->GetClassName() + (otherLeaf.empty() ? "" : " holding a " + otherLeaf);
  if (type == this->ReportedType)
  {
    return;
  }
  this->ReportedType = type;
  const char* remedy = "convert it first (e.g. Cell Centers, or Resample To Image)";
  if (vtkCompositeDataSet::SafeDownCast(input))
  {
    remedy = "apply Merge Blocks first to make one unstructured grid of its blocks";
  }
  else if (vtkTable::SafeDownCast(input))
  {
    remedy = "apply Table To Points first (or open a particle text file with the Octoray "
             "Particle Reader)";
  }
  // Every rank holds the same type: one message, from the first rank.
  vtkWarningOnFirstRankMacro("Octree Volume cannot draw a "
    << type << ": it draws point sets (vtkPointSet: vtkPolyData, vtkUnstructuredGrid, "
    << "vtkStructuredGrid, ...), images (vtkImageData) and composite data of point sets; nothing "
    << "is drawn. To draw this data, " << remedy << ".");
}

namespace
{
// The ranks of the global controller: 1 without MPI.
int RankCount()
{
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  return controller ? controller->GetNumberOfProcesses() : 1;
}

// The bounds of every rank's piece together (uninitialised where no rank has
// points), from this rank's `local` (uninitialised where it has none). Every
// rank must call it: the reduction is collective.
void ReduceBoundsOverRanks(const double local[6], double global[6])
{
  const bool valid = vtkMath::AreBoundsInitialized(local);
  double sent[6];
  for (int a = 0; a < 3; ++a)
  {
    // Minima and negated maxima: one MIN reduction gives both.
    sent[2 * a] = valid ? local[2 * a] : VTK_DOUBLE_MAX;
    sent[2 * a + 1] = valid ? -local[2 * a + 1] : VTK_DOUBLE_MAX;
  }
  double reduced[6];
  vtkMultiProcessController::GetGlobalController()->AllReduce(sent, reduced, 6, vtkCommunicator::MIN_OP);
  for (int a = 0; a < 3; ++a)
  {
    global[2 * a] = reduced[2 * a];
    global[2 * a + 1] = -reduced[2 * a + 1];
  }
}
}

//----------------------------------------------------------------------------
int vtkOctreeVolumeRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkMath::UninitializeBounds(this->DataBounds);
  this->DataSize = 0;
  this->Cache = nullptr;
  const int ranks = RankCount();
  if (inputVector[0]->GetNumberOfInformationObjects() == 1)
  {
    this->CacheInput(vtkDataObject::GetData(inputVector[0], 0), ranks);
  }
  // Every rank builds its octree in the cube around the bounds of the whole
  // data (and, with LeafDepth set, at the same depth), so the ranks' voxels
  // align and depth compositing reproduces the one-rank picture; one rank
  // takes the data's bounds too, not those of the points it draws (an
  // image's voxels above the background), whose cube put an image split
  // over ranks on a shifted grid. RequestData runs on every rank of the
  // pipeline update (whatever each rank holds, also nothing or an
  // undrawable type), so the reduction is collective.
  double globalBounds[6];
  std::copy_n(this->DataBounds, 6, globalBounds);
  if (ranks > 1)
  {
    ReduceBoundsOverRanks(this->DataBounds, globalBounds);
  }
  this->Mapper->SetRootBounds(globalBounds);
  std::copy_n(globalBounds, 6, this->WholeBounds);

  return this->Superclass::RequestData(request, inputVector, outputVector);
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::CacheInput(vtkDataObject* data, int ranks)
{
  // Composite data of point sets is drawn as one point set, as Merge Blocks
  // would make it.
  vtkSmartPointer<vtkPointSet> merged;
  std::string otherLeaf;
  if (auto* composite = vtkCompositeDataSet::SafeDownCast(data))
  {
    merged = this->MergedBlocks(composite, otherLeaf);
  }
  else
  {
    this->Merged = nullptr; // the memory of blocks no longer shown
  }
  if (!IsDrawable(merged ? merged.Get() : data))
  {
    if (data)
    {
      this->ReportUndrawable(data, otherLeaf);
    }
    return;
  }
  if (merged)
  {
    data = merged;
  }
  vtkDataSet* input = vtkDataSet::SafeDownCast(data);
  vtkPointSet* pointSet = vtkPointSet::SafeDownCast(input);
  if (pointSet && ranks > 1 && this->IsTranslucentBlendMode())
  {
    // The view will redistribute the piece for ordered compositing.
    this->Cache = octoray::PointCloudPiece(pointSet);
  }
  else
  {
    // A shallow copy: the view may move the piece, and the upstream
    // filter's output must stay untouched.
    this->Cache.TakeReference(input->NewInstance());
    this->Cache->ShallowCopy(input);
  }
  auto* cached = vtkPointSet::SafeDownCast(this->Cache);
  if (cached && !cached->GetPoints())
  {
    // An empty piece (a reader's output on the ranks it did not read on)
    // has no vtkPoints at all; the view's redistribution and delivery
    // expect one.
    vtkNew<vtkPoints> none;
    cached->SetPoints(none);
  }
  if (this->Cache->GetNumberOfPoints() > 0)
  {
    this->Cache->GetBounds(this->DataBounds);
  }
  this->DataSize = this->Cache->GetActualMemorySize();
  this->ReportedType.clear();
}

//----------------------------------------------------------------------------
bool vtkOctreeVolumeRepresentation::IsTranslucentBlendMode() const
{
  const int mode = this->Mapper->GetBlendMode();
  return mode != vtkOctreeVolumeMapper::SURFACE_BLEND &&
    mode != vtkVolumeMapper::ISOSURFACE_BLEND;
}

//----------------------------------------------------------------------------
int vtkOctreeVolumeRepresentation::ProcessViewRequest(
  vtkInformationRequestKey* request_type, vtkInformation* inInfo, vtkInformation* outInfo)
{
  if (!this->Superclass::ProcessViewRequest(request_type, inInfo, outInfo))
  {
    return 0;
  }
  if (request_type == vtkPVView::REQUEST_UPDATE())
  {
    this->DeliverPiece(inInfo, outInfo);
  }
  else if (request_type == vtkPVView::REQUEST_RENDER())
  {
    this->AttachPiece(inInfo);
  }
  return 1;
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::DeliverPiece(vtkInformation* inInfo, vtkInformation* outInfo)
{
  // This rank's points, or an empty vtkPolyData where it has none (an
  // empty piece, an input the mapper cannot draw, or no input at all).
  vtkDataObject* piece =
    this->Cache ? static_cast<vtkDataObject*>(this->Cache) : this->EmptyPiece->GetOutputDataObject(0);
  vtkPVRenderView::SetPiece(inInfo, this, piece, this->DataSize);

  // Every process traces its own points; the picture is composited, never
  // the data gathered on the client.
  vtkPVRenderView::SetRequiresDistributedRendering(inInfo, this, true);

  vtkNew<vtkMatrix4x4> matrix;
  this->Actor->GetMatrix(matrix);
  vtkPVRenderView::SetGeometryBounds(inInfo, this, this->DataBounds, matrix);

  if (!this->IsTranslucentBlendMode())
  {
    return;
  }
  const bool redistributed = this->Cache && this->Cache->IsA("vtkPointSet");
  if (redistributed)
  {
    // Blended modes: the view cuts the points into spatially disjoint
    // pieces (k-d tree over the ranks) that IceT blends in order.
    outInfo->Set(vtkPVRenderView::NEED_ORDERED_COMPOSITING(), 1);
    vtkPVRenderView::SetOrderedCompositingConfiguration(inInfo, this,
      vtkPVRenderView::DATA_IS_REDISTRIBUTABLE | vtkPVRenderView::USE_DATA_FOR_LOAD_BALANCING);
    vtkPVRenderView::SetRedistributionModeToUniquelyAssignBoundaryCells(inInfo, this);
  }
  // Nothing is blended where nothing is drawn (no input, or one the mapper
  // cannot draw, which ReportUndrawable names).
  const int ranks = RankCount();
  if (this->Cache && ranks > 1 && !this->OrderWarningIssued)
  {
    this->OrderWarningIssued = true;
    this->WarnAboutBlendOrder(ranks, redistributed);
  }
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::WarnAboutBlendOrder(int ranks, bool redistributed)
{
  if (!redistributed)
  {
    // Image data is not redistributed by the view: the pieces the reader
    // made are blended as they are.
    vtkWarningOnFirstRankMacro("Octree Volume: translucent blend modes on image data over "
      << ranks << " ranks blend each rank's picture without ordering; use the surface modes "
      << "or one rank for an exact picture.");
    return;
  }
  vtkWarningOnFirstRankMacro("Octree Volume: with a translucent blend mode over "
    << ranks
    << " ranks the points are redistributed into disjoint pieces and blended in order; "
       "each piece has its own octree, so voxels along the cuts may differ from a "
       "one-rank picture. The surface modes composite exactly.");
  const std::string compat = octoray::MissingExpatCompat();
  if (!compat.empty())
  {
    vtkWarningOnFirstRankMacro("Octree Volume: this libexpat defers reparsing (Debian 12's "
      "libexpat1 2.5.0-1+deb12u2 and later), and ParaView 5.11's ranks then cannot exchange "
      "data: the redistribution fails and ranks draw nothing. Start ParaView with LD_PRELOAD="
      << compat << " (see the README's ParaView section).");
  }
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::AttachPiece(vtkInformation* inInfo)
{
  vtkAlgorithmOutput* producerPort = vtkPVRenderView::GetPieceProducer(inInfo, this);
  vtkDataSet* piece =
    producerPort ? vtkDataSet::SafeDownCast(producerPort->GetProducer()->GetOutputDataObject(0)) : nullptr;
  // Once per server, by its first rank: say which backend draws, so a
  // server without a GPU tells the user it uses the CPU (it was said by
  // every rank for every display).
  static bool backendReported = false;
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  if (!backendReported && (!controller || controller->GetLocalProcessId() == 0))
  {
    backendReported = true;
    if (!vtkOctreeVolumeMapper::IsCudaAvailable())
    {
      vtkOutputWindowDisplayText("Octree Volume: no usable CUDA device on this server; "
                                 "vtkOctreeVolumeMapper uses its CPU backend.\n");
    }
  }
  // Every rank keeps the mapper on the volume (vtkPVLODVolume has no
  // other LOD to fall back on); a rank with nothing to draw gives it the
  // empty piece, draws nothing, and adds only background (far depth) to
  // the composite.
  if (this->Cache && IsDrawable(piece) && piece->GetNumberOfPoints() > 0)
  {
    this->Mapper->SetInputConnection(producerPort);
  }
  else
  {
    this->Mapper->SetInputConnection(this->EmptyPiece->GetOutputPort());
  }
  this->UpdateMapperParameters();
  this->Actor->SetMapper(this->Mapper);
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::UpdateMapperParameters()
{
  const char* colorArrayName = nullptr;
  int fieldAssociation = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  vtkInformation* info = this->GetInputArrayInformation(0);
  if (info && info->Has(vtkDataObject::FIELD_ASSOCIATION()) &&
    info->Has(vtkDataObject::FIELD_NAME()))
  {
    colorArrayName = info->Get(vtkDataObject::FIELD_NAME());
    fieldAssociation = info->Get(vtkDataObject::FIELD_ASSOCIATION());
  }
  this->Mapper->SelectScalarArray(colorArrayName);
  // The octree holds point attributes, and an image's cell scalars as
  // voxels (the mapper warns about a point set's cell scalars); no array
  // means the voxels' own colours or white. A CT preset maps the data's
  // values: with no array chosen (Solid Color) it maps the active point
  // scalars, as choosing the preset asks.
  const bool solidColor = !colorArrayName || !*colorArrayName;
  if (solidColor && !this->Preset.empty())
  {
    this->Mapper->SetScalarModeToDefault();
  }
  else
  {
    this->Mapper->SetScalarMode(fieldAssociation == vtkDataObject::FIELD_ASSOCIATION_CELLS
        ? VTK_SCALAR_MODE_USE_CELL_FIELD_DATA
        : VTK_SCALAR_MODE_USE_POINT_FIELD_DATA);
  }

  // As ParaView's Volume representation: "Map Scalars" off (or
  // multi-component mapping) makes 3/4-component arrays direct colours.
  this->Property->SetIndependentComponents(this->MapScalars && !this->MultiComponentsMapping);
  this->UpdatePreset();
  this->UpdateCropping();
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::UpdateCropping()
{
  const bool crop = this->Cropping && vtkMath::AreBoundsInitialized(this->WholeBounds);
  this->Mapper->SetCropping(crop);
  if (crop)
  {
    double planes[6];
    for (int i = 0; i < 6; ++i)
    {
      planes[i] = this->CroppingOrigin[i / 2] + this->WholeBounds[i] * this->CroppingScale[i / 2];
    }
    this->Mapper->SetCroppingRegionPlanes(planes);
    this->Mapper->SetCroppingRegionFlagsToSubVolume();
  }
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::SetCropping(bool on)
{
  if (this->Cropping != on)
  {
    this->Cropping = on;
    this->Modified();
  }
}

//----------------------------------------------------------------------------
// With a preset, the volume draws with PresetProperty: this->Property's
// settings (shading, components, ...) and the preset's colour and opacity.
void vtkOctreeVolumeRepresentation::UpdatePreset()
{
  if (this->Preset.empty())
  {
    this->Actor->SetProperty(this->Property);
    this->Mapper->SetImageBackground(this->ImageBackground);
    return;
  }
  if (this->PresetApplied != this->Preset || this->Property->GetMTime() > this->PresetPropertyTime)
  {
    vtkNew<vtkColorTransferFunction> color;
    vtkNew<vtkPiecewiseFunction> opacity;
    this->Presets->Apply(this->Preset.c_str(), color, opacity);
    this->PresetProperty->DeepCopy(this->Property);
    this->PresetProperty->SetColor(color);
    this->PresetProperty->SetScalarOpacity(opacity);
    this->PresetApplied = this->Preset;
    this->PresetPropertyTime = this->Property->GetMTime();
  }
  this->Actor->SetProperty(this->PresetProperty);
  this->Mapper->SetImageBackground(vtkOctreeVolumePresets::GetSurfaceThreshold(this->Preset.c_str()));
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::SetPreset(const char* name)
{
  std::string preset = name ? name : "";
  if (preset == "none" || preset == "None")
  {
    preset.clear();
  }
  if (!preset.empty() && !vtkOctreeVolumePresets::HasPreset(preset.c_str()))
  {
    vtkErrorMacro("Unknown preset '" << preset << "'; known presets: "
                                     << vtkOctreeVolumePresets::GetNamesAsString() << " (or none)");
    preset.clear();
  }
  if (preset != this->Preset)
  {
    this->Preset = preset;
    this->Modified();
  }
}

vtkStringArray* vtkOctreeVolumeRepresentation::GetPresetNames()
{
  return this->Presets->GetNames();
}

//----------------------------------------------------------------------------
bool vtkOctreeVolumeRepresentation::AddToView(vtkView* view)
{
  vtkPVRenderView* rview = vtkPVRenderView::SafeDownCast(view);
  if (rview)
  {
    rview->GetRenderer()->AddActor(this->Actor);
    return this->Superclass::AddToView(view);
  }
  return false;
}

//----------------------------------------------------------------------------
bool vtkOctreeVolumeRepresentation::RemoveFromView(vtkView* view)
{
  vtkPVRenderView* rview = vtkPVRenderView::SafeDownCast(view);
  if (rview)
  {
    rview->GetRenderer()->RemoveActor(this->Actor);
    return this->Superclass::RemoveFromView(view);
  }
  return false;
}

//----------------------------------------------------------------------------
const char* vtkOctreeVolumeRepresentation::GetLastUsedBackendName()
{
  return this->Mapper->GetLastUsedBackendName();
}

//----------------------------------------------------------------------------
// Forwarded to vtkVolumeProperty.
void vtkOctreeVolumeRepresentation::SetAmbient(double val)
{
  this->Property->SetAmbient(val);
}
void vtkOctreeVolumeRepresentation::SetDiffuse(double val)
{
  this->Property->SetDiffuse(val);
}
void vtkOctreeVolumeRepresentation::SetSpecular(double val)
{
  this->Property->SetSpecular(val);
}
void vtkOctreeVolumeRepresentation::SetSpecularPower(double val)
{
  this->Property->SetSpecularPower(val);
}
void vtkOctreeVolumeRepresentation::SetShade(bool val)
{
  this->Property->SetShade(val);
}

//----------------------------------------------------------------------------
// Forwarded to the mapper. The blend mode also decides whether the view must
// composite in order, so it marks the representation modified (a new
// REQUEST_UPDATE pass).
void vtkOctreeVolumeRepresentation::SetBlendMode(int val)
{
  if (this->Mapper->GetBlendMode() != val)
  {
    this->Mapper->SetBlendMode(val);
    this->MarkModified();
  }
}
void vtkOctreeVolumeRepresentation::SetRequestedBackend(int val)
{
  this->Mapper->SetRequestedBackend(val);
}
void vtkOctreeVolumeRepresentation::SetLeafDepth(int val)
{
  this->Mapper->SetLeafDepth(val);
}
void vtkOctreeVolumeRepresentation::SetLODPixelThreshold(double val)
{
  this->Mapper->SetLODPixelThreshold(val);
}
void vtkOctreeVolumeRepresentation::SetShadows(bool val)
{
  this->Mapper->SetShadows(val);
}
void vtkOctreeVolumeRepresentation::SetEstimateNormals(bool val)
{
  this->Mapper->SetEstimateNormals(val);
}
void vtkOctreeVolumeRepresentation::SetMaximumBounces(int val)
{
  this->Mapper->SetMaximumBounces(val);
}
void vtkOctreeVolumeRepresentation::SetDepthCue(double val)
{
  this->Mapper->SetDepthCue(val);
}
void vtkOctreeVolumeRepresentation::SetImageSampleDistance(double val)
{
  this->Mapper->SetImageSampleDistance(val);
}
void vtkOctreeVolumeRepresentation::SetImageBackground(double val)
{
  this->ImageBackground = val; // a preset overrides it (UpdatePreset)
  this->Mapper->SetImageBackground(this->Preset.empty() ? val : this->Mapper->GetImageBackground());
}
void vtkOctreeVolumeRepresentation::SetFillBetweenSlices(bool val)
{
  this->Mapper->SetFillBetweenSlices(val);
}

//----------------------------------------------------------------------------
void vtkOctreeVolumeRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Mapper: " << this->Mapper->GetClassName() << "\n";
  os << indent << "Cache: " << (this->Cache ? this->Cache->GetClassName() : "(none)") << "\n";
  os << indent << "Preset: " << (this->Preset.empty() ? "none" : this->Preset) << "\n";
  os << indent << "Cropping: " << (this->Cropping ? "on" : "off") << ", origin " << this->CroppingOrigin[0]
     << " " << this->CroppingOrigin[1] << " " << this->CroppingOrigin[2] << ", scale "
     << this->CroppingScale[0] << " " << this->CroppingScale[1] << " " << this->CroppingScale[2] << "\n";
}
