"""Cropping of "Octree Volume" (UseCropping, CroppingOrigin, CroppingScale:
the properties and meaning of ParaView's Volume representation of images),
on one rank or under `mpiexec -np N pvbatch` with the data split over the
ranks.

usage: plugin_cropping.py PLUGIN WORK_DIR

Seen side-on in parallel projection, what is drawn must span the box
CroppingOrigin + bounds * CroppingScale along the cut axis, as a fraction
of the uncropped picture's span, within 1.5 voxels:
- points: a column of points 1 x 1 x 4 (9 x 9 x 33, written as a particle
  file, read on rank 0 and split by RedistributeDataSet), LeafDepth 5
  (voxels of the points' spacing); cut along z to [0, 2] (scale 0.5), then
  to [0.5, 2.5] (origin 0.5, scale 0.5), then UseCropping off again;
- an image (the Wavelet source, 10 x 10 x 40, its extent split along z
  over the ranks) with the cropping set on the display, which ParaView's
  Volume representation shares with "Octree Volume": cut along z to
  [-5, 15] (origin 5, scale 0.5).
What is drawn must also have no gap along the cut axis. The box is made
from the bounds of every rank's piece together: with each rank's own
bounds the ranks cut at different planes, and on 2 ranks the image's
z 0..5 was missing.
"""
import os
import sys

import numpy as np
from paraview.simple import *  # noqa: F401,F403
from plugin_checks import check, finish, screenshot_rgb

plugin, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
LoadPlugin(plugin, remote=True, ns=globals())

column = os.path.join(work, "column.particles")
with open(column, "w") as f:
    f.write("# x y z\n")
    for i in range(9):
        for j in range(9):
            for k in range(33):
                f.write("%g %g %g\n" % (i / 8.0, j / 8.0, k / 8.0))

view = CreateView("RenderView")
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [0, 0, 0]
view.EnableRenderOnInteraction = 0
view.UseFXAA = 0
view.CameraParallelProjection = 1


def drawn_span(name, axis):
    """The first and last drawn row (axis "rows") or column, and how many
    between them are drawn."""
    out = os.path.join(work, name + ".png")
    SaveScreenshot(out, view, ImageResolution=[300, 300])
    drawn = screenshot_rgb(out).max(axis=2) > 0
    lines = np.nonzero(drawn.any(axis=1 if axis == "rows" else 0))[0]
    return (lines[0], lines[-1] + 1, lines.size) if lines.size else (0, 0, 0)


def check_cut(what, span, full, lo, hi, voxel):
    """span, in pixels, against the fractions lo..hi of full, within 1.5
    voxels (a fraction of full too), and drawn without a gap."""
    length = float(full[1] - full[0])
    got = ((span[0] - full[0]) / length, (span[1] - full[0]) / length)
    print("%s: drawn from %.3f to %.3f of the uncropped span (expected %.3f to %.3f), %d of its %d lines"
          % (what, got[0], got[1], lo, hi, span[2], span[1] - span[0]))
    check(what, abs(got[0] - lo) <= 1.5 * voxel and abs(got[1] - hi) <= 1.5 * voxel)
    check(what + ": no gap", span[2] == span[1] - span[0])


# ---- Points: the column, side-on (looking along +y), z up the picture.
reader = OctorayParticleReader(FileNames=[column])
split = RedistributeDataSet(Input=reader)
d = Show(split, view)
d.SetRepresentationType("Octree Volume")
d.ColorArrayName = ["POINTS", ""]
d.LeafDepth = 5
d.Backend = "CPU"
view.CameraPosition = [0.5, -10, 2]
view.CameraFocalPoint = [0.5, 0, 2]
view.CameraViewUp = [0, 0, 1]
Render(view)  # the representation reports its bounds to the view
view.ResetCamera()
# screenshot_rgb's rows are VTK's, bottom first: row 0 is at z = 0.
full = drawn_span("column", "rows")
voxel = 1.0 / 32  # the root cube's side (4) over 2^5 leaves, over the column's height
check("uncropped: the column spans most of the picture", full[1] - full[0] > 200)
d.UseCropping = 1
d.CroppingScale = [1, 1, 0.5]
check_cut("points, scale 0.5 along z: z 0..2", drawn_span("column_scaled", "rows"), full, 0.0, 0.5, voxel)
d.CroppingOrigin = [0, 0, 0.5]
check_cut("points, origin 0.5 and scale 0.5 along z: z 0.5..2.5", drawn_span("column_moved", "rows"), full,
          (0.5 + 1.0 / 16) / 4.125, (2.5 + 1.0 / 16) / 4.125, voxel)
d.UseCropping = 0
check_cut("points, UseCropping off: the whole column", drawn_span("column_again", "rows"), full, 0.0, 1.0, voxel)
Hide(split, view)

# ---- An image: the Wavelet source, 10 x 10 x 40 (its extent split along z
# over the ranks), side-on like the column.
wavelet = Wavelet(WholeExtent=[-5, 5, -5, 5, -20, 20])
w = Show(wavelet, view)
w.SetRepresentationType("Octree Volume")
w.ColorArrayName = ["POINTS", ""]
w.Backend = "CPU"
view.CameraPosition = [0, -100, 0]
view.CameraFocalPoint = [0, 0, 0]
view.CameraViewUp = [0, 0, 1]
Render(view)
view.ResetCamera()
full = drawn_span("wavelet", "rows")
check("uncropped: the wavelet spans most of the picture", full[1] - full[0] > 200)
w.UseCropping = 1
w.CroppingOrigin = [0, 0, 5]
w.CroppingScale = [1, 1, 0.5]
# The voxels reach half a spacing past the bounds: the uncropped picture
# spans z -20.5..20.5, the cropped one -5..15. With each rank's own bounds
# the two halves would be cut at -5..5 and 5..15: z 0..5 missing.
check_cut("image, origin 5 and scale 0.5 along z: z -5..15", drawn_span("wavelet_cropped", "rows"), full,
          15.5 / 41, 35.5 / 41, 1.0 / 41)
finish()
