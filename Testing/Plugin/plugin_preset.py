"""The "Octree Volume" representation's CT Preset in pvbatch, on the head CT
of Data/External (the reader's image output):

- the panel offers "none" and exactly the names vtkOctreeVolumePresets has;
- the image's panel has Image Background and Fill Between Slices, the
  reader's particles' panel (point data) neither, but the CT Preset;
- a preset puts its own colour and opacity functions (the documented
  control points) on the volume and the preset's surface threshold on the
  mapper, overriding ImageBackground; "none" gives back ParaView's colour
  map, opacity function and the ImageBackground set in the panel;
- the pictures: bone-coloured (red > green > blue) with ct-bone, different
  from the picture without a preset, and no warning that a gradient
  opacity is not applied (the preset's copy of ParaView's property has
  VTK's default, 1 everywhere);
- an unknown name is an error and leaves no preset;
- a preset on a display left at Solid Color maps the image's active
  scalars: ct-bone's picture.

usage: plugin_preset.py PLUGIN DATA_DIR OUTPUT_DIR
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403

from plugin_checks import check, finish

plugin, data, out = sys.argv[1:4]
LoadPlugin(plugin, remote=False, ns=globals())
import octoray  # noqa: E402  (the build's Python package, on PYTHONPATH)

known = [octoray.vtkOctreeVolumePresets.GetName(i) for i in range(octoray.vtkOctreeVolumePresets.GetNumberOfPresets())]

reader = OctoraySliceFolderReader(DirectoryName=os.path.join(data, "External", "HeadCT", "DICOM"))
view = CreateView("RenderView")
view.ViewSize = [320, 320]
view.OrientationAxesVisibility = 0
view.Background = [0.1, 0.1, 0.15]
display = Show(OutputPort(reader, 1), view)
display.SetRepresentationType("Octree Volume")
ColorBy(display, ("POINTS", "Scalars"))
display.OctreeShade = 1
display.Backend = "CPU"
display.ImageBackground = 100.0

domain = display.GetProperty("Preset").SMProperty.FindDomain("vtkSMStringListDomain")
offered = [domain.GetString(i) for i in range(domain.GetNumberOfStrings())]
check("the panel offers none + %s (got %s)" % (known, offered), offered == ["none"] + known)
check("the default is none", display.Preset == "none")

particles = Show(OutputPort(reader, 0), view)
image_only = ["ImageBackground", "FillBetweenSlices"]
check("the image's panel has %s" % image_only, all(p in display.ListProperties() for p in image_only))
check("the particles' panel has neither, but the preset",
      not any(p in particles.ListProperties() for p in image_only) and "Preset" in particles.ListProperties())
Hide(OutputPort(reader, 0), view)

view.ResetCamera()
camera = view.GetActiveCamera()
camera.Elevation(-80)  # the face: the CT's anterior is -y
view.ResetCamera()


def picture(name):
    path = os.path.join(out, name)
    SaveScreenshot(path, view, ImageResolution=[320, 320])
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    r = vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    return vtk_to_numpy(r.GetOutput().GetPointData().GetScalars())[:, :3].astype(int)


# The Octree Volume representation (client-server wrapped only: reached as
# its ParaView base class, whose actor holds the mapper and the property).
representation = display.GetClientSideObject().GetActiveRepresentation()
actor = representation.GetActor()
plain = picture("preset_none.png")
mapper = actor.GetMapper()
check("the mapper is octoray's (%s)" % mapper.GetClassName(), isinstance(mapper, octoray.vtkOctreeVolumeMapper))
check("without a preset the panel's ImageBackground (100) is used", mapper.GetImageBackground() == 100.0)
paraview_colour = actor.GetProperty().GetRGBTransferFunction(0)

display.Preset = "ct-bone"
# What the mapper says while it draws the preset, in a string window.
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow  # noqa: E402
paraview_window, said = vtkOutputWindow.GetInstance(), vtkStringOutputWindow()
vtkOutputWindow.SetInstance(said)
bone = picture("preset_ct-bone.png")
vtkOutputWindow.SetInstance(paraview_window)
check("ct-bone draws without a word of gradient opacity (the preset copies ParaView's property, whose "
      "gradient opacity is 1 everywhere): %r" % said.GetOutput(), "gradient opacity" not in said.GetOutput())
threshold = octoray.vtkOctreeVolumePresets.GetSurfaceThreshold("ct-bone")
check("ct-bone sets the mapper's ImageBackground to its threshold %g (got %g)"
      % (threshold, mapper.GetImageBackground()), mapper.GetImageBackground() == threshold)
prop = actor.GetProperty()
colour, opacity = prop.GetRGBTransferFunction(0), prop.GetScalarOpacity(0)
nodes = []
for i in range(colour.GetSize()):
    v = [0.0] * 6
    colour.GetNodeValue(i, v)
    nodes.append(tuple(round(x, 4) for x in v))
check("ct-bone's colour points: %s" % nodes,
      nodes == [(-3024, 0, 0, 0, 0.5, 0), (-16, 0.73, 0.25, 0.3, 0.49, 0.61), (641, 0.9, 0.82, 0.56, 0.5, 0),
                (3071, 1, 1, 1, 0.5, 0)])
opoints = []
for i in range(opacity.GetSize()):
    v = [0.0] * 4
    opacity.GetNodeValue(i, v)
    opoints.append(tuple(round(x, 4) for x in v[:2]))
check("ct-bone's opacity points: %s" % opoints, opoints == [(-3024, 0), (-16, 0), (641, 0.72), (3071, 0.71)])
check("the preset does not change ParaView's colour map", colour is not paraview_colour)
drawn = (abs(bone - bone[0]).max(axis=1) > 0)
check("ct-bone draws (%.1f %% of the picture)" % (100 * drawn.mean()), drawn.mean() > 0.05)
mean = bone[drawn].mean(axis=0)
check("ct-bone is bone-coloured: mean RGB %s has red > green > blue" % mean.round(), mean[0] > mean[1] > mean[2])
check("the ct-bone picture differs from the one without a preset", (abs(bone - plain).max(axis=1) > 32).mean() > 0.05)

display.Preset = "ct-skin"
picture("preset_ct-skin.png")
check("ct-skin's threshold on the mapper", mapper.GetImageBackground() == -750.0)

display.Preset = "none"
again = picture("preset_none_again.png")
check("none gives back the panel's ImageBackground", mapper.GetImageBackground() == 100.0)
check("none gives back ParaView's colour map",
      actor.GetProperty().GetRGBTransferFunction(0) is paraview_colour)
check("none draws as before the preset", (abs(again - plain).max(axis=1) > 32).mean() < 0.01)

display.Preset = "ct-skin"
picture("preset_ct-skin_again.png")
display.Preset = "no-such-preset"  # an error on the server (printed), not an exception here
picture("preset_unknown.png")
check("an unknown name leaves no preset: the panel's ImageBackground",
      mapper.GetImageBackground() == 100.0)
check("an unknown name leaves no preset: ParaView's colour map",
      actor.GetProperty().GetRGBTransferFunction(0) is paraview_colour)

# As the README writes it: the preset on a display left at Solid Color maps
# the image's active scalars (the picture is ct-bone's, not empty).
ColorBy(display, None)
display.Preset = "ct-bone"
solid = picture("preset_ct-bone_solid_color.png")
check("ct-bone with Solid Color draws ct-bone's picture (%.2f %% of the pixels off by more than 32)"
      % (100 * (abs(solid - bone).max(axis=1) > 32).mean()), (abs(solid - bone).max(axis=1) > 32).mean() < 0.01)

finish()
