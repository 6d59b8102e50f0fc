"""A point-only PLY file with colours, opened as ParaView opens it (File >
Open: ParaView's PLY reader, vtkPLYReader), drawn by "Octree Volume" with its
own colours.

usage: plugin_ply_colours.py PLUGIN WORK_DIR

The file (written here with vtkPLYWriter: vertices only, red, green, blue
uchar properties) holds two squares of points side by side, one red and one
green. The reader gives polydata with an "RGB" point array; shown as "Octree
Volume" coloured by RGB with Map Scalars off and seen from the front, the
picture must hold both colours as drawn: at least 5 % of the pixels
reddish (r > 2 g, r > 2 b) and 5 % greenish (9 % each here), red left of
green.
"""
import os
import sys

import numpy as np
from paraview.simple import *  # noqa: F401,F403
from plugin_checks import front_view, screenshot_rgb
from vtkmodules.vtkCommonCore import vtkPoints, vtkUnsignedCharArray
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkIOPLY import vtkPLYWriter

plugin, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
LoadPlugin(plugin, remote=False, ns=globals())

points = vtkPoints()
colours = vtkUnsignedCharArray()
colours.SetNumberOfComponents(3)
colours.SetName("RGB")
for i in range(40):
    for j in range(40):
        for slab, rgb in ((0, (230, 20, 20)), (1, (20, 230, 20))):
            points.InsertNextPoint(slab * 1.5 + i / 40.0, j / 40.0, (i % 2) * 0.05)
            colours.InsertNextTuple3(*rgb)
cloud = vtkPolyData()
cloud.SetPoints(points)
cloud.GetPointData().SetScalars(colours)
path = os.path.join(work, "two_slabs.ply")
writer = vtkPLYWriter()
writer.SetFileName(path)
writer.SetInputData(cloud)
writer.SetArrayName("RGB")
writer.Write()

failures = []


def check(what, got, expected):
    print(f"{what}: {got} (expected {expected})")
    if got != expected:
        failures.append(what)


r = OpenDataFile(path)
check("reader", r.GetXMLName(), "PLYReader")
r.UpdatePipeline()
info = r.GetDataInformation()
check("points", info.GetNumberOfPoints(), 3200)
check("RGB array", "RGB" in r.PointData.keys(), True)
view = GetActiveViewOrCreate("RenderView")
d = Show(r, view)
d.SetRepresentationType("Octree Volume")
ColorBy(d, ("POINTS", "RGB"))
d.MapScalars = 0
d.LeafDepth = 6
front_view(view)
out = os.path.join(work, "two_slabs.png")
SaveScreenshot(out, view, ImageResolution=[300, 200])

rgb = screenshot_rgb(out)
h, w, _ = rgb.shape
red = (rgb[:, :, 0] > 2 * rgb[:, :, 1]) & (rgb[:, :, 0] > 2 * rgb[:, :, 2]) & (rgb[:, :, 0] > 60)
green = (rgb[:, :, 1] > 2 * rgb[:, :, 0]) & (rgb[:, :, 1] > 2 * rgb[:, :, 2]) & (rgb[:, :, 1] > 60)
print(f"reddish {100 * red.mean():.1f} %, greenish {100 * green.mean():.1f} % of the picture")
check("reddish pixels >= 5 %", red.mean() >= 0.05, True)
check("greenish pixels >= 5 %", green.mean() >= 0.05, True)
if red.any() and green.any():
    columns = np.arange(w)[None, :].repeat(h, axis=0)
    check("red slab left of the green one", columns[red].mean() < columns[green].mean(), True)

if failures:
    print("FAILED:", ", ".join(failures))
    sys.exit(1)
print("OK")
