/**
 * @class   vtkOctreeVolumeMapper
 * @brief   ray-traces a sparse voxel octree of point data into a VTK renderer
 *
 * vtkOctreeVolumeMapper renders point data (a vtkPointSet: points with
 * optional colours, scalars, reflectivity, refraction and normals) or a
 * vtkImageData (every voxel above ImageBackground becomes a point, and
 * between slices farther apart than the pixels, interpolated points fill
 * the gaps: FillBetweenSlices; with cell scalars the voxels are the cells,
 * at their centres) by
 * building the octree engine's sparse voxel octree of the points and
 * ray-tracing it. It holds the VTK plumbing shared by both backends:
 *
 * - the camera: rays come from the inverse of
 *   vtkCamera::GetCompositeProjectionTransformMatrix (times the volume's
 *   matrix), so perspective, parallel projection, clipping range and tiled
 *   or off-axis viewports agree with VTK by construction;
 * - compositing: the depth of the opaque geometry already drawn in the
 *   viewport is read back so that rays stop there, and the picture
 *   (premultiplied RGBA) is drawn as a full-viewport quad that writes
 *   gl_FragDepth, so the octree hides and is hidden by other actors;
 *   under dual depth peeling of volumes (UseDepthPeelingForVolumes, on in
 *   ParaView) it is drawn once a frame onto what the peeling composites
 *   over, behind every translucent layer, and said once;
 * - vtkVolumeProperty: shade on/off, ambient, diffuse, specular, specular
 *   power, the colour transfer function and scalar opacity on the active
 *   scalars; of several components, on the value the colour function's
 *   VectorMode and VectorComponent choose (the magnitude or one component),
 *   as vtkScalarsToColors maps vectors and ParaView's colour map offers
 *   them; with IndependentComponents off, 3- or 4-component active scalars
 *   are colours (other dependent components are said once); a gradient
 *   opacity and 2D transfer functions are not applied, and said once;
 * - blend modes: composite, maximum, minimum, average, additive, and
 *   SURFACE_BLEND (first hit), the default; ISOSURFACE_BLEND, SLICE_BLEND
 *   and values VTK does not know draw as SURFACE_BLEND and say so once;
 * - settings no frame can be drawn with (a NaN from the volume property,
 *   which VTK's clamped setters let through) are an error said once, and
 *   nothing is drawn until they change; the octree is kept;
 * - renderer lights (headlight, camera and scene lights, positional or
 *   directional, colour and intensity) become engine lights;
 * - clipping planes (AddClippingPlane, in world coordinates) and cropping
 *   to the sub-volume (SetCropping, CroppingRegionPlanes with
 *   SetCroppingRegionFlagsToSubVolume) take voxels away for every ray:
 *   what they remove is neither seen, nor casts shadows, nor is reflected;
 *   a voxel they cut is drawn up to the cut and lit by the plane's normal
 *   (the flat face a solid cut open shows, where the data's own normals,
 *   a CT's gradient inside bone, are noise). At most 12 planes together;
 *   VTK's other cropping regions are said once and not applied;
 * - work only when needed: the octree is rebuilt when the input or the
 *   arrays it uses change, updated in place when only point positions change
 *   (animation), and the picture is re-traced only when the camera, lights,
 *   properties, settings or the opaque depth change.
 *
 * RequestedBackend chooses the engine at run time, as vtkSmartVolumeMapper's
 * RequestedRenderMode does: AUTO (the default) takes CUDA where a device is
 * usable; a CUDA failure (no device, out of memory, a lost device) falls
 * back to the CPU backend with one warning. GetLastUsedBackend() says which
 * backend made the last picture. On CUDA, the picture goes from device
 * memory straight into the OpenGL textures (CUDA-OpenGL interop) where the
 * window's OpenGL runs on the same GPU, and through host memory otherwise.
 * Each process picks its CUDA device by its rank on its host (CudaDevice).
 *
 * Render() fires VolumeMapperRenderStartEvent and VolumeMapperRenderEndEvent
 * and sets TimeToDraw, so VTK's interactive-rate logic sees what a frame
 * costs.
 *
 * Positional lights are treated as point lights without cone or attenuation.
 *
 * vtkCPUOctreeVolumeMapper and vtkCudaOctreeVolumeMapper are this class
 * with the backend preset, kept for their names.
 *
 * @sa vtkCPUOctreeVolumeMapper vtkCudaOctreeVolumeMapper
 */
#ifndef vtkOctreeVolumeMapper_h
#define vtkOctreeVolumeMapper_h

#include "octorayRenderingVolumeModule.h" // for export macro
#include "vtkVolumeMapper.h"

class vtkPolyData;

class OCTORAYRENDERINGVOLUME_EXPORT vtkOctreeVolumeMapper : public vtkVolumeMapper
{
public:
  static vtkOctreeVolumeMapper* New();
  vtkTypeMacro(vtkOctreeVolumeMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * First-hit rendering of the octree's voxels (the engine's surface mode),
   * beside vtkVolumeMapper's blend modes. The default blend mode.
   */
  enum
  {
    SURFACE_BLEND = 10
  };
  void SetBlendModeToSurface() { this->SetBlendMode(SURFACE_BLEND); }

  enum Backend
  {
    BACKEND_AUTO = 0,
    BACKEND_CUDA = 1,
    BACKEND_CPU = 2
  };

  ///@{
  /**
   * Which engine backend to use. AUTO: CUDA when a device is usable, else
   * the CPU. CUDA: CUDA, falling back to the CPU with a warning. CPU: the
   * CPU backend (the reference). Changing it rebuilds the octree at the next
   * render.
   */
  vtkSetClampMacro(RequestedBackend, int, BACKEND_AUTO, BACKEND_CPU);
  vtkGetMacro(RequestedBackend, int);
  void SetRequestedBackendToAuto() { this->SetRequestedBackend(BACKEND_AUTO); }
  void SetRequestedBackendToCuda() { this->SetRequestedBackend(BACKEND_CUDA); }
  void SetRequestedBackendToCPU() { this->SetRequestedBackend(BACKEND_CPU); }
  ///@}

  /**
   * The backend that made the last picture (BACKEND_CUDA or BACKEND_CPU),
   * or -1 before the first render. GetLastUsedBackendName() gives "CUDA",
   * "CPU" or "none"; GetBackendDescription() the engine's own words, e.g.
   * "CPU (2 threads)".
   */
  int GetLastUsedBackend();
  const char* GetLastUsedBackendName();
  const char* GetBackendDescription();

  /**
   * Whether a CUDA device is usable here (CUDA compiled in and a device
   * present).
   */
  static bool IsCudaAvailable();

  ///@{
  /**
   * The CUDA device to work on. -1 (the default) picks one by the process's
   * rank on its host, local rank % device count, so that pvbatch ranks on a
   * multi-GPU host spread over its GPUs: the local rank comes from the MPI
   * launcher's environment (Open MPI, MPICH, Intel MPI, MVAPICH2, Slurm, Cray
   * PALS) or else from VTK's global controller. The environment variable
   * OCTORAY_CUDA_DEVICE sets it for every mapper of a process. An index past
   * the devices wraps around. GetCudaDeviceInUse() is the device of the last
   * picture (-1 on the CPU).
   */
  vtkSetClampMacro(CudaDevice, int, -1, VTK_INT_MAX);
  vtkGetMacro(CudaDevice, int);
  int GetCudaDeviceInUse();
  ///@}

  ///@{
  /**
   * CUDA: copy the traced picture from device memory into the compositing
   * textures on the GPU (CUDA-OpenGL interop) rather than through host
   * memory. On by default; where the window's OpenGL is not driven by the
   * engine's GPU (Mesa's software OpenGL, another GPU), the mapper says so
   * once and takes the host path. GetLastPictureTransfer() says which path
   * the last traced picture took.
   */
  vtkSetMacro(UseCudaGLInterop, bool);
  vtkGetMacro(UseCudaGLInterop, bool);
  vtkBooleanMacro(UseCudaGLInterop, bool);
  enum PictureTransfer
  {
    TRANSFER_NONE = 0,  // nothing traced yet
    TRANSFER_HOST = 1,  // host memory, then a texture upload
    TRANSFER_DEVICE = 2 // device to device through CUDA-OpenGL interop
  };
  int GetLastPictureTransfer();
  const char* GetLastPictureTransferName(); // "none", "host" or "CUDA-OpenGL interop"
  ///@}

  ///@{
  /**
   * Octree leaf level, 1..21, or 0 (the default) to choose it from the data:
   * for points on a lattice (a vtkImageData; a point set whose field data
   * names its lattice, as vtkSliceStackReader's particles do) the leaves are
   * as large as the lattice's largest step and aligned with it, so the
   * volume has no gap (octorayLattice.h); for other points, the engine's
   * choice (the median leaf holds one point).
   */
  vtkSetClampMacro(LeafDepth, int, 0, 21);
  vtkGetMacro(LeafDepth, int);
  ///@}

  ///@{
  /**
   * Build the octree inside the cube around these bounds (xmin, xmax, ymin,
   * ymax, zmin, zmax) instead of one fitted to the input's points; every
   * point must lie inside and the bounds must be finite (else a warning
   * names them and nothing is drawn). Data split over parallel ranks then
   * gives every rank the same voxel grid, so the composited picture matches
   * one rank's (with a fixed LeafDepth). Uninitialized bounds (the default,
   * min > max) fit the cube to the points.
   */
  vtkSetVector6Macro(RootBounds, double);
  vtkGetVector6Macro(RootBounds, double);
  ///@}

  /**
   * Bounds that hold the voxels the mapper draws: the input's bounds out to
   * the boundaries of the leaves around the outermost points, which reach
   * past the points by up to a leaf (GetBounds() gives the points' bounds,
   * as vtkVolumeMapper does). Exact once the octree is built for the current
   * input; before that (the first frame) from the cube the build will use
   * and LeafDepth, or, with the automatic depth, a depth of log8(n / 2) for
   * n points, which the automatic choice (half the leaves hold one point)
   * does not go below: leaves of that shallower level hold the deeper ones.
   * (Image input without RootBounds, whose cube is fitted to the voxels
   * above ImageBackground: the image's bounds widened by half their largest
   * extent until the build.) A compositor that crops each process's picture
   * to the screen rectangle of its props' bounds (IceT in ParaView) must be
   * given these, or the outer parts of the edge voxels are cut off.
   * Uninitialized (min > max) without input points.
   */
  void GetVoxelBounds(double bounds[6]);

  ///@{
  /**
   * Level of detail: rays stop descending at voxels smaller than this many
   * pixels and draw the node there (its averaged attributes). 1 (the
   * default): leaves smaller than a pixel, which a ray would mostly miss
   * (a see-through, speckled picture of a dense cloud), are drawn by their
   * ancestor of about a pixel, and the trace does not pay for descending
   * below what the screen shows. 0 always descends to the leaves.
   * Clamped to 0 and above; NaN is an error and leaves the value.
   */
  virtual void SetLODPixelThreshold(double pixels);
  vtkGetMacro(LODPixelThreshold, double);
  ///@}

  ///@{
  /**
   * Shadow rays towards the lights (shaded surface mode only). Off by default.
   */
  vtkSetMacro(Shadows, bool);
  vtkGetMacro(Shadows, bool);
  vtkBooleanMacro(Shadows, bool);
  ///@}

  ///@{
  /**
   * Points without normals (no normals array, or image input with
   * ImageGradientNormals off): light them, and bend reflected and refracted
   * rays, by the normal of the plane fitted to the voxels within two voxels
   * of each one (made once per octree, at the first frame that shades it).
   * Off: by the occupancy of the six neighbouring voxels, which on a scanned
   * surface one voxel thick shows as speckle. On by default. Normals the
   * input has are always used.
   */
  vtkSetMacro(EstimateNormals, bool);
  vtkGetMacro(EstimateNormals, bool);
  vtkBooleanMacro(EstimateNormals, bool);
  ///@}

  ///@{
  /**
   * Reflections and refractions a ray may follow (surface mode). Default 2.
   */
  vtkSetClampMacro(MaximumBounces, int, 0, 8);
  vtkGetMacro(MaximumBounces, int);
  ///@}

  ///@{
  /**
   * Depth cue for unshaded surface rendering: the fraction of brightness
   * lost at the far side of the octree. 0 (the default) turns it off.
   * Clamped to 0..1; NaN is an error and leaves the value.
   */
  virtual void SetDepthCue(double fraction);
  vtkGetMacro(DepthCue, double);
  ///@}

  ///@{
  /**
   * Trace one ray per ImageSampleDistance x ImageSampleDistance pixels and
   * stretch the picture over the viewport. 1 (the default) traces every
   * pixel. Clamped to 1..32 and rounded to whole pixels when traced; NaN
   * is an error and leaves the value.
   */
  virtual void SetImageSampleDistance(double pixels);
  vtkGetMacro(ImageSampleDistance, double);
  ///@}

  ///@{
  /**
   * vtkImageData input: voxels whose value is at or below this become no
   * point: the value the transfer functions read (with several components,
   * the one the colour function's VectorMode and VectorComponent choose), or
   * with colours the largest component. Default 0. NaN is an error and
   * leaves the value.
   */
  virtual void SetImageBackground(double value);
  vtkGetMacro(ImageBackground, double);
  ///@}

  ///@{
  /**
   * vtkImageData input whose spacing differs between axes (a slice stack:
   * slices farther apart than pixels): fill the space between slices with
   * points interpolated linearly from the two neighbouring slices, so that
   * the points are no farther apart along the coarsest axis than along the
   * next (for a stack, the pixel spacing); ImageBackground applies to
   * the interpolated values. With LeafDepth 0 the leaves are then the pixel
   * size and the volume is closed. Off, the voxels alone become points and
   * the leaves are as large as the slice spacing (closed too, coarser).
   * The same rule as vtkSliceStackReader's FillBetweenSlices
   * (octorayLattice.h). Default on.
   */
  vtkSetMacro(FillBetweenSlices, bool);
  vtkGetMacro(FillBetweenSlices, bool);
  vtkBooleanMacro(FillBetweenSlices, bool);
  ///@}

  ///@{
  /**
   * vtkImageData input with one-component scalars: give each point the
   * normal of the scalar field, the negated gradient by central differences
   * (interpolated like the values between slices), as VTK's volume mappers
   * shade, so that shaded surfaces follow the tissue rather than the
   * voxels' faces. On by default; off, the octree's occupancy gives the
   * normals.
   */
  vtkSetMacro(ImageGradientNormals, bool);
  vtkGetMacro(ImageGradientNormals, bool);
  vtkBooleanMacro(ImageGradientNormals, bool);
  ///@}

  ///@{
  /**
   * Names of the optional per-point arrays read for reflectivity (0..1, the
   * weight of the mirror ray; values outside are clamped, and each is kept
   * to 1/65532) and index of refraction (0 = opaque).
   * Defaults: "Reflectivity" and "Refraction", as vtkParticleTextReader
   * names them; an input without them neither reflects nor refracts. Any
   * other name that names no point array of the input is said once for
   * the input, with the arrays it has.
   */
  vtkSetStringMacro(ReflectivityArrayName);
  vtkGetStringMacro(ReflectivityArrayName);
  vtkSetStringMacro(RefractionArrayName);
  vtkGetStringMacro(RefractionArrayName);
  ///@}

  ///@{
  /**
   * CUDA only: device bytes the engine may hold; past it, an allocation
   * fails as on a full GPU (and the mapper falls back to the CPU). 0 (the
   * default): no limit but the device's.
   */
  vtkSetMacro(CudaMemoryBudget, vtkIdType);
  vtkGetMacro(CudaMemoryBudget, vtkIdType);
  ///@}

  ///@{
  /**
   * Keep the engine's copy of the points after a build, so that an input
   * whose positions alone changed (a point set animated in place) is
   * updated rather than rebuilt, and (CUDA) the memory of a replaced octree
   * for the next build, which then allocates nothing. On by default. Off,
   * the engine holds only the octree's nodes, about a third of the memory
   * for a static scene, and moved points are rebuilt; it takes effect at
   * the next build.
   */
  vtkSetMacro(KeepPointsForUpdates, bool);
  vtkGetMacro(KeepPointsForUpdates, bool);
  vtkBooleanMacro(KeepPointsForUpdates, bool);
  ///@}

  ///@{
  /**
   * What the mapper did: full octree builds, in-place updates (only point
   * positions changed) and traced pictures. A render that changes nothing
   * redraws the last picture without tracing.
   */
  vtkGetMacro(NumberOfBuilds, vtkIdType);
  vtkGetMacro(NumberOfUpdates, vtkIdType);
  vtkGetMacro(NumberOfTraces, vtkIdType);
  ///@}

  ///@{
  /**
   * Seconds spent in the last build or update, the engine's last trace
   * (with its copy to the host, where it made one), and the VTK layer's
   * share of the last render: depth read-back, the picture's way into the
   * textures (upload or device copy) and the composite draw. Of the trace,
   * LastNormalEstimateSeconds: the normals it estimated (EstimateNormals; 0
   * where it made none, as every trace after an octree's first shaded one).
   */
  vtkGetMacro(LastBuildSeconds, double);
  vtkGetMacro(LastTraceSeconds, double);
  vtkGetMacro(LastNormalEstimateSeconds, double);
  vtkGetMacro(LastDepthReadSeconds, double);
  vtkGetMacro(LastUploadSeconds, double);
  vtkGetMacro(LastDrawSeconds, double);
  ///@}

  /**
   * The leaves of the octree built by the last render: one vertex per leaf
   * at its centre with its averaged colour as 8-bit RGBA ("Colors", the
   * active scalars) and, when the points carry scalars, their mean
   * ("Scalars"). Empty before the first render.
   */
  void GetLeafVoxels(vtkPolyData* output);

  /**
   * Side length of a leaf voxel in world coordinates (0 before the first
   * render).
   */
  double GetLeafSize();

  /**
   * The leaf level of the current octree: LeafDepth, or the level chosen
   * from the data when LeafDepth is 0 (0 before the first render).
   */
  int GetOctreeDepth();

  /**
   * Number of points the current octree holds.
   */
  vtkIdType GetNumberOfOctreePoints();

  ///@{
  /**
   * The input: a vtkPointSet (e.g. vtkPolyData) or a vtkImageData; any
   * other data set (vtkVolumeMapper's overload for a vtkRectilinearGrid
   * among them) is an error naming its type, and leaves no input.
   */
  void SetInputData(vtkDataSet* input) override;
  void SetInputData(vtkImageData* input) override;
  void SetInputData(vtkRectilinearGrid* input) override; // refused by name, as any other type
  ///@}

  void Render(vtkRenderer* ren, vtkVolume* vol) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkOctreeVolumeMapper();
  ~vtkOctreeVolumeMapper() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;

  int RequestedBackend = BACKEND_AUTO;
  int CudaDevice = -1;
  bool UseCudaGLInterop = true;
  int LeafDepth = 0;
  double LODPixelThreshold = 1.0;
  double RootBounds[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  bool Shadows = false;
  bool EstimateNormals = true;
  int MaximumBounces = 2;
  double DepthCue = 0.0;
  double ImageSampleDistance = 1.0;
  double ImageBackground = 0.0;
  bool FillBetweenSlices = true;
  bool ImageGradientNormals = true;
  char* ReflectivityArrayName = nullptr;
  char* RefractionArrayName = nullptr;
  vtkIdType CudaMemoryBudget = 0;
  bool KeepPointsForUpdates = true;

  vtkIdType NumberOfBuilds = 0;
  vtkIdType NumberOfUpdates = 0;
  vtkIdType NumberOfTraces = 0;
  double LastBuildSeconds = 0.0;
  double LastTraceSeconds = 0.0;
  double LastNormalEstimateSeconds = 0.0;
  double LastDepthReadSeconds = 0.0;
  double LastUploadSeconds = 0.0;
  double LastDrawSeconds = 0.0;

private:
  vtkOctreeVolumeMapper(const vtkOctreeVolumeMapper&) = delete;
  void operator=(const vtkOctreeVolumeMapper&) = delete;

  vtkDataSet* UpdatedInput();
  void SetNumber(const char* name, double value, double low, double high, double& member);

  // The engine, the input helper, the frame and the compositor; it does the
  // work of Render() (vtkOctreeVolumeMapper.cxx).
  class vtkInternals;
  vtkInternals* Internals;
};

#endif
