// The octree mapper against VTK's own GPU mappers, on the same points, the
// same camera orbit and the same offscreen window (issue 13). For each point
// set and window size, each method draws an orbit of the camera around the
// points and records:
//   - time to the first picture: from points in memory to the first frame on
//     screen (octree build, or resampling onto an image, plus the first
//     render); reading or generating the points is reported apart;
//   - median and 95th-percentile frame time over the orbit (each frame ends
//     with glFinish, so it is the GPU's time too);
//   - GPU memory the method added (cudaMemGetInfo: the device's whole use,
//     OpenGL's buffers and textures included).
// Methods:
//   octoray          vtkOctreeVolumeMapper, CUDA, picture to OpenGL device to device
//   octoray-host     the same with the picture through host memory
//   pointgauss       vtkPointGaussianMapper (ParaView's "Sphere" splat shader)
//   points           vtkPolyDataMapper drawing the vertices, 2-pixel points
//   smart-G          vtkPointInterpolator (Gaussian kernel) onto G^3 voxels,
//                    then vtkSmartVolumeMapper (GPU ray casting) of RGBA
// A method whose first frame is slow draws fewer orbit frames (at least 3),
// so that one run stays within the device's time; the count is recorded. A
// resampling whose time, extrapolated from the smaller grid's in the same
// run (voxels x), would pass --max-prepare seconds is skipped and says so.
//
//   octoray_bench_orbit [--points 1e6,1e7,1e8] [--sizes 1920x1080,3840x2160]
//     [--methods octoray,octoray-host,pointgauss,points,smart-256,smart-512]
//     [--file particles.txt|cloud.pcd] [--frames 60] [--seconds 6] [--max-prepare 90] [--json out.json]
//     [--images DIR]   (each method's first frame as a PNG)
//     [--tile N [--tile-depth D]]   (the file's cloud tiled to N points on a
//                      square grid, drawn by octoray at leaf depth D, default
//                      12, without keeping the points: a real scan at a
//                      billion points)
#include "BenchUtil.h"
#include "CommandLine.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCellArray.h"
#include "vtkFloatArray.h"
#include "vtkGaussianKernel.h"
#include "vtkImageData.h"
#include "vtkLookupTable.h"
#include "vtkNew.h"
#include "vtkOctreeVolumeMapper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPCDReader.h"
#include "vtkParticleTextReader.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPointGaussianMapper.h"
#include "vtkPointInterpolator.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSmartVolumeMapper.h"
#include "vtkTypeInt32Array.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"

#include <cuda_runtime_api.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <thread>

using namespace octoray::bench;

namespace
{
double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Bytes in use on the current CUDA device (all of it: CUDA and OpenGL).
double DeviceBytesUsed()
{
  std::size_t freeBytes = 0, total = 0;
  return cudaMemGetInfo(&freeBytes, &total) == cudaSuccess ? static_cast<double>(total - freeBytes) : 0.0;
}

// ---------------------------------------------------------------- points

// Clustered points with a colour from their position: `n` points in 64
// Gaussian blobs (fixed seed), made on every core; deterministic for a given
// n whatever the thread count.
// fn(b, begin, end) for the blocks [b * block, min(n, (b + 1) * block)) of
// [0, n), spread over the machine's threads.
template <typename Fn>
void ForEachBlock(std::size_t n, std::size_t block, Fn fn)
{
  const std::size_t blocks = (n + block - 1) / block;
  std::vector<std::thread> workers;
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  for (unsigned t = 0; t < threads; ++t)
  {
    workers.emplace_back([&, t] {
      for (std::size_t b = t; b < blocks; b += threads)
      {
        fn(b, b * block, std::min(n, (b + 1) * block));
      }
    });
  }
  for (std::thread& w : workers)
  {
    w.join();
  }
}

// A cloud of float positions and 8-bit RGB colours, as the generated and
// tiled scenes hand them to every method.
vtkSmartPointer<vtkPolyData> CloudOf(vtkFloatArray* xyz, vtkUnsignedCharArray* rgb)
{
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetData(xyz);
  cloud->SetPoints(points);
  rgb->SetName("Colors");
  cloud->GetPointData()->SetScalars(rgb);
  return cloud;
}

vtkSmartPointer<vtkPolyData> ClusteredPoints(std::size_t n)
{
  const int clusters = 64;
  Random centres(kDefaultSeed);
  std::vector<double> centre(3 * clusters), sigma(clusters);
  for (int k = 0; k < clusters; ++k)
  {
    for (int a = 0; a < 3; ++a)
    {
      centre[3 * k + a] = 0.1 + 0.8 * centres.Uniform();
    }
    sigma[k] = 0.01 + 0.05 * centres.Uniform();
  }
  vtkNew<vtkFloatArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(static_cast<vtkIdType>(n));
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetName("Colors");
  rgb->SetNumberOfComponents(3);
  rgb->SetNumberOfTuples(static_cast<vtkIdType>(n));
  ForEachBlock(n, std::size_t{ 1 } << 20, [&](std::size_t b, std::size_t begin, std::size_t end) {
    Random random(kDefaultSeed + 1 + b);
    for (std::size_t i = begin; i < end; ++i)
    {
      const std::size_t k = random.Next() % clusters;
      float* p = xyz->GetPointer(3 * static_cast<vtkIdType>(i));
      unsigned char* c = rgb->GetPointer(3 * static_cast<vtkIdType>(i));
      for (int a = 0; a < 3; ++a)
      {
        p[a] = static_cast<float>(centre[3 * k + a] + sigma[k] * random.Normal());
        c[a] = static_cast<unsigned char>(40 + 215 * std::min(1.0, std::max(0.0, static_cast<double>(p[a]))));
      }
    }
  });
  return CloudOf(xyz, rgb);
}

// `n` points from copies of `cloud` (positions and its "Colors") laid side
// by side on a square grid in x and y, a tenth of its extent apart; the
// last copy is cut at n. How a real scan reaches a billion points.
vtkSmartPointer<vtkPolyData> TiledCloud(vtkPolyData* cloud, std::size_t n)
{
  const std::size_t m = static_cast<std::size_t>(cloud->GetNumberOfPoints());
  double b[6];
  cloud->GetBounds(b);
  const std::size_t copies = (n + m - 1) / m;
  const std::size_t side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(copies))));
  const double step[2] = { 1.1 * (b[1] - b[0]), 1.1 * (b[3] - b[2]) };
  std::vector<float> from(3 * m);
  for (std::size_t k = 0; k < m; ++k)
  {
    const double* p = cloud->GetPoint(static_cast<vtkIdType>(k));
    for (int a = 0; a < 3; ++a)
    {
      from[3 * k + a] = static_cast<float>(p[a]);
    }
  }
  auto* colours = vtkUnsignedCharArray::SafeDownCast(cloud->GetPointData()->GetArray("Colors"));
  if (!colours || colours->GetNumberOfComponents() != 3)
  {
    std::fprintf(stderr, "--tile: the file's \"Colors\" are not 8-bit RGB; tiling copies those only\n");
    std::exit(2);
  }
  vtkNew<vtkFloatArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(static_cast<vtkIdType>(n));
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetNumberOfComponents(3);
  rgb->SetNumberOfTuples(static_cast<vtkIdType>(n));
  const unsigned char* colour = colours->GetPointer(0);
  ForEachBlock(n, m, [&](std::size_t copy, std::size_t begin, std::size_t end) {
    const float offset[3] = { static_cast<float>(step[0] * (copy % side)), static_cast<float>(step[1] * (copy / side)),
      0.0f };
    float* p = xyz->GetPointer(3 * static_cast<vtkIdType>(begin));
    for (std::size_t v = 0; v < 3 * (end - begin); ++v)
    {
      p[v] = from[v] + offset[v % 3];
    }
    std::copy(colour, colour + 3 * (end - begin), rgb->GetPointer(3 * static_cast<vtkIdType>(begin)));
  });
  return CloudOf(xyz, rgb);
}

// One vertex cell per point (vtkPolyDataMapper draws cells), 32-bit ids.
void AddVertices(vtkPolyData* cloud)
{
  const vtkIdType n = cloud->GetNumberOfPoints();
  vtkNew<vtkTypeInt32Array> offsets, connectivity;
  offsets->SetNumberOfValues(n + 1);
  connectivity->SetNumberOfValues(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    offsets->SetValue(i, static_cast<int>(i));
    connectivity->SetValue(i, static_cast<int>(i));
  }
  offsets->SetValue(n, static_cast<int>(n));
  vtkNew<vtkCellArray> verts;
  verts->SetData(offsets, connectivity);
  cloud->SetVerts(verts);
}

// ---------------------------------------------------------------- methods

struct Scene
{
  std::string Name;
  vtkSmartPointer<vtkPolyData> Cloud;
  double Bounds[6];
  double Radius; // splat radius: about the mean point spacing on the surface
  double PrepareSeconds = 0.0; // reading or generating the points
  int LeafDepth = 0;           // octoray's leaf level; 0: chosen from the data
  bool KeepPoints = true;      // octoray's KeepPointsForUpdates
};

struct Method
{
  vtkSmartPointer<vtkProp> Prop;
  double PrepareSeconds = 0.0; // resampling onto an image, before the first render
  bool PreparedEarlier = false; // for an earlier window size: not in this run's clock
  vtkOctreeVolumeMapper* Octree = nullptr;
  std::string Note;
};

Method Octree(const Scene& scene, bool interop)
{
  vtkNew<vtkOctreeVolumeMapper> mapper;
  mapper->SetRequestedBackendToCuda();
  mapper->SetUseCudaGLInterop(interop);
  mapper->SetInputData(scene.Cloud);
  mapper->SetLeafDepth(scene.LeafDepth); // 0 unless --tile: chosen from the data, as a user gets it
  mapper->SetKeepPointsForUpdates(scene.KeepPoints);
  auto volume = vtkSmartPointer<vtkVolume>::New();
  volume->SetMapper(mapper);
  vtkNew<vtkVolumeProperty> property;
  property->IndependentComponentsOff();
  property->ShadeOn();
  volume->SetProperty(property);
  Method m;
  m.Prop = volume;
  m.Octree = mapper;
  return m;
}

// ParaView's "Sphere" preset of the Point Gaussian representation: a lit,
// opaque disc shaded as a sphere (the default Gaussian blur is translucent).
const char* const kSphereShader = "//VTK::Color::Impl\n"
                                  "float dist = dot(offsetVCVSOutput.xy, offsetVCVSOutput.xy);\n"
                                  "if (dist > 1.0) { discard; } else {\n"
                                  "  float scale = (1.0 - dist);\n"
                                  "  ambientColor *= scale;\n"
                                  "  diffuseColor *= scale;\n"
                                  "}\n";

Method PointGaussian(const Scene& scene)
{
  vtkNew<vtkPointGaussianMapper> mapper;
  mapper->SetInputData(scene.Cloud);
  mapper->SetScaleFactor(scene.Radius);
  mapper->EmissiveOff();
  mapper->SetSplatShaderCode(kSphereShader);
  mapper->SetColorModeToDirectScalars();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  Method m;
  m.Prop = actor;
  return m;
}

Method Points(const Scene& scene)
{
  if (!scene.Cloud->GetVerts() || scene.Cloud->GetVerts()->GetNumberOfCells() == 0)
  {
    AddVertices(scene.Cloud);
  }
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(scene.Cloud);
  mapper->SetColorModeToDirectScalars();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetPointSize(2);
  Method m;
  m.Prop = actor;
  return m;
}

// RGBA voxels from the interpolator's output: its colour and, as alpha, its
// mask of voxels that had points within the kernel's radius.
vtkSmartPointer<vtkUnsignedCharArray> RgbaVoxels(vtkDataSet* out, vtkDataArray* valid, const int dims[3])
{
  auto* colours = vtkDataArray::SafeDownCast(out->GetPointData()->GetArray("Colors"));
  const vtkIdType voxels = out->GetNumberOfPoints();
  auto rgba = vtkSmartPointer<vtkUnsignedCharArray>::New();
  rgba->SetName("RGBA");
  rgba->SetNumberOfComponents(4);
  rgba->SetNumberOfTuples(voxels);
  for (vtkIdType i = 0; i < voxels; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      rgba->SetTypedComponent(i, c, static_cast<unsigned char>(colours->GetComponent(i, c)));
    }
    rgba->SetTypedComponent(i, 3, valid->GetComponent(i, 0) != 0 ? 255 : 0);
  }
  // An empty voxel beside a filled one takes that voxel's colour: the ray
  // caster interpolates colour and opacity apart (not premultiplied), so
  // black empty voxels would otherwise darken every blob's rim.
  const vtkIdType step[3] = { 1, dims[0], static_cast<vtkIdType>(dims[0]) * dims[1] };
  for (vtkIdType i = 0; i < voxels; ++i)
  {
    if (rgba->GetTypedComponent(i, 3) != 0)
    {
      continue;
    }
    for (int a = 0; a < 6; ++a)
    {
      const vtkIdType j = i + (a % 2 ? step[a / 2] : -step[a / 2]);
      if (j >= 0 && j < voxels && valid->GetComponent(j, 0) != 0)
      {
        for (int c = 0; c < 3; ++c)
        {
          rgba->SetTypedComponent(i, c, rgba->GetTypedComponent(j, c));
        }
        break;
      }
    }
  }
  return rgba;
}

struct Resampled
{
  vtkSmartPointer<vtkImageData> Image;
  double Seconds = 0.0;
  bool Earlier = false; // done for an earlier window size
};

// The points resampled onto `grid`^3 voxels over their bounds by
// vtkPointInterpolator with a Gaussian kernel (radius: the scene's splat
// radius, at least a voxel). The image does not depend on the window size:
// it is made once per scene and grid, and its time counted again in each
// window size's first picture.
Resampled Resample(const Scene& scene, int grid)
{
  static std::map<std::string, Resampled> done;
  const std::string key = scene.Name + "/" + std::to_string(scene.Cloud->GetNumberOfPoints()) + "/" + std::to_string(grid);
  if (done.count(key))
  {
    Resampled earlier = done[key];
    earlier.Earlier = true;
    return earlier;
  }
  const double* b = scene.Bounds;
  const double longest = std::max({ b[1] - b[0], b[3] - b[2], b[5] - b[4] });
  const double h = longest / (grid - 1);
  const double t0 = Now();
  vtkNew<vtkImageData> image;
  int dims[3];
  for (int a = 0; a < 3; ++a)
  {
    dims[a] = std::max(2, static_cast<int>(std::ceil((b[2 * a + 1] - b[2 * a]) / h)) + 1);
  }
  image->SetDimensions(dims);
  image->SetOrigin(b[0], b[2], b[4]);
  image->SetSpacing(h, h, h);
  vtkNew<vtkGaussianKernel> kernel;
  kernel->SetRadius(std::max(scene.Radius, h));
  kernel->SetSharpness(2.0);
  vtkNew<vtkPointInterpolator> interpolator;
  interpolator->SetInputData(image);
  interpolator->SetSourceData(scene.Cloud);
  interpolator->SetKernel(kernel);
  interpolator->SetNullPointsStrategyToMaskPoints();
  interpolator->Update();
  vtkDataSet* out = interpolator->GetOutput();
  auto* valid = vtkDataArray::SafeDownCast(
    out->GetPointData()->GetArray(interpolator->GetValidPointsMaskArrayName().c_str()));
  Resampled r;
  r.Image = vtkSmartPointer<vtkImageData>::New();
  r.Image->CopyStructure(out);
  r.Image->GetPointData()->SetScalars(RgbaVoxels(out, valid, dims));
  r.Seconds = Now() - t0;
  done[key] = r;
  return r;
}

// vtkSmartVolumeMapper (GPU ray casting) of the resampled RGBA voxels.
Method SmartVolume(const Scene& scene, int grid)
{
  const Resampled resampled = Resample(scene, grid);
  Method m;
  m.PrepareSeconds = resampled.Seconds;
  m.PreparedEarlier = resampled.Earlier;
  vtkNew<vtkSmartVolumeMapper> mapper;
  mapper->SetInputData(resampled.Image);
  mapper->SetRequestedRenderModeToGPU();
  auto volume = vtkSmartPointer<vtkVolume>::New();
  volume->SetMapper(mapper);
  // RGB drawn directly, A through the opacity function. Unshaded: with
  // dependent RGBA components VTK 9.2's ray caster lights with the ambient
  // term only, which would just darken the picture.
  vtkNew<vtkVolumeProperty> property;
  property->IndependentComponentsOff();
  property->ShadeOff();
  property->SetInterpolationTypeToLinear();
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(0, 0.0);
  opacity->AddPoint(255, 1.0);
  property->SetScalarOpacity(opacity);
  volume->SetProperty(property);
  m.Prop = volume;
  const int* dims = resampled.Image->GetDimensions();
  m.Note = std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" + std::to_string(dims[2]);
  return m;
}

// ---------------------------------------------------------------- the orbit

struct Result
{
  std::string Scene, Method, Note;
  std::size_t Points = 0;
  int Width = 0, Height = 0;
  double PrepareSeconds = 0.0, FirstPictureSeconds = 0.0, MedianFrame = 0.0, P95Frame = 0.0, GpuBytes = 0.0;
  int Frames = 0;
  // octoray's share of a frame: trace, depth read, picture transfer, draw.
  double Trace = 0.0, Depth = 0.0, Transfer = 0.0, Draw = 0.0;
  std::string Backend;
};

double Percentile(std::vector<double> v, double q)
{
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5))];
}

// The window's picture as a PNG file.
void WritePicture(vtkRenderWindow* window, const std::string& path)
{
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  vtkNew<vtkPNGWriter> png;
  png->SetInputConnection(grab->GetOutputPort());
  png->SetFileName(path.c_str());
  png->Write();
}

Result Orbit(const Scene& scene, const std::string& name, int width, int height, int frames, double seconds,
  const std::string& images)
{
  Result r;
  r.Scene = scene.Name;
  r.Method = name;
  r.Points = static_cast<std::size_t>(scene.Cloud->GetNumberOfPoints());
  r.Width = width;
  r.Height = height;
  const double before = DeviceBytesUsed();
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(width, height);
  vtkNew<vtkRenderer> ren;
  ren->SetBackground(0.1, 0.1, 0.12);
  window->AddRenderer(ren);
  auto* gl = vtkOpenGLRenderWindow::SafeDownCast(window);
  window->Render(); // the context and an empty frame: not the method's cost
  gl->WaitForCompletion();

  const double t0 = Now();
  Method m;
  if (name == "octoray" || name == "octoray-host")
  {
    m = Octree(scene, name == "octoray");
  }
  else if (name == "pointgauss")
  {
    m = PointGaussian(scene);
  }
  else if (name == "points")
  {
    m = Points(scene);
  }
  else
  {
    m = SmartVolume(scene, std::stoi(name.substr(name.find('-') + 1)));
  }
  ren->AddViewProp(m.Prop);
  ren->ResetCamera(scene.Bounds);
  ren->GetActiveCamera()->Elevation(25);
  ren->GetActiveCamera()->Zoom(1.3);
  ren->ResetCameraClippingRange(scene.Bounds);
  window->Render();
  gl->WaitForCompletion();
  r.FirstPictureSeconds = Now() - t0 + (m.PreparedEarlier ? m.PrepareSeconds : 0.0);
  r.PrepareSeconds = m.PrepareSeconds;
  r.Note = m.Note;
  r.GpuBytes = DeviceBytesUsed() - before;
  if (!images.empty())
  {
    WritePicture(window, images + "/" + scene.Name + "-" + std::to_string(r.Points) + "-" + std::to_string(width) +
        "x" + std::to_string(height) + "-" + name + ".png");
  }

  // Fewer frames for a slow method (at least 3), so the run fits its time.
  const double firstFrame = r.FirstPictureSeconds - m.PrepareSeconds;
  r.Frames = std::max(3, std::min(frames, static_cast<int>(seconds / std::max(firstFrame, 1e-3))));
  std::vector<double> times, trace, depth, transfer, draw;
  for (int f = 0; f < r.Frames; ++f)
  {
    ren->GetActiveCamera()->Azimuth(360.0 / r.Frames);
    ren->ResetCameraClippingRange(scene.Bounds);
    const double f0 = Now();
    window->Render();
    gl->WaitForCompletion();
    times.push_back(Now() - f0);
    if (m.Octree)
    {
      trace.push_back(m.Octree->GetLastTraceSeconds());
      depth.push_back(m.Octree->GetLastDepthReadSeconds());
      transfer.push_back(m.Octree->GetLastUploadSeconds());
      draw.push_back(m.Octree->GetLastDrawSeconds());
    }
  }
  r.MedianFrame = Summarise(times).median;
  r.P95Frame = Percentile(times, 0.95);
  if (m.Octree)
  {
    r.Trace = Summarise(trace).median;
    r.Depth = Summarise(depth).median;
    r.Transfer = Summarise(transfer).median;
    r.Draw = Summarise(draw).median;
    r.Backend = std::string(m.Octree->GetLastUsedBackendName()) + ", " + m.Octree->GetLastPictureTransferName();
  }
  return r;
}

void Print(const Result& r)
{
  std::printf("%-10s %11zu %4dx%-4d %-13s first %9.1f ms (prepare %8.1f)  frame median %8.2f p95 %8.2f ms (%2d)  "
              "GPU %8.1f MB %s%s\n",
    r.Scene.c_str(), r.Points, r.Width, r.Height, r.Method.c_str(), 1e3 * r.FirstPictureSeconds,
    1e3 * r.PrepareSeconds, 1e3 * r.MedianFrame, 1e3 * r.P95Frame, r.Frames, r.GpuBytes / 1e6, r.Note.c_str(),
    r.Backend.empty() ? "" : (" [" + r.Backend + "]").c_str());
  if (!r.Backend.empty())
  {
    std::printf("%59s trace %.2f, depth read %.2f, picture to OpenGL %.2f, draw %.2f ms\n", "", 1e3 * r.Trace,
      1e3 * r.Depth, 1e3 * r.Transfer, 1e3 * r.Draw);
  }
  std::fflush(stdout);
}

Scene MakeScene(const std::string& name, vtkSmartPointer<vtkPolyData> cloud, double prepare)
{
  Scene s;
  s.Name = name;
  s.Cloud = cloud;
  s.PrepareSeconds = prepare;
  cloud->GetBounds(s.Bounds);
  const double longest = std::max({ s.Bounds[1] - s.Bounds[0], s.Bounds[3] - s.Bounds[2], s.Bounds[5] - s.Bounds[4] });
  // About the spacing of the points seen as a surface: longest / sqrt(n), a
  // few pixels across at these window sizes.
  s.Radius = 1.5 * longest / std::sqrt(static_cast<double>(cloud->GetNumberOfPoints()));
  return s;
}

struct Options
{
  std::vector<std::size_t> Points = { 1000000, 10000000, 100000000 }; // 0: the file's scene alone
  std::vector<std::array<int, 2>> Sizes = { { 1920, 1080 }, { 3840, 2160 } };
  std::string Methods = "octoray,octoray-host,pointgauss,points,smart-256,smart-512", File, Json, Images;
  double Tile = 0.0; // points: the file's cloud tiled to that many (a static scene, points not kept)
  int TileDepth = 12;
  int Frames = 60;
  double Seconds = 6.0, MaxPrepare = 90.0;
};

// A cloud without colours (the LMS400 laser scan has only intensity) gets
// them from its intensity, or else its elevation, through a blue-to-red
// table: every method then draws the same colours, and the resampled
// volumes have colour to interpolate.
void ColourIfUncoloured(vtkPolyData* cloud)
{
  if (cloud->GetPointData()->GetArray("Colors"))
  {
    return;
  }
  vtkSmartPointer<vtkDataArray> values = cloud->GetPointData()->GetArray("Intensity");
  if (!values)
  {
    values = vtkSmartPointer<vtkFloatArray>::New();
    values->SetNumberOfTuples(cloud->GetNumberOfPoints());
    for (vtkIdType i = 0; i < cloud->GetNumberOfPoints(); ++i)
    {
      values->SetTuple1(i, cloud->GetPoint(i)[2]);
    }
  }
  // The range from the 1st to the 99th percentile, as the Python scenes
  // colour: a few bright returns would otherwise push the rest into blue.
  std::vector<double> sorted(values->GetNumberOfTuples());
  for (vtkIdType i = 0; i < values->GetNumberOfTuples(); ++i)
  {
    sorted[i] = values->GetTuple1(i);
  }
  vtkNew<vtkLookupTable> table;
  table->SetRange(Percentile(sorted, 0.01), Percentile(sorted, 0.99));
  table->SetHueRange(0.667, 0.0);
  table->Build();
  vtkSmartPointer<vtkUnsignedCharArray> rgb;
  rgb.TakeReference(table->MapScalars(values, VTK_COLOR_MODE_MAP_SCALARS, 0, VTK_RGB));
  rgb->SetName("Colors");
  cloud->GetPointData()->AddArray(rgb);
  cloud->GetPointData()->SetScalars(rgb);
}

// The generated point sets, and the file's points (a particle text file or a
// PCL point cloud) as a scene of its own.
std::vector<Scene> LoadScenes(const Options& o)
{
  std::vector<Scene> scenes;
  for (const std::size_t n : o.Points)
  {
    if (n == 0)
    {
      continue; // --points 0: the file's scene alone
    }
    const double t0 = Now();
    vtkSmartPointer<vtkPolyData> cloud = ClusteredPoints(n);
    scenes.push_back(MakeScene("clusters", cloud, Now() - t0));
  }
  if (!o.File.empty())
  {
    const double t0 = Now();
    const bool pcd = o.File.size() > 4 && o.File.compare(o.File.size() - 4, 4, ".pcd") == 0;
    vtkSmartPointer<vtkPointFileReader> reader;
    if (pcd)
    {
      reader = vtkSmartPointer<vtkPCDReader>::New();
    }
    else
    {
      reader = vtkSmartPointer<vtkParticleTextReader>::New();
    }
    reader->SetFileName(o.File.c_str());
    reader->Update();
    auto cloud = vtkSmartPointer<vtkPolyData>::New();
    cloud->ShallowCopy(reader->GetOutput());
    cloud->SetVerts(nullptr);
    ColourIfUncoloured(cloud);
    std::string name = o.File.substr(o.File.find_last_of('/') + 1);
    if (o.Tile > 0)
    {
      cloud = TiledCloud(cloud, static_cast<std::size_t>(o.Tile));
      name += ".tiled";
    }
    scenes.push_back(MakeScene(name, cloud, Now() - t0));
    if (o.Tile > 0)
    {
      scenes.back().LeafDepth = o.TileDepth;
      scenes.back().KeepPoints = false;
    }
  }
  return scenes;
}

Record ToRecord(const Result& r)
{
  Record record;
  record.name = "orbit " + r.Scene + " " + std::to_string(r.Width) + "x" + std::to_string(r.Height) + " " + r.Method;
  record.backend = r.Method.rfind("octoray", 0) == 0 ? "cuda" : "vtk";
  record.n = r.Points;
  record.seconds = r.MedianFrame;
  record.With("first_picture_s", r.FirstPictureSeconds)
    .With("prepare_s", r.PrepareSeconds)
    .With("p95_frame_s", r.P95Frame)
    .With("frames", r.Frames)
    .With("gpu_bytes", r.GpuBytes)
    .With("width", r.Width)
    .With("height", r.Height);
  if (!r.Backend.empty())
  {
    record.With("trace_s", r.Trace).With("depth_read_s", r.Depth).With("transfer_s", r.Transfer).With("draw_s", r.Draw);
  }
  return record;
}

// The ratios, where the methods ran: octoray's frame against the
// fastest VTK frame and against its own picture through host memory, and its
// first picture against vtkSmartVolumeMapper's.
void PrintRatios(const std::map<std::string, Result>& results)
{
  const auto octoray = results.find("octoray");
  if (octoray == results.end())
  {
    return;
  }
  const Result& o = octoray->second;
  const Result* fastest = nullptr;
  const Result* smart = nullptr;
  for (const auto& [method, r] : results)
  {
    if (method.rfind("octoray", 0) == 0)
    {
      continue;
    }
    if (!fastest || r.MedianFrame < fastest->MedianFrame)
    {
      fastest = &r;
    }
    if (method.rfind("smart", 0) == 0 && (!smart || r.FirstPictureSeconds < smart->FirstPictureSeconds))
    {
      smart = &r;
    }
  }
  std::printf("  => octoray frame %.2f ms", 1e3 * o.MedianFrame);
  if (fastest)
  {
    std::printf("; fastest VTK frame (%s) %.2f ms, %.2fx octoray's", fastest->Method.c_str(), 1e3 * fastest->MedianFrame,
      fastest->MedianFrame / o.MedianFrame);
  }
  if (smart)
  {
    std::printf("; first picture %.3f s, %.3fx %s's", o.FirstPictureSeconds,
      o.FirstPictureSeconds / smart->FirstPictureSeconds, smart->Method.c_str());
  }
  const auto host = results.find("octoray-host");
  if (host != results.end())
  {
    std::printf("; picture through host memory %.2f ms a frame", 1e3 * host->second.MedianFrame);
  }
  std::printf("\n");
}

// A resampling onto grid^3 voxels whose time, extrapolated from the last
// one's seconds per voxel, would pass --max-prepare.
bool ResamplingTooSlow(const std::string& method, double secondsPerVoxel, const Options& o, double& estimate)
{
  if (method.rfind("smart-", 0) != 0 || secondsPerVoxel <= 0.0)
  {
    return false;
  }
  const double grid = std::stod(method.substr(6));
  estimate = secondsPerVoxel * grid * grid * grid;
  return estimate > o.MaxPrepare;
}

// Every method on one scene at one window size.
void RunSize(const Scene& scene, int w, int h, const Options& o, std::vector<Record>& records)
{
  std::map<std::string, Result> results;
  double secondsPerVoxel = 0.0; // the last resampling's
  for (const std::string& method : octoray::SplitList(o.Methods))
  {
    double estimate = 0.0;
    if (ResamplingTooSlow(method, secondsPerVoxel, o, estimate))
    {
      std::printf("%-10s %11lld %4dx%-4d %-13s skipped: resampling estimated at %.0f s (over --max-prepare %.0f)\n",
        scene.Name.c_str(), static_cast<long long>(scene.Cloud->GetNumberOfPoints()), w, h, method.c_str(), estimate,
        o.MaxPrepare);
      continue;
    }
    const Result r = Orbit(scene, method, w, h, o.Frames, o.Seconds, o.Images);
    if (method.rfind("smart-", 0) == 0)
    {
      const double grid = std::stod(method.substr(6));
      secondsPerVoxel = r.PrepareSeconds / (grid * grid * grid);
    }
    Print(r);
    results[method] = r;
    records.push_back(ToRecord(r));
  }
  PrintRatios(results);
}
}

int main(int argc, char* argv[])
{
  Options o;
  octoray::CommandLine cli;
  cli.Text("--methods", o.Methods).Text("--file", o.File);
  cli.Counts("--points", o.Points);
  cli.Option("--sizes", "a list of sizes WxH such as 1920x1080,3840x2160", [&o](const std::string& v) {
    o.Sizes.clear();
    for (const std::string& size : octoray::SplitList(v))
    {
      std::array<int, 2> wh{};
      if (!octoray::CommandLine::ParseSize(size, wh[0], wh[1]))
      {
        return false;
      }
      o.Sizes.push_back(wh);
    }
    return !o.Sizes.empty();
  });
  cli.Integer("--frames", o.Frames, 3).Real("--seconds", o.Seconds).Text("--json", o.Json).Text("--images", o.Images);
  cli.Real("--max-prepare", o.MaxPrepare).Real("--tile", o.Tile).Integer("--tile-depth", o.TileDepth, 1);
  const char* usage =
    "usage: octoray_bench_orbit [--points 1e6,1e7] [--sizes 1920x1080] [--methods octoray,points]\n"
    "                           [--file particles.txt|cloud.pcd] [--frames 60] [--seconds 6] [--max-prepare 90]\n"
    "                           [--json out.json] [--images DIR] [--tile N [--tile-depth 12]]\n";
  if (const std::optional<int> stop = cli.ParseOrStop(argc, argv, usage))
  {
    return *stop;
  }
  if (!vtkOctreeVolumeMapper::IsCudaAvailable())
  {
    std::printf("no usable CUDA device: octoray falls back to the CPU and GPU memory reads 0\n");
  }
  cudaFree(nullptr); // the CUDA context first: its own memory is nobody's cost
  std::vector<Record> records;
  for (const Scene& scene : LoadScenes(o))
  {
    std::printf("\n%s, %lld points: generated or read in %.2f s\n", scene.Name.c_str(),
      static_cast<long long>(scene.Cloud->GetNumberOfPoints()), scene.PrepareSeconds);
    for (const std::array<int, 2>& size : o.Sizes)
    {
      RunSize(scene, size[0], size[1], o, records);
    }
  }
  SaveRecords(o.Json, records);
  return 0;
}
