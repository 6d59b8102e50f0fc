"""The "Octoray Particle Normals" filter (vtkParticleNormals, PCL) in
ParaView, feeding "Octree Volume" with Shade on.

usage: plugin_normals.py PLUGIN WORK_DIR

A plane of points, z = 0.3 x + 0.1 y over the unit square (80 x 80, each
point moved up to a quarter of the spacing within the plane, a fixed
pattern), without normals:
- the filter's normals lie within 1 degree of the plane's, every point has
  one, and they face the filter's ViewPoint (above the plane, then below);
- a Radius below the points' spacing leaves every point without one (the
  property reaches PCL);
- drawn white with Phong, seen from above, the plane with the filter's
  normals is evenly lit, as a plane under directional lights is: the
  drawn pixels' brightness spreads (standard deviation) by at most 4/255.
  Without normals, "Estimate Normals" (on by default) lights the voxels by
  the plane fitted to their neighbours: a spread of at most 10/255 (4.3
  here; the voxels' steps tilt some fits by a few degrees).
  With it off, they are lit by their occupancy, which follows the plane's
  steps: the spread must be at least three times the filter's.
The three screenshots side by side (occupancy, estimated, the filter's)
go to WORK_DIR/plane_side_by_side.png (the README's picture).
"""
import math
import os
import sys

import numpy as np
from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403
from plugin_checks import check, finish, screenshot_rgb, write_rgb
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData

plugin, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
LoadPlugin(plugin, remote=False, ns=globals())

SIDE = 80
points = vtkPoints()
for i in range(SIDE):
    for j in range(SIDE):
        x = (i + 0.25 * math.sin(7.0 * i + 3.0 * j)) / SIDE
        y = (j + 0.25 * math.cos(5.0 * i - 11.0 * j)) / SIDE
        points.InsertNextPoint(x, y, 0.3 * x + 0.1 * y)
cloud = vtkPolyData()
cloud.SetPoints(points)
up = np.array([-0.3, -0.1, 1.0]) / math.sqrt(1.1)

source = TrivialProducer()
source.GetClientSideObject().SetOutput(cloud)
normals = OctorayParticleNormals(Input=source, ViewPoint=[0.5, 0.5, 10.0])


def fetched_normals():
    out = dsa.WrapDataObject(servermanager.Fetch(normals))
    return np.asarray(out.PointData["Normals"])


n = fetched_normals()
lengths = np.linalg.norm(n, axis=1)
angles = np.degrees(np.arccos(np.clip(np.abs(n @ up) / np.maximum(lengths, 1e-30), -1.0, 1.0)))
print("largest angle to the plane's normal: %.4f degrees" % angles.max())
check("every point has a unit normal", bool(np.all(np.abs(lengths - 1.0) < 1e-4)))
check("every normal within 1 degree of the plane's", angles.max() < 1.0)
check("ViewPoint above: every normal faces up", bool(np.all(n @ up > 0)))
normals.ViewPoint = [0.5, 0.5, -10.0]
check("ViewPoint below: every normal faces down", bool(np.all(fetched_normals() @ up < 0)))
normals.ViewPoint = [0.5, 0.5, 10.0]
normals.Radius = 0.2 / SIDE
check("Radius below the spacing: no point has a normal", bool(np.all(fetched_normals() == 0)))
normals.Radius = 0.0

view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [300, 300]
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [0, 0, 0]
spreads, pictures = {}, {}
cases = (("occupancy", source, 0), ("estimated", source, 1), ("filter", normals, 1))
for name, shown, estimate in cases:
    for s in (normals, source):
        Hide(s, view)
    d = Show(shown, view)
    d.SetRepresentationType("Octree Volume")
    d.ColorArrayName = ["POINTS", ""]  # Solid Color: white
    d.OctreeShade = 1
    d.EstimateNormals = estimate
    d.LeafDepth = 6
    d.Backend = "CPU"
    view.CameraPosition = [0.5, 0.5, 5.0]
    view.CameraFocalPoint = [0.5, 0.5, 0.2]
    view.CameraViewUp = [0, 1, 0]
    view.ResetCamera()
    out = os.path.join(work, "plane_%s_normals.png" % name)
    SaveScreenshot(out, view, ImageResolution=[300, 300])
    rgb = pictures[name] = screenshot_rgb(out)
    drawn = rgb.max(axis=2) > 0
    brightness = rgb.mean(axis=2)[drawn]
    spreads[name] = brightness.std()
    print("%s normals: %.1f %% of the pixels drawn, brightness %.1f, spread %.2f (of 255)"
          % (name, 100 * drawn.mean(), brightness.mean(), spreads[name]))
    check("%s normals: the plane covers a third of the picture" % name, drawn.mean() > 0.33)
write_rgb(np.hstack([pictures[name] for name, _, _ in cases]), os.path.join(work, "plane_side_by_side.png"))
check("the filter's normals: spread <= 4/255", spreads["filter"] <= 4.0)
check("estimated normals: spread <= 10/255", spreads["estimated"] <= 10.0)
check("occupancy: spread >= 3 times the filter's", spreads["occupancy"] >= 3.0 * spreads["filter"])
finish()
