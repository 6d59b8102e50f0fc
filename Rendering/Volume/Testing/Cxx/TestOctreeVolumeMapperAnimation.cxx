// Moving points for N frames (--frames N, default 100) gives the pictures of
// building from scratch at each frame. Left renderer: one mapper, updated in
// place; right renderer: a new mapper per frame. Eight fixed corner points
// keep the bounds, and so the root cube, the same for both. --backend
// cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkRenderer.h"

using namespace octoray_test;

int TestOctreeVolumeMapperAnimation(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const int frames = std::stoi(Argument(argc, argv, "--frames", "100"));
  const int w = 160, h = 160;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(600, 21);
  vtkPoints* points = cloud->GetPoints();
  auto* colors = vtkUnsignedCharArray::SafeDownCast(cloud->GetPointData()->GetScalars());
  const unsigned char white[3] = { 255, 255, 255 };
  for (int corner = 0; corner < 8; ++corner)
  {
    points->InsertNextPoint(corner & 1 ? 1.2 : -1.2, corner & 2 ? 1.2 : -1.2, corner & 4 ? 1.2 : -1.2);
    colors->InsertNextTypedTuple(white);
  }
  std::vector<double> base(3 * 600);
  for (vtkIdType i = 0; i < 600; ++i)
  {
    points->GetPoint(i, &base[3 * i]);
  }
  vtkSmartPointer<vtkOctreeVolumeMapper> animated = NewMapper(backend);
  animated->SetInputData(cloud);
  animated->SetLeafDepth(5);
  vtkNew<vtkRenderer> left;
  left->SetViewport(0, 0, 0.5, 1);
  left->AddVolume(Volume(animated));
  SetCamera(left->GetActiveCamera());
  vtkNew<vtkRenderer> right;
  right->SetViewport(0.5, 0, 1, 1);
  SetCamera(right->GetActiveCamera());
  vtkSmartPointer<vtkRenderWindow> window = Window(2 * w, h);
  window->AddRenderer(left);
  window->AddRenderer(right);
  auto moveTo = [&](int frame) {
    const double t = 0.05 * frame;
    for (vtkIdType i = 0; i < 600; ++i)
    {
      const double* b = &base[3 * i];
      points->SetPoint(
        i, b[0] * 0.9 + 0.08 * std::sin(t + i), b[1] * 0.9 + 0.08 * std::cos(1.3 * t + i), b[2] * 0.9);
    }
    points->Modified();
  };
  int differing = 0, emptyFrames = 0, notByBackend = 0;
  for (int frame = 0; frame < frames; ++frame)
  {
    moveTo(frame);
    // A fresh copy, so that the right mapper builds from scratch.
    vtkNew<vtkPolyData> copy;
    copy->DeepCopy(cloud);
    vtkSmartPointer<vtkOctreeVolumeMapper> fresh = NewMapper(backend);
    fresh->SetInputData(copy);
    fresh->SetLeafDepth(5);
    right->RemoveAllViewProps();
    right->AddVolume(Volume(fresh));
    const Picture p = Capture(window);
    notByBackend += !DrewWith(animated, backend) || !DrewWith(fresh, backend);
    int covered = 0;
    for (int y = 0; y < h; ++y)
    {
      for (int x = 0; x < w; ++x)
      {
        differing += !Same(p.At(x, y), p.At(x + w, y));
        covered += p.Depth(x, y) < 1.0f;
      }
    }
    emptyFrames += covered < 1000;
  }
  std::cout << "animation: " << frames << " frames, " << animated->GetNumberOfBuilds() << " build(s), "
            << animated->GetNumberOfUpdates() << " updates, " << differing << " differing pixels\n";
  CHECK(notByBackend == 0);
  CHECK(animated->GetNumberOfBuilds() == 1);
  CHECK(animated->GetNumberOfUpdates() == frames - 1);
  CHECK(differing == 0);
  CHECK(emptyFrames == 0);

  // A mapper that keeps no points (KeepPointsForUpdates off) rebuilds the
  // moved points, with the same pictures as the updated mapper.
  vtkSmartPointer<vtkOctreeVolumeMapper> lean = NewMapper(backend);
  lean->KeepPointsForUpdatesOff();
  lean->SetInputData(cloud);
  lean->SetLeafDepth(5);
  right->RemoveAllViewProps();
  right->AddVolume(Volume(lean));
  int leanDiffering = 0;
  for (int frame = frames; frame < frames + 3; ++frame)
  {
    moveTo(frame);
    const Picture p = Capture(window);
    for (int y = 0; y < h; ++y)
    {
      for (int x = 0; x < w; ++x)
      {
        leanDiffering += !Same(p.At(x, y), p.At(x + w, y));
      }
    }
  }
  std::cout << "without kept points: " << lean->GetNumberOfBuilds() << " builds, " << lean->GetNumberOfUpdates()
            << " updates, " << leanDiffering << " differing pixels\n";
  CHECK(DrewWith(lean, backend));
  CHECK(lean->GetNumberOfBuilds() == 3 && lean->GetNumberOfUpdates() == 0);
  CHECK(leanDiffering == 0);
  return Result();
}
