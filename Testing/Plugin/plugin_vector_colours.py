"""A vector array drawn by "Octree Volume" coloured by its Magnitude and by
one component, as ParaView's colour map offers them (the colour function's
VectorMode and VectorComponent).

usage: plugin_vector_colours.py PLUGIN WORK_DIR

Two squares of points side by side carry a 3-component "Velocity": the
left one (1, 0, 0), the right one (0, 3, 0). Seen from the front with the
default colour map (blue at the low end of the range, red at the high):
- by Magnitude (ParaView's default for vectors; range 1..3) the left square
  is blue and the right one red;
- by X (range 0..1) the left square is red and the right one blue;
- by Y (range 0..3) as by Magnitude.
Each picture must have at least 5 % of its pixels reddish (r > 2 b) and 5 %
bluish (b > 2 r), the red side where the colouring puts it. Before the
mapper read the colour map's vector mode it drew component 0 whatever the
colour map said: by Magnitude, red left of blue.
"""
import os
import sys

import numpy as np
from paraview.simple import *  # noqa: F401,F403
from plugin_checks import front_view, screenshot_rgb
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData

plugin, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
LoadPlugin(plugin, remote=False, ns=globals())

points = vtkPoints()
velocity = []
for i in range(40):
    for j in range(40):
        for slab, v in ((0, (1.0, 0.0, 0.0)), (1, (0.0, 3.0, 0.0))):
            points.InsertNextPoint(slab * 1.5 + i / 40.0, j / 40.0, (i % 2) * 0.05)
            velocity.append(v)
cloud = vtkPolyData()
cloud.SetPoints(points)
dsa.WrapDataObject(cloud).PointData.append(np.array(velocity), "Velocity")

failures = []


def check(what, got, expected):
    print(f"{what}: {got} (expected {expected})")
    if got != expected:
        failures.append(what)


source = TrivialProducer()
source.GetClientSideObject().SetOutput(cloud)
view = GetActiveViewOrCreate("RenderView")
d = Show(source, view)
d.SetRepresentationType("Octree Volume")
d.LeafDepth = 6
front_view(view)

for colouring, red_side in (("Magnitude", "right"), ("X", "left"), ("Y", "right")):
    ColorBy(d, ("POINTS", "Velocity", colouring))
    d.RescaleTransferFunctionToDataRange(False, True)
    out = os.path.join(work, f"velocity_{colouring}.png")
    SaveScreenshot(out, view, ImageResolution=[300, 200])
    rgb = screenshot_rgb(out)
    h, w, _ = rgb.shape
    red = (rgb[:, :, 0] > 2 * rgb[:, :, 2]) & (rgb[:, :, 0] > 60)
    blue = (rgb[:, :, 2] > 2 * rgb[:, :, 0]) & (rgb[:, :, 2] > 60)
    print(f"by {colouring}: reddish {100 * red.mean():.1f} %, bluish {100 * blue.mean():.1f} % of the picture")
    check(f"by {colouring}: reddish pixels >= 5 %", red.mean() >= 0.05, True)
    check(f"by {colouring}: bluish pixels >= 5 %", blue.mean() >= 0.05, True)
    if red.any() and blue.any():
        columns = np.arange(w)[None, :].repeat(h, axis=0)
        side = "left" if columns[red].mean() < columns[blue].mean() else "right"
        check(f"by {colouring}: the red square's side", side, red_side)

if failures:
    print("FAILED:", ", ".join(failures))
    sys.exit(1)
print("OK")
