// Clipping planes and cropping take voxels away: the picture of a clipped
// image must be the picture of the same image with those voxels below
// ImageBackground. The image is a block of voxels coloured through a
// transfer function, turned and moved by the volume's matrix, so that the
// planes, given in world coordinates, reach the data through its inverse.
// Each plane lies on a face between voxel layers, so that what it keeps is
// whole voxels, which the reference can leave out.
//
// Cases: one plane (its normal in world coordinates derived from three
// points of the data plane, independently of the mapper's transform);
// cropping to a sub-volume (CroppingRegionPlanes in data coordinates); the
// plane moved away after a frame, without touching the mapper (the picture
// must be traced again: the whole block). --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkColorTransferFunction.h"
#include "vtkMatrix4x4.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPlane.h"
#include "vtkRenderer.h"

#include <functional>

using namespace octoray_test;

namespace
{
const int kDims[3] = { 24, 20, 16 };
const double kSpacing = 0.1;
const double kOrigin[3] = { -1.2, -1.0, -0.8 };

// Whether sample (i, j, k) is kept.
using Keep = std::function<bool(int, int, int)>;

// Values 1..200 that differ between neighbours; 0 (background) where not
// kept. The transfer function spans the values drawn, so both ends lie in
// every part a test keeps: samples (13, 5, 5) and (14, 6, 6).
float Value(int i, int j, int k)
{
  if (i == 13 && j == 5 && k == 5)
    return 200.0f;
  if (i == 14 && j == 6 && k == 6)
    return 1.0f;
  return static_cast<float>(1 + (i * 7 + j * 3 + k * 5) % 200);
}

vtkSmartPointer<vtkImageData> Block(const Keep& keep)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(kDims);
  image->SetSpacing(kSpacing, kSpacing, kSpacing);
  image->SetOrigin(kOrigin[0], kOrigin[1], kOrigin[2]);
  image->AllocateScalars(VTK_FLOAT, 1);
  auto* values = static_cast<float*>(image->GetScalarPointer());
  for (int k = 0; k < kDims[2]; ++k)
    for (int j = 0; j < kDims[1]; ++j)
      for (int i = 0; i < kDims[0]; ++i)
        *values++ = keep(i, j, k) ? Value(i, j, k) : 0.0f;
  return image;
}

// The boundary between sample layers n - 1 and n on axis a, in data coordinates.
double Between(int a, int n)
{
  return kOrigin[a] + (n - 0.5) * kSpacing;
}

struct View
{
  vtkSmartPointer<vtkOctreeVolumeMapper> mapper;
  vtkSmartPointer<vtkVolume> volume;
  vtkSmartPointer<vtkRenderWindow> window;
};

View MakeView(const Backend& backend, vtkImageData* image)
{
  View v;
  v.mapper = NewMapper(backend);
  v.mapper->SetInputData(image);
  v.mapper->SetImageBackground(0.5);
  v.volume = Volume(v.mapper);
  v.volume->GetProperty()->IndependentComponentsOn();
  vtkNew<vtkColorTransferFunction> colours;
  colours->AddRGBPoint(1, 0.9, 0.2, 0.1);
  colours->AddRGBPoint(100, 0.1, 0.8, 0.3);
  colours->AddRGBPoint(200, 0.2, 0.3, 0.9);
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(0, 1);
  opacity->AddPoint(200, 1);
  v.volume->GetProperty()->SetColor(colours);
  v.volume->GetProperty()->SetScalarOpacity(opacity);
  v.volume->RotateZ(30);
  v.volume->RotateX(-20);
  v.volume->SetPosition(0.1, -0.05, 0.0);
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(v.volume);
  SetCamera(ren->GetActiveCamera());
  v.window = Window(200, 160);
  v.window->AddRenderer(ren);
  return v;
}

// World point of a data point under the volume's matrix.
void ToWorld(vtkVolume* volume, const double data[3], double world[3])
{
  const double in[4] = { data[0], data[1], data[2], 1 };
  double out[4];
  volume->GetMatrix()->MultiplyPoint(in, out);
  for (int a = 0; a < 3; ++a)
    world[a] = out[a] / out[3];
}

// The world plane through the data plane x = x0, keeping the side of
// larger x: from three of its points, the normal oriented towards a data
// point on the kept side.
void WorldPlaneOfDataX(vtkVolume* volume, double x0, vtkPlane* plane)
{
  const double d0[3] = { x0, 0, 0 }, d1[3] = { x0, 1, 0 }, d2[3] = { x0, 0, 1 }, inside[3] = { x0 + 1, 0, 0 };
  double p0[3], p1[3], p2[3], q[3], u[3], w[3], n[3];
  ToWorld(volume, d0, p0);
  ToWorld(volume, d1, p1);
  ToWorld(volume, d2, p2);
  ToWorld(volume, inside, q);
  for (int a = 0; a < 3; ++a)
    u[a] = p1[a] - p0[a], w[a] = p2[a] - p0[a];
  n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
  const double side = n[0] * (q[0] - p0[0]) + n[1] * (q[1] - p0[1]) + n[2] * (q[2] - p0[2]);
  for (int a = 0; a < 3; ++a)
    n[a] *= side > 0 ? 1 : -1;
  plane->SetOrigin(p0);
  plane->SetNormal(n);
}

// The clipped picture against the reference's: colours equal outside the
// band of colour edges, where float and double may round a ray to the
// neighbouring voxel; depth within 1e-5. Says what it found.
bool Matches(const char* what, const Picture& clipped, const Picture& reference, const Picture& whole)
{
  const std::vector<char> band = Band(reference);
  int colour = 0, depth = 0, inBand = 0;
  for (int y = 0; y < reference.h; ++y)
  {
    for (int x = 0; x < reference.w; ++x)
    {
      const bool differs = !Same(clipped.At(x, y), reference.At(x, y));
      const bool edge = band[static_cast<size_t>(y) * reference.w + x] != 0;
      colour += differs && !edge;
      inBand += differs && edge;
      depth += std::fabs(clipped.Depth(x, y) - reference.Depth(x, y)) > 1e-5f;
    }
  }
  const int changed = Differing(whole, reference);
  std::cout << what << ": " << Covered(clipped) << " covered pixels (" << Covered(whole) << " unclipped, "
            << changed << " changed by the clip); " << colour << " colour differences off the edges, " << inBand
            << " on them, " << depth << " depth differences\n";
  return changed > 1000 && colour == 0 && inBand * 100 <= Covered(reference) && depth <= inBand;
}

Picture Draw(View& v, const Backend& backend, bool& drew)
{
  const Picture p = Capture(v.window);
  drew = drew && DrewWith(v.mapper, backend);
  return p;
}
}

int TestOctreeVolumeMapperClipping(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  bool drew = true;
  View whole = MakeView(backend, Block([](int, int, int) { return true; }));
  const Picture unclipped = Draw(whole, backend, drew);

  // One plane: the samples from layer 12 on are kept.
  View clipped = MakeView(backend, Block([](int, int, int) { return true; }));
  vtkNew<vtkPlane> plane;
  WorldPlaneOfDataX(clipped.volume, Between(0, 12), plane);
  clipped.mapper->AddClippingPlane(plane);
  const Picture byPlane = Draw(clipped, backend, drew);
  View halfBlock = MakeView(backend, Block([](int i, int, int) { return i >= 12; }));
  CHECK(Matches("clipping plane", byPlane, Draw(halfBlock, backend, drew), unclipped));

  // The plane moved beyond the block, the mapper untouched: all of it again.
  WorldPlaneOfDataX(clipped.volume, Between(0, 0) - 1.0, plane);
  const Picture moved = Draw(clipped, backend, drew);
  std::cout << "plane moved away: " << Differing(moved, unclipped) << " pixels differ from the unclipped picture\n";
  CHECK(Differing(moved, unclipped) == 0);

  // Cropping to a sub-volume: layers 4..19, 3..15 and 2..12 kept.
  View cropped = MakeView(backend, Block([](int, int, int) { return true; }));
  cropped.mapper->SetCropping(true);
  cropped.mapper->SetCroppingRegionFlagsToSubVolume();
  cropped.mapper->SetCroppingRegionPlanes(
    Between(0, 4), Between(0, 20), Between(1, 3), Between(1, 16), Between(2, 2), Between(2, 13));
  const Picture byBox = Draw(cropped, backend, drew);
  View subVolume = MakeView(backend, Block([](int i, int j, int k) {
    return i >= 4 && i < 20 && j >= 3 && j < 16 && k >= 2 && k < 13;
  }));
  CHECK(Matches("cropping", byBox, Draw(subVolume, backend, drew), unclipped));
  CHECK(drew);
  return Result();
}
