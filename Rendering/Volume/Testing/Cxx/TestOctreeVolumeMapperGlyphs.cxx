// The surface picture and its depth against an independent reference: the
// mapper's own leaf voxels drawn by VTK's OpenGL pipeline as flat cubes of
// the leaf size. Outside the one-pixel band at voxel edges, every pixel has
// the same colour and a depth within 1e-4. Arguments: --projection
// perspective|parallel, --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkActor.h"
#include "vtkCubeSource.h"
#include "vtkGlyph3D.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"

using namespace octoray_test;

int TestOctreeVolumeMapperGlyphs(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const bool parallel = Argument(argc, argv, "--projection", "perspective") == "parallel";
  const int size = 300;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(250, 7);
  vtkSmartPointer<vtkOctreeVolumeMapper> mapper = NewMapper(backend);
  mapper->SetInputData(cloud);
  mapper->SetLeafDepth(4);
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(Volume(mapper));
  SetCamera(ren->GetActiveCamera(), parallel);
  vtkSmartPointer<vtkRenderWindow> window = Window(size, size);
  window->AddRenderer(ren);
  const Picture octree = Capture(window);
  CHECK(DrewWith(mapper, backend));

  vtkNew<vtkPolyData> leaves;
  mapper->GetLeafVoxels(leaves);
  CHECK(leaves->GetNumberOfPoints() > 50);
  vtkNew<vtkCubeSource> cube;
  const double side = mapper->GetLeafSize();
  cube->SetXLength(side);
  cube->SetYLength(side);
  cube->SetZLength(side);
  vtkNew<vtkGlyph3D> glyphs;
  glyphs->SetInputData(leaves);
  glyphs->SetSourceConnection(cube->GetOutputPort());
  glyphs->ScalingOff();
  glyphs->OrientOff();
  glyphs->SetColorModeToColorByScalar();
  vtkNew<vtkPolyDataMapper> glyphMapper;
  glyphMapper->SetInputConnection(glyphs->GetOutputPort());
  glyphMapper->SetColorModeToDirectScalars();
  vtkNew<vtkActor> actor;
  actor->SetMapper(glyphMapper);
  actor->GetProperty()->LightingOff();
  vtkNew<vtkRenderer> refRen;
  refRen->AddActor(actor);
  SetCamera(refRen->GetActiveCamera(), parallel);
  vtkSmartPointer<vtkRenderWindow> refWindow = Window(size, size);
  refWindow->AddRenderer(refRen);
  const Picture reference = Capture(refWindow);

  const std::vector<char> band = Band(reference);
  int compared = 0, coveredCompared = 0, colourMismatch = 0, depthMismatch = 0;
  double worstDepth = 0.0;
  for (int y = 0; y < size; ++y)
  {
    for (int x = 0; x < size; ++x)
    {
      if (band[static_cast<size_t>(y) * size + x])
      {
        continue;
      }
      ++compared;
      coveredCompared += reference.Depth(x, y) < 1.0f;
      if (!Same(octree.At(x, y), reference.At(x, y)) && colourMismatch++ < 5)
      {
        const unsigned char *a = octree.At(x, y), *b = reference.At(x, y);
        std::cerr << "pixel " << x << "," << y << ": octree " << int(a[0]) << " " << int(a[1]) << " " << int(a[2])
                  << ", cubes " << int(b[0]) << " " << int(b[1]) << " " << int(b[2]) << "\n";
      }
      const double dz = std::fabs(double(octree.Depth(x, y)) - reference.Depth(x, y));
      worstDepth = std::max(worstDepth, dz);
      depthMismatch += dz > 1e-4;
    }
  }
  const int covered = Covered(reference);
  std::cout << (parallel ? "parallel" : "perspective") << ": " << covered << " covered pixels, " << compared
            << " compared outside the band (" << coveredCompared << " of them covered), " << colourMismatch
            << " colour and " << depthMismatch << " depth mismatches, worst depth difference " << worstDepth << "\n";
  // Enough of the picture is compared for the test to mean something.
  CHECK(covered > size * size / 8);
  CHECK(compared > size * size / 2);
  CHECK(coveredCompared > covered / 2);
  CHECK(colourMismatch == 0);
  CHECK(depthMismatch == 0);
  return Result();
}
