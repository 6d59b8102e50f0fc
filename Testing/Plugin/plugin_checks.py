"""Named checks for the plugin tests: each is printed and all are run, and
finish() exits non-zero when any failed. (The test's own folder is on
sys.path, so a test imports this as plugin_checks.)"""
import sys

failures = []


def check(what, ok):
    print("%s: %s" % ("ok" if ok else "FAILED", what))
    if not ok:
        failures.append(what)


def finish():
    if failures:
        print("%d check(s) failed" % len(failures))
        sys.exit(1)
    print("OK")


def front_view(view, focus=(1.25, 0.5, 0.0), size=(300, 200)):
    """`view` black, without axes, `size` pixels, looking down -z at `focus`
    (the two squares of points side by side that the colour tests draw,
    x 0..2.5, y 0..1) and fitted to what it shows."""
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [0, 0, 0]
    view.CameraPosition = [focus[0], focus[1], focus[2] + 6]
    view.CameraFocalPoint = list(focus)
    view.CameraViewUp = [0, 1, 0]
    view.ResetCamera()


def screenshot_rgb(path):
    """A PNG's colours as a (height, width, 3) array of ints, the bottom row
    first (VTK's order)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader
    png = vtkPNGReader()
    png.SetFileName(path)
    png.Update()
    w, h, _ = png.GetOutput().GetDimensions()
    return vtk_to_numpy(png.GetOutput().GetPointData().GetScalars())[:, :3].astype(int).reshape(h, w, 3)


def write_rgb(rgb, path):
    """A (height, width, 3) array in screenshot_rgb's order as a PNG."""
    import numpy as np
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter
    h, w, _ = rgb.shape
    image = vtkImageData()
    image.SetDimensions(w, h, 1)
    image.GetPointData().SetScalars(numpy_to_vtk(rgb.reshape(-1, 3).astype(np.uint8), deep=True))
    png = vtkPNGWriter()
    png.SetFileName(path)
    png.SetInputData(image)
    png.Write()
