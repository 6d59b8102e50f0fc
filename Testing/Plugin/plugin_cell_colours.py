"""An image coloured by a cell array in "Octree Volume": each cell a voxel
with its value, as ParaView's Volume representation draws cell data.

usage: plugin_cell_colours.py PLUGIN WORK_DIR

A flat image of 40 x 20 cells (41 x 21 points) holds a cell array "side":
1 in the left half, 2 in the right (above the default ImageBackground, 0). Coloured by it (CELLS) with the default
colour map and seen from the front, the left half must be bluish and the
right half reddish (at least 10 % of the picture each, the red right of
the blue). Before, the mapper drew the voxels without the cell values
(white) and warned that cell scalars are not supported.
"""
import os
import sys

import numpy as np
from paraview.simple import *  # noqa: F401,F403
from plugin_checks import check, finish, front_view, screenshot_rgb
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.vtkCommonDataModel import vtkImageData

plugin, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
LoadPlugin(plugin, remote=False, ns=globals())

image = vtkImageData()
image.SetDimensions(41, 21, 1)
image.SetSpacing(1.0 / 16, 1.0 / 16, 1.0)
side = np.array([2.0 if i >= 20 else 1.0 for j in range(20) for i in range(40)])
dsa.WrapDataObject(image).CellData.append(side, "side")

source = TrivialProducer()
source.GetClientSideObject().SetOutput(image)
view = GetActiveViewOrCreate("RenderView")
d = Show(source, view)
d.SetRepresentationType("Octree Volume")
ColorBy(d, ("CELLS", "side"))
d.RescaleTransferFunctionToDataRange(False, True)
front_view(view)
out = os.path.join(work, "cell_colours.png")
SaveScreenshot(out, view, ImageResolution=[300, 200])
rgb = screenshot_rgb(out)
red = (rgb[:, :, 0] > 2 * rgb[:, :, 2]) & (rgb[:, :, 0] > 60)
blue = (rgb[:, :, 2] > 2 * rgb[:, :, 0]) & (rgb[:, :, 2] > 60)
columns = np.arange(rgb.shape[1])[None, :].repeat(rgb.shape[0], axis=0)
print("reddish %.1f %%, bluish %.1f %% of the picture" % (100 * red.mean(), 100 * blue.mean()))
check("reddish and bluish pixels >= 10 % each", red.mean() >= 0.1 and blue.mean() >= 0.1)
check("the red half right of the blue one", red.any() and blue.any() and columns[red].mean() > columns[blue].mean())
finish()
