"""Composite data of point sets drawn by "Octree Volume" as one point set,
as Merge Blocks would make it.

usage: plugin_composite.py PLUGIN WORK_DIR

Two squares of points side by side, each a particle file read as a block
of a multiblock dataset (Group Datasets), with a point array "value" (0 on
the left square, 1 on the right); the left one also has "left_only":
blocks whose arrays differ still merge, with the arrays they share (as
Merge Blocks does). Shown as
"Octree Volume" coloured by "value", the picture must equal, pixel for
pixel, that of the same points as one vtkPolyData shown alike in the same
view: with the default colour map the left square blue, the right one red.
Before, composite data drew nothing, with a warning to apply Merge Blocks.
Runs on one rank and on several (the blocks on rank 0, an empty piece on
the others).

On one rank, an update of the representation that hands over the same
blocks (a blend mode chosen) keeps the merged points and so the octree: no
build. Before, every update appended the blocks again and the mapper
rebuilt from the copy. A block whose points move in place is still a build.
"""
import os
import sys

import numpy as np
from paraview.simple import *  # noqa: F401,F403
from plugin_checks import check, finish, front_view, screenshot_rgb

plugin, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
LoadPlugin(plugin, remote=True, ns=globals())

import octoray  # noqa: E402,F401  (the build's Python package: the mapper's methods)


def square_file(name, slabs):
    """A particle file of the squares `slabs` (0: left, 1: right) with the
    column "value" (the slab), and "left only" where only the left is; read
    on rank 0 (the other ranks get an empty piece)."""
    path = os.path.join(work, name + ".particles")
    left_only = slabs == [0]
    with open(path, "w") as f:
        f.write("# x y z value" + (" left_only" if left_only else "") + "\n")
        for slab in slabs:
            for i in range(40):
                for j in range(40):
                    f.write("%g %g %g %g" % (slab * 1.5 + i / 40.0, j / 40.0, (i % 2) * 0.05, slab))
                    f.write(" %g\n" % (slab + 5.0) if left_only else "\n")
    return OctorayParticleReader(FileNames=[path])


view = GetActiveViewOrCreate("RenderView")
view.UseFXAA = 0
front_view(view)
group = GroupDatasets(Input=[square_file("left", [0]), square_file("right", [1])])
one = square_file("both", [0, 1])
pictures = {}
for name, shown in (("blocks", group), ("one polydata", one)):
    for s in (group, one):
        Hide(s, view)
    d = Show(shown, view)
    d.SetRepresentationType("Octree Volume")
    d.LeafDepth = 6
    d.Backend = "CPU"
    ColorBy(d, ("POINTS", "value"))
    d.RescaleTransferFunctionToDataRange(False, True)
    front_view(view)
    out = os.path.join(work, "composite_%s.png" % name.replace(" ", "_"))
    SaveScreenshot(out, view, ImageResolution=[300, 200])
    pictures[name] = screenshot_rgb(out)

rgb = pictures["blocks"]
red = (rgb[:, :, 0] > 2 * rgb[:, :, 2]) & (rgb[:, :, 0] > 60)
blue = (rgb[:, :, 2] > 2 * rgb[:, :, 0]) & (rgb[:, :, 2] > 60)
columns = np.arange(rgb.shape[1])[None, :].repeat(rgb.shape[0], axis=0)
print("blocks: reddish %.1f %%, bluish %.1f %% of the picture" % (100 * red.mean(), 100 * blue.mean()))
check("blocks: reddish and bluish pixels >= 5 % each", red.mean() >= 0.05 and blue.mean() >= 0.05)
check("blocks: the red square right of the blue one",
      red.any() and blue.any() and columns[red].mean() > columns[blue].mean())
differing = (np.abs(pictures["blocks"] - pictures["one polydata"]).max(axis=2) > 0).mean()
print("pixels differing from the one-polydata picture: %.4f %%" % (100 * differing))
check("blocks drawn as the same points in one polydata", differing == 0)

# The representation's own updates (a blend mode chosen) on one rank, where
# the blocks are drawn where they are. On more, the translucent modes hand
# the view new pieces to redistribute, and the mapper builds from those.
if servermanager.ActiveConnection.GetNumberOfDataPartitions() == 1:
    for s in (group, one):
        Hide(s, view)
    blocks = Show(group, view)
    Render(view)
    mapper = blocks.GetClientSideObject().GetActiveRepresentation().GetActor().GetMapper()

    def builds_for(*blend_modes):
        """The builds for blend modes chosen in turn, each rendered."""
        before = mapper.GetNumberOfBuilds()
        for mode in blend_modes:
            blocks.OctreeBlendMode = mode
            Render(view)
        return mapper.GetNumberOfBuilds() - before

    again = builds_for("Composite", "Surface")
    check("the same blocks updated twice: %d builds (0)" % again, again == 0)
    points = group.GetClientSideObject().GetOutputDataObject(0).GetBlock(0).GetPoints()
    for i in range(points.GetNumberOfPoints()):
        x, y, z = points.GetPoint(i)
        points.SetPoint(i, x, y + 0.25, z)
    points.Modified()
    moved = builds_for("Composite")
    check("a block moved in place, then updated: %d builds (1)" % moved, moved == 1)
finish()
