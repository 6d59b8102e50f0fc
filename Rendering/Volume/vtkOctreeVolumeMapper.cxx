#include "vtkOctreeVolumeMapper.h"

#include "vtkCPUOctreeVolumeMapper.h"
#include "vtkCamera.h"
#include "vtkCellArray.h"
#include "vtkColorTransferFunction.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkCudaOctreeVolumeMapper.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtk_glew.h"

#include <octoray/Engine.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace
{
double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// A float copy of one component of an array (the engine takes float
// attributes); a direct pointer when the array already is one contiguous
// float component.
const float* FloatComponent(vtkDataArray* array, int component, std::vector<float>& storage)
{
  if (array->GetNumberOfComponents() == 1 && component == 0)
  {
    if (auto* f = vtkFloatArray::FastDownCast(array))
    {
      return f->GetPointer(0);
    }
  }
  const vtkIdType n = array->GetNumberOfTuples();
  storage.resize(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    storage[i] = static_cast<float>(array->GetComponent(i, component));
  }
  return storage.data();
}

// The signature of an array as the octree used it: a change of contents
// (MTime) or of the array itself means a rebuild.
struct ArrayStamp
{
  const void* array = nullptr;
  vtkMTimeType mtime = 0;
  bool operator==(const ArrayStamp& o) const { return array == o.array && mtime == o.mtime; }
  bool operator!=(const ArrayStamp& o) const { return !(*this == o); }
};

ArrayStamp Stamp(vtkAbstractArray* a)
{
  ArrayStamp s;
  if (a)
  {
    s.array = a;
    s.mtime = a->GetMTime();
  }
  return s;
}
}

class vtkOctreeVolumeMapper::vtkInternals
{
public:
  std::unique_ptr<octoray::Engine> Engine;
  int EngineBackend = -1;   // BACKEND_CUDA or BACKEND_CPU; -1: none yet
  bool CudaFailed = false;  // a CUDA failure sent this mapper to the CPU for good
  bool Switched = false;    // set by Guarded when it just replaced CUDA by the CPU
  std::string Description;

  // What the current octree was built from.
  bool Built = false;
  const void* Input = nullptr;
  vtkMTimeType InputMTime = 0;
  vtkIdType Count = 0;
  ArrayStamp Points;
  std::vector<ArrayStamp> Arrays; // colours/scalars, reflectivity, refraction, normals
  std::string Layout;             // which arrays play which role
  int Depth = 0;
  std::array<double, 6> RootBounds{};
  int BuiltBackend = -1;
  vtkIdType BuildCounter = 0; // bumped by every build and update (the trace key)

  // Host copies the engine reads during a build (converted types, image voxels).
  std::vector<double> Xyz;
  std::vector<float> Scalar, Reflectivity, Refraction, Normal, ColorFloat;
  std::vector<std::uint8_t> Color8;
  bool HasScalar = false;
  double ScalarRange[2] = { 0, 1 };

  // The last picture and what it was traced from.
  octoray::Image Image;
  std::vector<double> TraceKey;
  std::vector<float> TraceDepth;
  bool Uploaded = false;

  // OpenGL resources.
  vtkSmartPointer<vtkTextureObject> ColorTexture;
  vtkSmartPointer<vtkTextureObject> DepthTexture;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  unsigned int ResolveFramebuffer = 0;
  unsigned int ResolveDepth = 0;
  int ResolveSize[2] = { 0, 0 };
  unsigned int ResolveFormat = 0;
  vtkOpenGLRenderWindow* Window = nullptr;

  void ForgetOctree()
  {
    this->Built = false;
    this->TraceKey.clear();
  }
};

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper* vtkOctreeVolumeMapper::New()
{
  // An object factory may replace the class (as for VTK's own mappers).
  if (vtkObject* ret = vtkObjectFactory::CreateInstance("vtkOctreeVolumeMapper"))
  {
    return static_cast<vtkOctreeVolumeMapper*>(ret);
  }
  if (vtkOctreeVolumeMapper::IsCudaAvailable())
  {
    return vtkCudaOctreeVolumeMapper::New();
  }
  return vtkCPUOctreeVolumeMapper::New();
}

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper::vtkOctreeVolumeMapper()
  : Internals(new vtkInternals)
{
  // Point clouds are surfaces more often than clouds of density: first hit.
  this->BlendMode = SURFACE_BLEND;
  this->SetReflectivityArrayName("Reflectivity");
  this->SetRefractionArrayName("Refraction");
}

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper::~vtkOctreeVolumeMapper()
{
  this->ReleaseGraphicsResources(this->Internals->Window);
  this->SetReflectivityArrayName(nullptr);
  this->SetRefractionArrayName(nullptr);
  delete this->Internals;
}

//------------------------------------------------------------------------------
bool vtkOctreeVolumeMapper::IsCudaAvailable()
{
  return octoray::CudaAvailable(nullptr);
}

//------------------------------------------------------------------------------
int vtkOctreeVolumeMapper::GetLastUsedBackend()
{
  return this->Internals->Built ? this->Internals->EngineBackend : -1;
}

const char* vtkOctreeVolumeMapper::GetLastUsedBackendName()
{
  switch (this->GetLastUsedBackend())
  {
    case BACKEND_CUDA:
      return "CUDA";
    case BACKEND_CPU:
      return "CPU";
    default:
      return "none";
  }
}

const char* vtkOctreeVolumeMapper::GetBackendDescription()
{
  return this->Internals->Description.c_str();
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::SetInputData(vtkDataSet* input)
{
  if (input && !vtkPointSet::SafeDownCast(input) && !vtkImageData::SafeDownCast(input))
  {
    vtkErrorMacro("The input must be a vtkPointSet or a vtkImageData, not a " << input->GetClassName());
    return;
  }
  this->SetInputDataInternal(0, input);
}

//------------------------------------------------------------------------------
int vtkOctreeVolumeMapper::FillInputPortInformation(int port, vtkInformation* info)
{
  (void)port;
  // vtkPointSet (points with attributes) and vtkImageData (voxels above the
  // background become points); vtkVolumeMapper itself asks for images only.
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
namespace
{
// Creates the engine of `backend`; false (with `why`) when it cannot be had.
bool MakeEngine(int backend, std::unique_ptr<octoray::Engine>& engine, std::string& why)
{
  try
  {
    engine = octoray::CreateEngine(
      backend == vtkOctreeVolumeMapper::BACKEND_CUDA ? octoray::Backend::CUDA : octoray::Backend::CPU);
    return true;
  }
  catch (const std::exception& e)
  {
    why = e.what();
    return false;
  }
}
}

//------------------------------------------------------------------------------
// Picks and creates the engine for the requested backend. CUDA that cannot be
// had falls back to the CPU: silently for AUTO, with a warning for CUDA.
static bool EnsureEngine(vtkOctreeVolumeMapper* self, int requested,
  std::unique_ptr<octoray::Engine>& engine, int& backend, bool cudaFailed, std::string& description,
  std::string& warning, std::string& error)
{
  int wanted = requested;
  if (requested == vtkOctreeVolumeMapper::BACKEND_AUTO)
  {
    wanted = (!cudaFailed && vtkOctreeVolumeMapper::IsCudaAvailable())
      ? vtkOctreeVolumeMapper::BACKEND_CUDA
      : vtkOctreeVolumeMapper::BACKEND_CPU;
  }
  else if (requested == vtkOctreeVolumeMapper::BACKEND_CUDA && cudaFailed)
  {
    wanted = vtkOctreeVolumeMapper::BACKEND_CPU;
  }
  if (engine && backend == wanted)
  {
    return true;
  }
  (void)self;
  std::string why;
  if (MakeEngine(wanted, engine, why))
  {
    backend = wanted;
    description = engine->Description();
    return true;
  }
  if (wanted == vtkOctreeVolumeMapper::BACKEND_CUDA)
  {
    warning = "the CUDA backend is not available (" + why + "); using the CPU backend";
    if (MakeEngine(vtkOctreeVolumeMapper::BACKEND_CPU, engine, why))
    {
      backend = vtkOctreeVolumeMapper::BACKEND_CPU;
      description = engine->Description();
      return true;
    }
  }
  error = "cannot create the octree engine: " + why;
  engine.reset();
  backend = -1;
  return false;
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  vtkInternals& in = *this->Internals;
  vtkDataSet* input = this->GetInput();
  if (!input)
  {
    vtkErrorMacro("No input.");
    return;
  }
  auto* window = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!window)
  {
    vtkErrorMacro("vtkOctreeVolumeMapper draws only into OpenGL render windows.");
    return;
  }
  // Bring the input up to date (a pipeline connection).
  if (this->GetInputAlgorithm())
  {
    this->GetInputAlgorithm()->Update();
    input = this->GetInput();
  }
  if (!input || input->GetNumberOfPoints() == 0)
  {
    return; // nothing to draw is not an error
  }
  vtkVolumeProperty* property = vol->GetProperty();

  // ---- The engine: backend choice and CUDA fallback.
  {
    std::string warning, error;
    const int before = in.EngineBackend;
    if (!EnsureEngine(this, this->RequestedBackend, in.Engine, in.EngineBackend, in.CudaFailed,
          in.Description, warning, error))
    {
      vtkErrorMacro(<< error);
      return;
    }
    if (!warning.empty())
    {
      in.CudaFailed = true; // say it once
      vtkWarningMacro(<< warning);
    }
    if (before != in.EngineBackend)
    {
      in.ForgetOctree();
    }
    if (in.EngineBackend == BACKEND_CUDA && this->CudaMemoryBudget > 0)
    {
      in.Engine->SetMemoryBudget(static_cast<std::size_t>(this->CudaMemoryBudget));
    }
  }

  // ---- The octree: build, update, or nothing. A CUDA failure switches
  // to the CPU backend; the octree is then built again there.
  in.Switched = false;
  int status = this->PrepareOctree(input, property);
  if (status < 0 && in.Switched)
  {
    in.Switched = false;
    status = this->PrepareOctree(input, property);
  }
  if (status < 0 || !in.Built)
  {
    return;
  }

  // ---- The frame.
  int width = 0, height = 0, x0 = 0, y0 = 0;
  ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  if (width <= 0 || height <= 0)
  {
    return;
  }
  const double aspect = ren->GetTiledAspectRatio();
  vtkCamera* camera = ren->GetActiveCamera();
  // NDC <- data: VTK's composite projection (row-major, world -> NDC) times
  // the volume's matrix; the engine wants its inverse.
  vtkNew<vtkMatrix4x4> ndcFromData;
  vtkMatrix4x4::Multiply4x4(
    camera->GetCompositeProjectionTransformMatrix(aspect, -1, 1), vol->GetMatrix(), ndcFromData);
  vtkNew<vtkMatrix4x4> dataFromNdc;
  vtkMatrix4x4::Invert(ndcFromData, dataFromNdc);
  vtkNew<vtkMatrix4x4> dataFromWorld;
  vtkMatrix4x4::Invert(vol->GetMatrix(), dataFromWorld);

  double t0 = Now();
  std::vector<float> depth;
  this->ReadDepth(window, x0, y0, width, height, depth);
  this->LastDepthReadSeconds = Now() - t0;

  octoray::RenderSettings s;
  const int step = std::max(1, static_cast<int>(std::lround(this->ImageSampleDistance)));
  s.width = (width + step - 1) / step;
  s.height = (height + step - 1) / step;
  if (step == 1)
  {
    s.depthBuffer = depth;
  }
  else
  {
    // The depth at each traced pixel's centre sample.
    s.depthBuffer.resize(static_cast<std::size_t>(s.width) * s.height);
    for (int y = 0; y < s.height; ++y)
    {
      const int sy = std::min(height - 1, y * step + step / 2);
      for (int x = 0; x < s.width; ++x)
      {
        const int sx = std::min(width - 1, x * step + step / 2);
        s.depthBuffer[static_cast<std::size_t>(y) * s.width + x] =
          depth[static_cast<std::size_t>(sy) * width + sx];
      }
    }
  }
  for (int i = 0; i < 16; ++i)
  {
    s.inverseViewProjection[i] = dataFromNdc->GetElement(i / 4, i % 4);
  }

  switch (this->BlendMode)
  {
    case vtkVolumeMapper::COMPOSITE_BLEND:
      s.blend = octoray::BlendMode::Composite;
      break;
    case vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND:
      s.blend = octoray::BlendMode::Maximum;
      break;
    case vtkVolumeMapper::MINIMUM_INTENSITY_BLEND:
      s.blend = octoray::BlendMode::Minimum;
      break;
    case vtkVolumeMapper::AVERAGE_INTENSITY_BLEND:
      s.blend = octoray::BlendMode::Average;
      break;
    case vtkVolumeMapper::ADDITIVE_BLEND:
      s.blend = octoray::BlendMode::Additive;
      break;
    default: // SURFACE_BLEND, and the nearest to an iso-surface
      s.blend = octoray::BlendMode::Surface;
      break;
  }
  if (property->GetShade(0))
  {
    s.shade = octoray::ShadeMode::Phong;
  }
  else if (this->DepthCue > 0.0)
  {
    s.shade = octoray::ShadeMode::DepthCue;
  }
  else
  {
    s.shade = octoray::ShadeMode::Flat;
  }
  s.ambient = static_cast<float>(property->GetAmbient(0));
  s.diffuse = static_cast<float>(property->GetDiffuse(0));
  s.specular = static_cast<float>(property->GetSpecular(0));
  s.specularPower = static_cast<float>(property->GetSpecularPower(0));
  s.depthCue = static_cast<float>(this->DepthCue);
  s.shadows = this->Shadows;
  s.maxBounces = this->MaximumBounces;
  s.lodPixels = static_cast<float>(this->LODPixelThreshold);
  s.opacityUnitDistance = static_cast<float>(property->GetScalarOpacityUnitDistance(0));

  // Lights: the renderer's switched-on lights, in data coordinates. Camera
  // lights and the headlight carry the camera's transform, which
  // GetTransformedPosition applies.
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  bool anyLight = false;
  while (vtkLight* light = lights->GetNextLight(it))
  {
    if (!light->GetSwitch())
    {
      continue;
    }
    anyLight = true;
    if (s.lights.size() == 8)
    {
      vtkWarningMacro("The octree engine takes at most 8 lights; the others are ignored.");
      break;
    }
    double p[4], f[4];
    light->GetTransformedPosition(p);
    light->GetTransformedFocalPoint(f);
    p[3] = f[3] = 1.0;
    double pd[4], fd[4];
    dataFromWorld->MultiplyPoint(p, pd);
    dataFromWorld->MultiplyPoint(f, fd);
    octoray::Light l;
    if (light->GetPositional())
    {
      for (int a = 0; a < 3; ++a)
      {
        l.position[a] = pd[a] / pd[3];
      }
      l.position[3] = 1.0;
    }
    else
    {
      for (int a = 0; a < 3; ++a)
      {
        l.position[a] = pd[a] / pd[3] - fd[a] / fd[3]; // towards the light
      }
      l.position[3] = 0.0;
    }
    double c[3];
    light->GetDiffuseColor(c);
    for (int a = 0; a < 3; ++a)
    {
      l.color[a] = static_cast<float>(c[a]);
    }
    l.intensity = static_cast<float>(light->GetIntensity());
    s.lights.push_back(l);
  }
  if (!anyLight)
  {
    // Every light off: VTK leaves ambient light only; the engine would
    // otherwise add its own headlight.
    octoray::Light dark;
    dark.intensity = 0.0f;
    s.lights.push_back(dark);
  }

  // Transfer function on the scalars (unless the points carry colours).
  if (in.HasScalar)
  {
    double range[2] = { in.ScalarRange[0], in.ScalarRange[1] };
    if (!(range[1] > range[0]))
    {
      range[0] -= 0.5;
      range[1] += 0.5;
    }
    s.transfer.range[0] = static_cast<float>(range[0]);
    s.transfer.range[1] = static_cast<float>(range[1]);
    const int n = 1024;
    std::vector<double> rgb(3 * n);
    std::vector<double> alpha(n);
    if (property->GetColorChannels(0) == 1)
    {
      std::vector<double> grey(n);
      property->GetGrayTransferFunction(0)->GetTable(range[0], range[1], n, grey.data());
      for (int i = 0; i < n; ++i)
      {
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = grey[i];
      }
    }
    else
    {
      property->GetRGBTransferFunction(0)->GetTable(range[0], range[1], n, rgb.data());
    }
    property->GetScalarOpacity(0)->GetTable(range[0], range[1], n, alpha.data());
    s.transfer.table.resize(n);
    for (int i = 0; i < n; ++i)
    {
      s.transfer.table[i] = octoray::Rgba{ static_cast<float>(rgb[3 * i]),
        static_cast<float>(rgb[3 * i + 1]), static_cast<float>(rgb[3 * i + 2]),
        static_cast<float>(alpha[i]) };
    }
  }

  // ---- Trace only when something that shapes the picture changed.
  std::vector<double> key;
  key.reserve(64 + 8 * s.lights.size());
  key.insert(key.end(), s.inverseViewProjection, s.inverseViewProjection + 16);
  key.push_back(s.width);
  key.push_back(s.height);
  key.push_back(static_cast<double>(this->GetMTime()));
  key.push_back(static_cast<double>(property->GetMTime()));
  key.push_back(static_cast<double>(in.BuildCounter));
  key.push_back(static_cast<double>(in.EngineBackend));
  for (const octoray::Light& l : s.lights)
  {
    key.insert(key.end(), l.position, l.position + 4);
    key.insert(key.end(), l.color, l.color + 3);
    key.push_back(l.intensity);
  }
  const bool retrace = key != in.TraceKey || s.depthBuffer != in.TraceDepth || !in.Uploaded;
  if (retrace)
  {
    in.TraceKey.clear();
    auto trace = [&] {
      s.copyToHost = true;
      const octoray::RenderStats stats = in.Engine->Render(s, in.Image);
      this->LastTraceSeconds = stats.seconds + stats.copySeconds;
    };
    in.Switched = false;
    bool ok = this->Guarded("render", trace);
    if (!ok && in.Switched)
    {
      // The CUDA engine failed and the CPU one replaced it: build there and
      // trace again.
      in.Switched = false;
      if (this->PrepareOctree(input, property) < 0 || !in.Built)
      {
        return;
      }
      key[16 + 4] = static_cast<double>(in.BuildCounter);
      key[16 + 5] = static_cast<double>(in.EngineBackend);
      ok = this->Guarded("render", trace);
    }
    if (!ok)
    {
      return;
    }
    ++this->NumberOfTraces;
    in.TraceKey = std::move(key);
    in.TraceDepth = std::move(s.depthBuffer);
    in.Uploaded = false;
  }
  this->Draw(ren, window);
}

//------------------------------------------------------------------------------
// Every engine call goes through here: a CUDA failure (out of memory, a lost
// device) replaces the engine by a CPU one with a warning and returns false
// with Switched set (the caller builds again); a CPU failure is an error.
bool vtkOctreeVolumeMapper::Guarded(const char* what, const std::function<void()>& call)
{
  vtkInternals& in = *this->Internals;
  try
  {
    call();
    return true;
  }
  catch (const std::exception& e)
  {
    if (in.EngineBackend != BACKEND_CUDA)
    {
      vtkErrorMacro(<< "octree " << what << " failed: " << e.what());
      return false;
    }
    vtkWarningMacro(<< "CUDA " << what << " failed (" << e.what() << "); falling back to the CPU backend");
    in.CudaFailed = true;
    in.ForgetOctree();
    std::string why;
    if (!MakeEngine(BACKEND_CPU, in.Engine, why))
    {
      vtkErrorMacro(<< "cannot create the CPU engine: " << why);
      in.EngineBackend = -1;
      return false;
    }
    in.EngineBackend = BACKEND_CPU;
    in.Description = in.Engine->Description();
    in.Switched = true;
    return false;
  }
}

//------------------------------------------------------------------------------
// Builds, updates or keeps the octree. Returns 1 when it changed, 0 when it
// was up to date, -1 on failure.
int vtkOctreeVolumeMapper::PrepareOctree(vtkDataSet* input, vtkVolumeProperty* property)
{
  vtkInternals& in = *this->Internals;
  const double start = Now();
  auto* pointSet = vtkPointSet::SafeDownCast(input);
  auto* image = vtkImageData::SafeDownCast(input);
  if (!pointSet && !image)
  {
    vtkErrorMacro("The input must be a vtkPointSet or a vtkImageData, not a " << input->GetClassName());
    return -1;
  }

  // The active scalars as the volume property reads them: colours when they
  // have 3 or 4 components and the components are not independent, else
  // component 0 through the transfer functions.
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(input, this->ScalarMode, this->ArrayAccessMode,
    this->ArrayId, this->ArrayName, cellFlag);
  if (scalars && cellFlag)
  {
    vtkWarningMacro("Cell scalars are not supported; the points are drawn without them.");
    scalars = nullptr;
  }
  const bool colours = scalars && !property->GetIndependentComponents() &&
    (scalars->GetNumberOfComponents() == 3 || scalars->GetNumberOfComponents() == 4);
  vtkDataArray* reflectivity = nullptr;
  vtkDataArray* refraction = nullptr;
  vtkDataArray* normals = nullptr;
  if (pointSet)
  {
    vtkPointData* pd = input->GetPointData();
    reflectivity = this->ReflectivityArrayName ? pd->GetArray(this->ReflectivityArrayName) : nullptr;
    refraction = this->RefractionArrayName ? pd->GetArray(this->RefractionArrayName) : nullptr;
    normals = pd->GetNormals();
    if (normals && normals->GetNumberOfComponents() != 3)
    {
      normals = nullptr;
    }
  }
  std::string layout = std::string(colours ? "colours" : (scalars ? "scalars" : "plain")) +
    (reflectivity ? "+reflectivity" : "") + (refraction ? "+refraction" : "") + (normals ? "+normals" : "");
  if (image)
  {
    layout += "+image:" + std::to_string(this->ImageBackground);
  }
  std::vector<ArrayStamp> arrays = { Stamp(scalars), Stamp(reflectivity), Stamp(refraction),
    Stamp(normals) };
  const ArrayStamp points = pointSet ? Stamp(pointSet->GetPoints() ? pointSet->GetPoints()->GetData() : nullptr)
                                     : ArrayStamp{ input, input->GetMTime() };
  const vtkIdType count = input->GetNumberOfPoints();
  std::array<double, 6> rootBounds;
  std::copy(this->RootBounds, this->RootBounds + 6, rootBounds.begin());

  const bool sameArrays = in.Built && in.Input == input && in.Count == count &&
    in.Layout == layout && in.Arrays == arrays && in.Depth == this->LeafDepth &&
    in.RootBounds == rootBounds && in.BuiltBackend == in.EngineBackend;
  if (sameArrays && in.Points == points)
  {
    return 0;
  }

  // Only the positions moved (a point set animated in place): update.
  if (sameArrays && pointSet && in.Points.array == points.array)
  {
    vtkDataArray* xyz = pointSet->GetPoints()->GetData();
    octoray::PositionsView moved;
    moved.count = static_cast<std::size_t>(count);
    std::vector<double> copy;
    if (auto* f = vtkFloatArray::FastDownCast(xyz))
    {
      moved.xyzFloat = f->GetPointer(0);
    }
    else if (auto* d = vtkDoubleArray::FastDownCast(xyz))
    {
      moved.xyzDouble = d->GetPointer(0);
    }
    else
    {
      copy.resize(3 * static_cast<std::size_t>(count));
      for (vtkIdType i = 0; i < count; ++i)
      {
        xyz->GetTuple(i, &copy[3 * i]);
      }
      moved.xyzDouble = copy.data();
    }
    if (this->Guarded("update", [&] { in.Engine->Update(moved); }))
    {
      in.Points = points;
      ++in.BuildCounter;
      ++this->NumberOfUpdates;
      this->LastBuildSeconds = Now() - start;
      return 1;
    }
    if (in.EngineBackend != BACKEND_CPU || in.Built)
    {
      return -1;
    }
    // The engine was replaced: fall through to a full build on the CPU.
  }

  this->UpdateProgress(0.0);
  octoray::PointCloudView view;
  in.HasScalar = false;
  in.Xyz.clear();
  in.Scalar.clear();
  in.Color8.clear();
  in.ColorFloat.clear();
  if (image)
  {
    // Every voxel above the background is a point at the voxel's position,
    // with its value as scalar (or its components as colour).
    const int comps = scalars ? scalars->GetNumberOfComponents() : 0;
    const vtkIdType n = image->GetNumberOfPoints();
    for (vtkIdType i = 0; i < n; ++i)
    {
      double value = 0.0;
      if (scalars)
      {
        value = scalars->GetComponent(i, 0);
        for (int c = 1; c < comps; ++c)
        {
          value = std::max(value, scalars->GetComponent(i, c));
        }
      }
      else
      {
        value = 1.0; // no scalars: the whole grid
      }
      if (!(value > this->ImageBackground))
      {
        continue;
      }
      double p[3];
      image->GetPoint(i, p);
      in.Xyz.insert(in.Xyz.end(), p, p + 3);
      if (colours)
      {
        for (int c = 0; c < 4; ++c)
        {
          double v = c < comps ? scalars->GetComponent(i, c) : 255.0;
          if (!vtkUnsignedCharArray::SafeDownCast(scalars))
          {
            in.ColorFloat.push_back(static_cast<float>(c < comps ? v : 1.0));
          }
          else
          {
            in.Color8.push_back(static_cast<std::uint8_t>(v));
          }
        }
      }
      else if (scalars)
      {
        in.Scalar.push_back(static_cast<float>(scalars->GetComponent(i, 0)));
      }
      if (i % 65536 == 0)
      {
        this->UpdateProgress(0.5 * static_cast<double>(i) / n);
      }
    }
    if (in.Xyz.empty())
    {
      vtkWarningMacro("Every voxel of the image is at or below the background " << this->ImageBackground
                                                                              << "; nothing to draw.");
      in.ForgetOctree();
      return -1;
    }
    view.count = in.Xyz.size() / 3;
    view.xyzDouble = in.Xyz.data();
    if (!in.Color8.empty())
    {
      view.color8 = in.Color8.data();
      view.colorComponents = 4;
    }
    else if (!in.ColorFloat.empty())
    {
      view.colorFloat = in.ColorFloat.data();
      view.colorComponents = 4;
    }
    else if (!in.Scalar.empty())
    {
      view.scalar = in.Scalar.data();
    }
  }
  else
  {
    if (!pointSet->GetPoints())
    {
      return -1;
    }
    vtkDataArray* xyz = pointSet->GetPoints()->GetData();
    view.count = static_cast<std::size_t>(count);
    if (auto* f = vtkFloatArray::FastDownCast(xyz))
    {
      view.xyzFloat = f->GetPointer(0);
    }
    else if (auto* d = vtkDoubleArray::FastDownCast(xyz))
    {
      view.xyzDouble = d->GetPointer(0);
    }
    else
    {
      in.Xyz.resize(3 * static_cast<std::size_t>(count));
      for (vtkIdType i = 0; i < count; ++i)
      {
        xyz->GetTuple(i, &in.Xyz[3 * i]);
      }
      view.xyzDouble = in.Xyz.data();
    }
    if (colours)
    {
      const int comps = scalars->GetNumberOfComponents();
      view.colorComponents = comps;
      if (auto* uc = vtkUnsignedCharArray::FastDownCast(scalars))
      {
        view.color8 = uc->GetPointer(0);
      }
      else
      {
        // Float or double colours are taken as 0..1 (HDR allowed).
        in.ColorFloat.resize(static_cast<std::size_t>(count) * comps);
        for (vtkIdType i = 0; i < count; ++i)
        {
          for (int c = 0; c < comps; ++c)
          {
            in.ColorFloat[i * comps + c] = static_cast<float>(scalars->GetComponent(i, c));
          }
        }
        view.colorFloat = in.ColorFloat.data();
      }
    }
    else if (scalars)
    {
      view.scalar = FloatComponent(scalars, 0, in.Scalar);
    }
    if (reflectivity)
    {
      view.reflectivity = FloatComponent(reflectivity, 0, in.Reflectivity);
    }
    if (refraction)
    {
      view.refraction = FloatComponent(refraction, 0, in.Refraction);
    }
    if (normals)
    {
      if (auto* f = vtkFloatArray::FastDownCast(normals))
      {
        view.normal = f->GetPointer(0);
      }
      else
      {
        in.Normal.resize(3 * static_cast<std::size_t>(count));
        for (vtkIdType i = 0; i < count; ++i)
        {
          for (int c = 0; c < 3; ++c)
          {
            in.Normal[3 * i + c] = static_cast<float>(normals->GetComponent(i, c));
          }
        }
        view.normal = in.Normal.data();
      }
    }
  }
  if (view.scalar)
  {
    float lo = view.scalar[0], hi = view.scalar[0];
    for (std::size_t i = 1; i < view.count; ++i)
    {
      lo = std::min(lo, view.scalar[i]);
      hi = std::max(hi, view.scalar[i]);
    }
    in.HasScalar = true;
    in.ScalarRange[0] = lo;
    in.ScalarRange[1] = hi;
  }
  this->UpdateProgress(0.5);

  octoray::BuildOptions options;
  options.depth = this->LeafDepth;
  if (vtkMath::AreBoundsInitialized(this->RootBounds))
  {
    // The caller's cube (e.g. global bounds over parallel ranks): the same
    // voxel grid on every rank.
    const double lo[3] = { this->RootBounds[0], this->RootBounds[2], this->RootBounds[4] };
    const double hi[3] = { this->RootBounds[1], this->RootBounds[3], this->RootBounds[5] };
    options.fixedCube = true;
    options.cube = octoray::RootCube::FromBounds(lo, hi);
  }
  in.Built = false;
  if (!this->Guarded("build", [&] { in.Engine->Build(view, options); }))
  {
    return -1;
  }
  in.Built = true;
  in.Input = input;
  in.InputMTime = input->GetMTime();
  in.Count = count;
  in.Points = points;
  in.Arrays = arrays;
  in.Layout = layout;
  in.Depth = this->LeafDepth;
  in.RootBounds = rootBounds;
  in.BuiltBackend = in.EngineBackend;
  ++in.BuildCounter;
  ++this->NumberOfBuilds;
  this->LastBuildSeconds = Now() - start;
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
// Reads the window depth of the viewport from the framebuffer VTK is drawing
// into. A multisampled framebuffer cannot be read directly: its depth is
// first resolved into a single-sampled one of the same format.
void vtkOctreeVolumeMapper::ReadDepth(
  vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, std::vector<float>& depth)
{
  vtkInternals& in = *this->Internals;
  vtkOpenGLState* state = window->GetState();
  depth.assign(static_cast<std::size_t>(width) * height, 1.0f);

  GLint drawFramebuffer = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFramebuffer);
  GLint samples = 0;
  glGetIntegerv(GL_SAMPLES, &samples);

  state->PushReadFramebufferBinding();
  if (samples <= 0)
  {
    state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<unsigned int>(drawFramebuffer));
  }
  else
  {
    // The depth format of the source: blits between depth buffers need the
    // same format.
    const GLenum attachment = drawFramebuffer == 0 ? GL_DEPTH : GL_DEPTH_ATTACHMENT;
    GLint bits = 24, type = GL_UNSIGNED_NORMALIZED, stencil = 0;
    glGetFramebufferAttachmentParameteriv(
      GL_DRAW_FRAMEBUFFER, attachment, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &bits);
    glGetFramebufferAttachmentParameteriv(
      GL_DRAW_FRAMEBUFFER, attachment, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &type);
    glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER,
      drawFramebuffer == 0 ? GL_STENCIL : GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE,
      &stencil);
    GLenum format = GL_DEPTH_COMPONENT24;
    if (type == GL_FLOAT)
    {
      format = stencil > 0 ? GL_DEPTH32F_STENCIL8 : GL_DEPTH_COMPONENT32F;
    }
    else if (bits == 16)
    {
      format = GL_DEPTH_COMPONENT16;
    }
    else if (bits == 32)
    {
      format = GL_DEPTH_COMPONENT32;
    }
    else if (stencil > 0)
    {
      format = GL_DEPTH24_STENCIL8;
    }
    if (!in.ResolveFramebuffer || in.ResolveSize[0] != width || in.ResolveSize[1] != height ||
      in.ResolveFormat != format)
    {
      if (!in.ResolveFramebuffer)
      {
        glGenFramebuffers(1, &in.ResolveFramebuffer);
        glGenRenderbuffers(1, &in.ResolveDepth);
      }
      glBindRenderbuffer(GL_RENDERBUFFER, in.ResolveDepth);
      glRenderbufferStorage(GL_RENDERBUFFER, format, width, height);
      glBindRenderbuffer(GL_RENDERBUFFER, 0);
      state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, in.ResolveFramebuffer);
      glFramebufferRenderbuffer(GL_READ_FRAMEBUFFER,
        (format == GL_DEPTH24_STENCIL8 || format == GL_DEPTH32F_STENCIL8) ? GL_DEPTH_STENCIL_ATTACHMENT
                                                                          : GL_DEPTH_ATTACHMENT,
        GL_RENDERBUFFER, in.ResolveDepth);
      in.ResolveSize[0] = width;
      in.ResolveSize[1] = height;
      in.ResolveFormat = format;
    }
    // Draw binding -> our framebuffer (as the draw target of the blit).
    state->PushDrawFramebufferBinding();
    state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<unsigned int>(drawFramebuffer));
    state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, in.ResolveFramebuffer);
    glBlitFramebuffer(
      x0, y0, x0 + width, y0 + height, 0, 0, width, height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    state->PopDrawFramebufferBinding();
    state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, in.ResolveFramebuffer);
    x0 = y0 = 0;
  }
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(x0, y0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
  state->PopReadFramebufferBinding();
  if (glGetError() != GL_NO_ERROR)
  {
    vtkWarningMacro("Could not read the depth of the opaque geometry; the octree is drawn without it.");
    std::fill(depth.begin(), depth.end(), 1.0f);
  }
}

//------------------------------------------------------------------------------
// Draws the last picture over the viewport: premultiplied colour blended
// over what is there, and the engine's window depth as the fragment depth.
void vtkOctreeVolumeMapper::Draw(vtkRenderer* ren, vtkOpenGLRenderWindow* window)
{
  vtkInternals& in = *this->Internals;
  (void)ren;
  if (in.Window != window)
  {
    this->ReleaseGraphicsResources(in.Window);
    in.Window = window;
  }
  double t0 = Now();
  if (!in.ColorTexture)
  {
    in.ColorTexture = vtkSmartPointer<vtkTextureObject>::New();
    in.DepthTexture = vtkSmartPointer<vtkTextureObject>::New();
    in.ColorTexture->SetContext(window);
    in.DepthTexture->SetContext(window);
    in.Uploaded = false;
  }
  if (!in.Uploaded)
  {
    const int w = in.Image.width, h = in.Image.height;
    // Full float: the window depth must survive to 1e-4 and better.
    in.ColorTexture->Create2DFromRaw(w, h, 4, VTK_FLOAT, in.Image.rgba.data());
    in.DepthTexture->Create2DFromRaw(w, h, 1, VTK_FLOAT, in.Image.depth.data());
    for (vtkTextureObject* t : { in.ColorTexture.Get(), in.DepthTexture.Get() })
    {
      t->SetMinificationFilter(vtkTextureObject::Nearest);
      t->SetMagnificationFilter(vtkTextureObject::Nearest);
      t->SetWrapS(vtkTextureObject::ClampToEdge);
      t->SetWrapT(vtkTextureObject::ClampToEdge);
    }
    in.Uploaded = true;
  }
  this->LastUploadSeconds = Now() - t0;
  t0 = Now();

  if (!in.Quad)
  {
    std::string fs = vtkOpenGLRenderUtilities::GetFullScreenQuadFragmentShaderTemplate();
    vtkShaderProgram::Substitute(fs, "//VTK::FSQ::Decl",
      "uniform sampler2D octorayColor;\n"
      "uniform sampler2D octorayDepth;\n");
    // Pixels no ray coloured leave colour and depth as they were.
    vtkShaderProgram::Substitute(fs, "//VTK::FSQ::Impl",
      "  vec4 c = texture(octorayColor, texCoord);\n"
      "  if (c.a <= 0.0) { discard; }\n"
      "  gl_FragData[0] = c;\n"
      "  gl_FragDepth = texture(octorayDepth, texCoord).r;\n");
    in.Quad.reset(new vtkOpenGLQuadHelper(window, nullptr, fs.c_str(), nullptr));
  }
  else
  {
    window->GetShaderCache()->ReadyShaderProgram(in.Quad->Program);
  }
  if (!in.Quad->Program)
  {
    vtkErrorMacro("Could not compile the composite shader.");
    return;
  }
  vtkOpenGLState* state = window->GetState();
  vtkOpenGLState::ScopedglEnableDisable depthTest(state, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable blend(state, GL_BLEND);
  vtkOpenGLState::ScopedglDepthFunc depthFunc(state);
  vtkOpenGLState::ScopedglDepthMask depthMask(state);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFunc(state);
  // The rays already stopped at the opaque depth, so every fragment is in
  // front of what is drawn: the depth test only serves to write the depth.
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_ALWAYS);
  state->vtkglDepthMask(GL_TRUE);
  state->vtkglEnable(GL_BLEND);
  state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  in.ColorTexture->Activate();
  in.DepthTexture->Activate();
  in.Quad->Program->SetUniformi("octorayColor", in.ColorTexture->GetTextureUnit());
  in.Quad->Program->SetUniformi("octorayDepth", in.DepthTexture->GetTextureUnit());
  in.Quad->Render();
  in.DepthTexture->Deactivate();
  in.ColorTexture->Deactivate();
  this->LastDrawSeconds = Now() - t0;
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  vtkInternals& in = *this->Internals;
  if (in.ColorTexture)
  {
    in.ColorTexture->ReleaseGraphicsResources(window);
    in.DepthTexture->ReleaseGraphicsResources(window);
  }
  in.ColorTexture = nullptr;
  in.DepthTexture = nullptr;
  if (in.Quad)
  {
    in.Quad->ReleaseGraphicsResources(window);
    in.Quad.reset();
  }
  if (in.ResolveFramebuffer && window)
  {
    if (auto* w = vtkOpenGLRenderWindow::SafeDownCast(window))
    {
      w->MakeCurrent();
      glDeleteFramebuffers(1, &in.ResolveFramebuffer);
      glDeleteRenderbuffers(1, &in.ResolveDepth);
    }
  }
  in.ResolveFramebuffer = in.ResolveDepth = 0;
  in.ResolveSize[0] = in.ResolveSize[1] = 0;
  in.Uploaded = false;
  in.Window = nullptr;
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::GetLeafVoxels(vtkPolyData* output)
{
  vtkInternals& in = *this->Internals;
  output->Initialize();
  if (!in.Built || !in.Engine)
  {
    return;
  }
  octoray::HostOctree tree;
  in.Engine->CopyToHost(tree);
  const int depth = tree.depth;
  const std::uint32_t begin = tree.levelBegin[depth], end = tree.levelBegin[depth + 1];
  const double leaf = tree.cube.size / static_cast<double>(1u << depth);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(end - begin);
  vtkNew<vtkUnsignedCharArray> colors;
  colors->SetName("Colors");
  colors->SetNumberOfComponents(4);
  colors->SetNumberOfTuples(end - begin);
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName("Scalars");
  scalars->SetNumberOfTuples(tree.scalar.empty() ? 0 : end - begin);
  vtkNew<vtkCellArray> verts;
  for (std::uint32_t node = begin; node < end; ++node)
  {
    std::uint32_t x, y, z;
    octoray::DecodeMorton(tree.key[node], x, y, z);
    const double p[3] = { tree.cube.origin[0] + (x + 0.5) * leaf, tree.cube.origin[1] + (y + 0.5) * leaf,
      tree.cube.origin[2] + (z + 0.5) * leaf };
    const vtkIdType id = node - begin;
    points->SetPoint(id, p);
    const octoray::Rgba c = tree.color.empty() ? octoray::Rgba{ 1, 1, 1, 1 } : tree.color[node];
    const float rgba[4] = { c.r, c.g, c.b, c.a };
    for (int k = 0; k < 4; ++k)
    {
      const float v = std::min(1.0f, std::max(0.0f, rgba[k]));
      colors->SetTypedComponent(id, k, static_cast<unsigned char>(std::lround(v * 255.0f)));
    }
    if (!tree.scalar.empty())
    {
      scalars->SetValue(id, tree.scalar[node]);
    }
    verts->InsertNextCell(1, &id);
  }
  output->SetPoints(points);
  output->SetVerts(verts);
  output->GetPointData()->SetScalars(colors);
  if (!tree.scalar.empty())
  {
    output->GetPointData()->AddArray(scalars);
  }
}

//------------------------------------------------------------------------------
double vtkOctreeVolumeMapper::GetLeafSize()
{
  vtkInternals& in = *this->Internals;
  if (!in.Built || !in.Engine)
  {
    return 0.0;
  }
  octoray::HostOctree tree;
  in.Engine->CopyToHost(tree);
  return tree.cube.size / static_cast<double>(1u << tree.depth);
}

//------------------------------------------------------------------------------
vtkIdType vtkOctreeVolumeMapper::GetNumberOfOctreePoints()
{
  vtkInternals& in = *this->Internals;
  return (in.Built && in.Engine) ? static_cast<vtkIdType>(in.Engine->PointCount()) : 0;
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  static const char* backends[] = { "Auto", "CUDA", "CPU" };
  os << indent << "RequestedBackend: " << backends[this->RequestedBackend] << "\n";
  os << indent << "LastUsedBackend: " << this->GetLastUsedBackendName() << "\n";
  os << indent << "BackendDescription: " << this->Internals->Description << "\n";
  os << indent << "LeafDepth: " << this->LeafDepth << (this->LeafDepth == 0 ? " (auto)" : "") << "\n";
  os << indent << "LODPixelThreshold: " << this->LODPixelThreshold << "\n";
  os << indent << "RootBounds: " << this->RootBounds[0] << " " << this->RootBounds[1] << " "
     << this->RootBounds[2] << " " << this->RootBounds[3] << " " << this->RootBounds[4] << " "
     << this->RootBounds[5] << "\n";
  os << indent << "Shadows: " << (this->Shadows ? "On" : "Off") << "\n";
  os << indent << "MaximumBounces: " << this->MaximumBounces << "\n";
  os << indent << "DepthCue: " << this->DepthCue << "\n";
  os << indent << "ImageSampleDistance: " << this->ImageSampleDistance << "\n";
  os << indent << "ImageBackground: " << this->ImageBackground << "\n";
  os << indent << "ReflectivityArrayName: "
     << (this->ReflectivityArrayName ? this->ReflectivityArrayName : "(none)") << "\n";
  os << indent << "RefractionArrayName: "
     << (this->RefractionArrayName ? this->RefractionArrayName : "(none)") << "\n";
  os << indent << "CudaMemoryBudget: " << this->CudaMemoryBudget << "\n";
  os << indent << "NumberOfBuilds: " << this->NumberOfBuilds << "\n";
  os << indent << "NumberOfUpdates: " << this->NumberOfUpdates << "\n";
  os << indent << "NumberOfTraces: " << this->NumberOfTraces << "\n";
  os << indent << "LastBuildSeconds: " << this->LastBuildSeconds << "\n";
  os << indent << "LastTraceSeconds: " << this->LastTraceSeconds << "\n";
  os << indent << "LastDepthReadSeconds: " << this->LastDepthReadSeconds << "\n";
  os << indent << "LastUploadSeconds: " << this->LastUploadSeconds << "\n";
  os << indent << "LastDrawSeconds: " << this->LastDrawSeconds << "\n";
}
