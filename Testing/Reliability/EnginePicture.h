// The CPU engine's picture of a poly data's points, shared by the
// reliability tests: an orthographic view down -z of the cube around the
// points, written as the inverse view-projection directly.
#pragma once

#include <octoray/Engine.h>

#include <vtkPolyData.h>

#include <algorithm>
#include <vector>

inline std::vector<float> EnginePicture(vtkPolyData* pd, int width, int height)
{
  const vtkIdType n = pd->GetNumberOfPoints();
  std::vector<float> xyz(3 * n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    double p[3];
    pd->GetPoint(i, p);
    for (int a = 0; a < 3; ++a)
      xyz[3 * i + a] = static_cast<float>(p[a]);
  }
  octoray::PointCloudView view;
  view.count = static_cast<size_t>(n);
  view.xyzFloat = xyz.data();
  auto engine = octoray::CreateEngine(octoray::Backend::CPU);
  engine->Build(view, octoray::BuildOptions{});
  octoray::RenderSettings s;
  s.width = width;
  s.height = height;
  double b[6];
  pd->GetBounds(b);
  const double c[3] = { (b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2 };
  const double r = std::max({ b[1] - b[0], b[3] - b[2], b[5] - b[4], 1e-6 });
  const double inv[16] = { r, 0, 0, c[0], 0, r, 0, c[1], 0, 0, -r, c[2], 0, 0, 0, 1 };
  std::copy(inv, inv + 16, s.inverseViewProjection);
  octoray::Image image;
  engine->Render(s, image);
  return image.rgba;
}
