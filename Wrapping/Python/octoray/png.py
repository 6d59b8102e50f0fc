"""PNG files as numpy arrays of shape (height, width[, components]), top row
first as people and image tools count rows (VTK's images start at the
bottom row). For tests, scripts and the data checks."""
import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy


def read_png(path):
    """The picture at path: (height, width, components), top row first."""
    reader = vtk.vtkPNGReader()
    reader.SetFileName(str(path))
    reader.Update()
    image = reader.GetOutput()
    w, h, _ = image.GetDimensions()
    if w * h == 0:
        raise IOError("cannot read PNG file '%s'" % path)
    return vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, -1)[::-1]


def write_png(path, rows):
    """rows: (height, width[, components]), uint8 or uint16, top row first."""
    h, w = rows.shape[:2]
    image = vtk.vtkImageData()
    image.SetDimensions(w, h, 1)
    flipped = np.ascontiguousarray(rows[::-1]).reshape(h * w, -1)
    image.GetPointData().SetScalars(numpy_to_vtk(flipped, deep=1))
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(str(path))
    writer.SetInputData(image)
    writer.Write()
    if writer.GetErrorCode():
        raise IOError("cannot write PNG file '%s'" % path)
