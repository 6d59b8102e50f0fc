"""A vtkStructuredGrid in "Octree Volume": offered and drawn as its points,
as the same points in an unstructured grid are.

usage: plugin_structured.py PLUGIN WORK_DIR

The Wavelet image through ParaView's Transform filter (a rotation) is a
vtkStructuredGrid. Its display must offer "Octree Volume" (before, the
representation type was refused without a word, though the warning for
undrawable data named vtkStructuredGrid among what it draws), and its
picture must be the picture of the same grid through Merge Blocks (an
unstructured grid of the same points), pixel for pixel, coloured by RTData;
and ParaView must not warn of a property exposed twice.
"""
import os
import sys

import numpy as np
from paraview.simple import *  # noqa: F401,F403
from plugin_checks import check, finish, screenshot_rgb

plugin, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
LoadPlugin(plugin, remote=False, ns=globals())

grid = Transform(Input=Wavelet())
grid.Transform.Rotate = [20, 30, 0]
grid.UpdatePipeline()
check("the Transform of an image is a vtkStructuredGrid (%s)" % grid.GetDataInformation().GetDataSetTypeAsString(),
      grid.GetDataInformation().GetDataSetTypeAsString() == "vtkStructuredGrid")
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [240, 200]
view.OrientationAxesVisibility = 0
view.UseFXAA = 0


def picture(source, name):
    d = Show(source, view)
    offered = d.GetProperty("Representation").Available
    d.SetRepresentationType("Octree Volume")
    ColorBy(d, ("POINTS", "RTData"))
    view.ResetCamera()
    path = os.path.join(work, name)
    SaveScreenshot(path, view, ImageResolution=[240, 200])
    Hide(source, view)
    return offered, d.Representation, screenshot_rgb(path)


from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow  # noqa: E402
paraview_window, said = vtkOutputWindow.GetInstance(), vtkStringOutputWindow()
vtkOutputWindow.SetInstance(said)
offered, shown, structured = picture(grid, "structured.png")
vtkOutputWindow.SetInstance(paraview_window)
check("the representation exposes each property once (%r)" % said.GetOutput().strip()[:300],
      "already exists" not in said.GetOutput())
check("Octree Volume is offered for a vtkStructuredGrid (%s)" % offered, "Octree Volume" in offered)
check("and shown (%s)" % shown, shown == "Octree Volume")
_, _, merged = picture(MergeBlocks(Input=grid), "merged.png")
background = structured[0, 0]
drawn = (np.abs(structured - background).max(axis=2) > 8).mean()
check("the grid's points cover %.1f %% of the picture" % (100 * drawn), drawn > 0.1)
check("the picture is the unstructured grid's of the same points (%d pixels differ)"
      % (structured != merged).any(axis=2).sum(), (structured == merged).all())
finish()
