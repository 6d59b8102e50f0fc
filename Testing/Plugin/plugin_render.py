"""The "Octree Volume" representation in pvbatch: shows the bundled LiDAR
particles (split over the ranks with RedistributeDataSet), saves a
screenshot and compares it with a baseline.

usage: plugin_render.py PLUGIN DATA_DIR OUTPUT.png [BASELINE.png]

Tolerance: at most 1 % of the pixels may differ by more than 32 (of 255) in
any channel. Serial and parallel runs compare with the same baseline.
"""
import sys

from paraview.simple import *  # noqa: F401,F403

plugin, data, output = sys.argv[1:4]
baseline = sys.argv[4] if len(sys.argv) > 4 else None
LoadPlugin(plugin, remote=True, ns=globals())

reader = OctorayParticleReader(FileNames=[data + "/Particles/lidar_simple.particles"])
# The data split over the ranks (a pass-through on one rank).
split = RedistributeDataSet(Input=reader)
view = CreateView("RenderView")
view.ViewSize = [400, 300]
view.OrientationAxesVisibility = 0
view.Background = [0.1, 0.1, 0.15]
display = Show(split, view)
display.SetRepresentationType("Octree Volume")
ColorBy(display, ("POINTS", "Colors"))
display.MapScalars = 0
display.OctreeBlendMode = "Surface"
display.OctreeShade = 1  # Phong
display.LeafDepth = 6    # fixed: the same voxels whatever each rank holds
display.Backend = "CPU"  # the reference backend, also on a GPU machine
view.ResetCamera()
camera = view.GetActiveCamera()
camera.Elevation(35)
camera.Azimuth(20)
view.ResetCamera()
SaveScreenshot(output, view, ImageResolution=[400, 300])
print("saved", output)

if baseline:
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    import numpy as np

    def load(path):
        r = vtkPNGReader()
        r.SetFileName(path)
        r.Update()
        img = r.GetOutput()
        a = vtk_to_numpy(img.GetPointData().GetScalars()).astype(int)
        return img.GetDimensions(), a[:, :3]

    dims, got = load(output)
    bdims, want = load(baseline)
    if dims != bdims:
        print(f"size {dims} differs from the baseline's {bdims}")
        sys.exit(1)
    bad = (np.abs(got - want).max(axis=1) > 32).mean()
    drawn = (np.abs(want - want[0]).max(axis=1) > 0).mean()
    print(f"pixels differing by > 32: {100 * bad:.3f} % (tolerance 1 %); "
          f"octree covers {100 * drawn:.1f} % of the baseline")
    if bad > 0.01 or drawn < 0.05:
        sys.exit(1)
print("OK")
