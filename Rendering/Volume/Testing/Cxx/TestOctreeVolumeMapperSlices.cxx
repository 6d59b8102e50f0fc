// A slice stack must draw as a closed volume. A solid block written as 8
// slices 3 pixel spacings apart (pixels 1 x 1, slices 3; 23 x 15 pixels; an
// origin off the grid) is drawn from the side (the slice axis across the
// view, where gaps between slices would show as stripes), from the other
// side, at a grazing angle, from above, and with a parallel projection. In
// every view no pixel inside the block's silhouette may show the
// background. The silhouette is VTK's own: the block's box (vtkCubeSource
// over the voxel centres' bounds, in the image's frame) drawn with the same
// camera, shrunk by two pixels; and nothing may be drawn farther outside it
// than a leaf (its diagonal where the block is turned).
//
// Cases: the vtkImageData itself (FillBetweenSlices on, the default: leaves
// of the pixel size, the 7590 points of 22 planes; off: leaves of the slice
// spacing, the 2760 voxels), point sets that name their lattice in the
// field data as vtkSliceStackReader's particles do (the slices' pixels, and
// the filled planes), and the image in a root cube around larger bounds (as
// parallel ranks build theirs), the image turned obliquely, the image with
// an extent that does not start at 0, and the block as the cells of an image
// coloured by cell scalars. --backend cpu|cuda; the side views in parallel
// projection are written to the testing temporary folder (-T) to look at.
#include "octorayMapperTesting.h"

#include "vtkActor.h"
#include "vtkCellData.h"
#include "vtkCubeSource.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkPNGWriter.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderer.h"
#include "vtkTransform.h"

using namespace octoray_test;

namespace
{
const int kDims[3] = { 23, 15, 8 };
const double kSpacing[3] = { 1.0, 1.0, 3.0 };
const double kOrigin[3] = { 0.3, -0.2, 0.1 };
const int kSize = 220;

vtkSmartPointer<vtkImageData> Block()
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(kDims[0], kDims[1], kDims[2]);
  image->SetSpacing(kSpacing[0], kSpacing[1], kSpacing[2]);
  image->SetOrigin(kOrigin[0], kOrigin[1], kOrigin[2]);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* rgb = vtkUnsignedCharArray::SafeDownCast(image->GetPointData()->GetScalars());
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i)
  {
    const unsigned char c[3] = { 210, 180, 90 };
    rgb->SetTypedTuple(i, c);
  }
  return image;
}

// The same block as an image whose extent starts at `start` (as the
// Wavelet source's, or an image's pieces over ranks), the origin moved so
// that its voxels lie where Block()'s do.
vtkSmartPointer<vtkImageData> BlockFrom(const int start[3])
{
  vtkSmartPointer<vtkImageData> image = Block();
  image->SetExtent(start[0], start[0] + kDims[0] - 1, start[1], start[1] + kDims[1] - 1, start[2],
    start[2] + kDims[2] - 1);
  image->SetOrigin(kOrigin[0] - start[0] * kSpacing[0], kOrigin[1] - start[1] * kSpacing[1],
    kOrigin[2] - start[2] * kSpacing[2]);
  return image;
}

// The same block as the cells of an image one point larger along each axis,
// whose cell centres lie where Block()'s points do, the colours cell data.
vtkSmartPointer<vtkImageData> BlockCells()
{
  vtkSmartPointer<vtkImageData> block = Block();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(kDims[0] + 1, kDims[1] + 1, kDims[2] + 1);
  image->SetSpacing(kSpacing[0], kSpacing[1], kSpacing[2]);
  image->SetOrigin(kOrigin[0] - 0.5 * kSpacing[0], kOrigin[1] - 0.5 * kSpacing[1], kOrigin[2] - 0.5 * kSpacing[2]);
  image->GetCellData()->SetScalars(block->GetPointData()->GetScalars());
  return image;
}

// The block's voxel centres on planes `planeStep` apart along z (3: the
// slices; 1: the slices and two filled planes between each two), with the
// lattice in the field-data array vtkSliceStackReader writes: origin, the
// three step vectors, the counts (octorayLattice.h).
vtkSmartPointer<vtkPolyData> BlockPoints(double planeStep)
{
  const int planes = static_cast<int>(std::lround((kDims[2] - 1) * kSpacing[2] / planeStep)) + 1;
  vtkNew<vtkPoints> points;
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetNumberOfComponents(3);
  for (int k = 0; k < planes; ++k)
  {
    for (int j = 0; j < kDims[1]; ++j)
    {
      for (int i = 0; i < kDims[0]; ++i)
      {
        points->InsertNextPoint(kOrigin[0] + i * kSpacing[0], kOrigin[1] + j * kSpacing[1], kOrigin[2] + k * planeStep);
        const unsigned char c[3] = { 210, 180, 90 };
        rgb->InsertNextTypedTuple(c);
      }
    }
  }
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  cloud->SetPoints(points);
  cloud->GetPointData()->SetScalars(rgb);
  vtkNew<vtkDoubleArray> lattice;
  lattice->SetName("PointLattice");
  lattice->SetNumberOfComponents(15);
  const double tuple[15] = { kOrigin[0], kOrigin[1], kOrigin[2], kSpacing[0], 0, 0, 0, kSpacing[1], 0, 0, 0,
    planeStep, double(kDims[0]), double(kDims[1]), double(planes) };
  lattice->InsertNextTuple(tuple);
  cloud->GetFieldData()->AddArray(lattice);
  return cloud;
}

void Save(const Picture& p, const std::string& file)
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(p.w, p.h, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  std::copy(p.rgb.begin(), p.rgb.end(), static_cast<unsigned char*>(image->GetScalarPointer()));
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(file.c_str());
  writer->Write();
}

struct View
{
  const char* Name;
  double Direction[3]; // from the camera towards the block
  double Up[3];
  bool Parallel;
};

void Aim(vtkRenderer* ren, const double bounds[6], const View& v)
{
  vtkCamera* camera = ren->GetActiveCamera();
  const double c[3] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5]) };
  camera->SetFocalPoint(c);
  camera->SetPosition(c[0] - 100 * v.Direction[0], c[1] - 100 * v.Direction[1], c[2] - 100 * v.Direction[2]);
  camera->SetViewUp(v.Up);
  camera->SetViewAngle(30);
  camera->SetParallelProjection(v.Parallel);
  ren->ResetCamera(bounds);
  const double margin = 10;
  const double wide[6] = { bounds[0] - margin, bounds[1] + margin, bounds[2] - margin, bounds[3] + margin,
    bounds[4] - margin, bounds[5] + margin };
  ren->ResetCameraClippingRange(wide);
}

// Pixels covered by VTK's drawing of the box `bounds` (in the image's index
// frame scaled by the spacing: `frame` maps it to the world) with view `v`
// of the block whose world bounds are `block` (the camera is aimed at them).
std::vector<char> BoxMask(const double block[6], const double bounds[6], vtkMatrix4x4* frame, const View& v)
{
  vtkNew<vtkCubeSource> cube;
  cube->SetBounds(bounds);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(cube->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->SetUserMatrix(frame);
  vtkNew<vtkRenderer> ren;
  ren->AddActor(actor);
  Aim(ren, block, v);
  vtkSmartPointer<vtkRenderWindow> window = Window(kSize, kSize);
  window->AddRenderer(ren);
  const Picture p = Capture(window);
  std::vector<char> mask(static_cast<size_t>(kSize) * kSize);
  for (size_t i = 0; i < mask.size(); ++i)
  {
    mask[i] = p.depth[i] < 1.0f;
  }
  return mask;
}

// The mask shrunk (r > 0) or grown (r < 0) by |r| pixels.
std::vector<char> Morph(const std::vector<char>& mask, int r)
{
  const int a = std::abs(r);
  std::vector<char> out(mask.size());
  for (int y = 0; y < kSize; ++y)
  {
    for (int x = 0; x < kSize; ++x)
    {
      bool all = true, any = false;
      for (int dy = -a; dy <= a; ++dy)
      {
        for (int dx = -a; dx <= a; ++dx)
        {
          const int nx = x + dx, ny = y + dy;
          const bool in = nx >= 0 && ny >= 0 && nx < kSize && ny < kSize && mask[static_cast<size_t>(ny) * kSize + nx];
          all = all && in;
          any = any || in;
        }
      }
      out[static_cast<size_t>(y) * kSize + x] = r > 0 ? all : any;
    }
  }
  return out;
}

const View kViews[] = {
  { "side (slice axis vertical, looking along +y)", { 0, 1, 0 }, { 0, 0, 1 }, false },
  { "side (looking along -x)", { -1, 0, 0 }, { 0, 0, 1 }, false },
  { "side, parallel projection", { 0, 1, 0 }, { 0, 0, 1 }, true },
  { "grazing (azimuth 20, elevation 4)", { std::sin(0.349), std::cos(0.349), -0.07 }, { 0, 0, 1 }, false },
  { "edge on a corner (azimuth 45)", { 0.7071, 0.7071, 0 }, { 0, 0, 1 }, false },
  { "above (looking along -z)", { 0, 0, -1 }, { 0, 1, 0 }, false },
};
}

int TestOctreeVolumeMapperSlices(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  vtkSmartPointer<vtkImageData> image = Block();
  // The same block turned 30 degrees about z and 20 about x (an oblique
  // acquisition): world-aligned leaves as large as a lattice cell's diagonal.
  vtkSmartPointer<vtkImageData> turned = Block();
  vtkNew<vtkTransform> turn;
  turn->RotateZ(30);
  turn->RotateX(20);
  double direction[9];
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      direction[3 * r + c] = turn->GetMatrix()->GetElement(r, c);
    }
  }
  turned->SetDirectionMatrix(direction);

  struct Case
  {
    const char* Name;
    vtkSmartPointer<vtkDataSet> Input;
    bool Fill;
    vtkIdType Points;
    double Leaf;
    bool RootBounds = false; // in a cube around larger bounds, as parallel ranks share
    bool Oblique = false;
    bool CellData = false; // the colours are cell scalars
  };
  const int start[3] = { -4, 7, 2 };
  const vtkIdType filled = kDims[0] * kDims[1] * ((kDims[2] - 1) * 3 + 1);
  const vtkIdType voxels = kDims[0] * kDims[1] * kDims[2];
  const Case cases[] = {
    { "image, filled between slices", image, true, filled, 1.0 },
    { "image, not filled", image, false, voxels, 3.0 },
    { "point set on the slices with its lattice", BlockPoints(3.0), true, voxels, 3.0 },
    { "point set of the filled planes with its lattice", BlockPoints(1.0), true, filled, 1.0 },
    { "image, filled, in the caller's root bounds", image, true, filled, 1.0, true },
    { "image turned obliquely, filled", turned, true, filled, std::sqrt(3.0), false, true },
    { "image whose extent starts at (-4, 7, 2), filled", BlockFrom(start), true, filled, 1.0 },
    { "image of cells coloured by cell scalars, filled", BlockCells(), true, filled, 1.0, false, false, true },
  };
  const std::string temporary = Argument(argc, argv, "-T", "");
  int caseNumber = 0;
  for (const Case& c : cases)
  {
    ++caseNumber;
    // The voxel centres' bounds: the input's points', or for cells those of
    // the block their centres make.
    double block[6];
    (c.CellData ? static_cast<vtkDataSet*>(image) : c.Input.Get())->GetBounds(block);
    // The box of the voxel centres in the image's frame, and that frame.
    const double local[6] = { 0, (kDims[0] - 1) * kSpacing[0], 0, (kDims[1] - 1) * kSpacing[1], 0,
      (kDims[2] - 1) * kSpacing[2] };
    vtkNew<vtkMatrix4x4> frame;
    for (int r = 0; r < 3; ++r)
    {
      for (int k = 0; k < 3; ++k)
      {
        frame->SetElement(r, k, c.Oblique ? direction[3 * r + k] : (r == k ? 1.0 : 0.0));
      }
      frame->SetElement(r, 3, kOrigin[r]);
    }
    vtkSmartPointer<vtkOctreeVolumeMapper> mapper = NewMapper(backend);
    mapper->SetInputData(c.Input);
    mapper->SetFillBetweenSlices(c.Fill);
    if (c.CellData)
    {
      mapper->SetScalarModeToUseCellData();
    }
    if (c.RootBounds)
    {
      mapper->SetRootBounds(block[0] - 3.7, block[1] + 11.2, block[2] - 0.4, block[3] + 5.5, block[4] - 7.9, block[5] + 1.3);
    }
    for (const View& v : kViews)
    {
      vtkNew<vtkRenderer> ren;
      ren->AddVolume(Volume(mapper));
      Aim(ren, block, v);
      vtkSmartPointer<vtkRenderWindow> window = Window(kSize, kSize);
      window->AddRenderer(ren);
      const Picture p = Capture(window);
      CHECK(DrewWith(mapper, backend));
      if (v.Parallel && !temporary.empty())
      {
        Save(p, temporary + "/TestOctreeVolumeMapperSlices-" + backend.Name() + "-case" + std::to_string(caseNumber) +
            "-side.png");
      }
      const double leaf = mapper->GetLeafSize();
      // Inside: the box of the voxel centres, shrunk by two pixels. Outside:
      // the box grown by a leaf (leaves reach past the centres), and by two
      // pixels.
      const std::vector<char> inside = Morph(BoxMask(block, local, frame, v), 2);
      const double grow = leaf * (c.Oblique ? std::sqrt(3.0) : 1.0); // a leaf's diagonal
      const double grown[6] = { local[0] - grow, local[1] + grow, local[2] - grow, local[3] + grow, local[4] - grow,
        local[5] + grow };
      const std::vector<char> near = Morph(BoxMask(block, grown, frame, v), -2);
      int holes = 0, insidePixels = 0, spilled = 0;
      for (int y = 0; y < kSize; ++y)
      {
        for (int x = 0; x < kSize; ++x)
        {
          const size_t i = static_cast<size_t>(y) * kSize + x;
          const bool drawn = p.Depth(x, y) < 1.0f;
          insidePixels += inside[i];
          if (inside[i] && (!drawn || (p.At(x, y)[0] == 0 && p.At(x, y)[1] == 0 && p.At(x, y)[2] == 0)))
          {
            if (holes++ < 3)
            {
              std::cerr << "  background at pixel " << x << "," << y << "\n";
            }
          }
          spilled += drawn && !near[i];
        }
      }
      std::cout << c.Name << ", " << v.Name << ": " << mapper->GetNumberOfOctreePoints() << " points, leaf "
                << leaf << ", " << insidePixels << " pixels inside the silhouette, " << holes
                << " of them background, " << spilled << " drawn outside\n";
      CHECK(insidePixels > kSize * kSize / 20);
      CHECK(holes == 0);
      CHECK(spilled == 0);
      CHECK(mapper->GetNumberOfOctreePoints() == c.Points);
      CHECK(std::abs(leaf - c.Leaf) < 1e-6 * c.Leaf);
    }
  }
  return Result();
}
