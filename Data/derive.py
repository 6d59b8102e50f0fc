#!/usr/bin/python3
"""How the files in Data/ were made from their upstream packages (see
Data/README.md). Not run by the build; kept so that the derivation can be
repeated:

    mkdir /tmp/dl && cd /tmp/dl
    pip download --no-deps pydicom==2.4.4
    pip download --no-deps --only-binary=:all: --python-version 3.11 \
        --platform manylinux_2_17_x86_64 scikit-image==0.22.0
    pip download --no-deps --no-binary=:all: laspy==2.5.4
    unzip -q pydicom-2.4.4-py3-none-any.whl -d pyd
    unzip -q scikit_image-0.22.0-*.whl -d ski
    tar xzf laspy-2.5.4.tar.gz
    PYTHONPATH=/tmp/dl/laspy-2.5.4 /usr/bin/python3 Data/derive.py /tmp/dl
"""
import os
import shutil
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk

dl = sys.argv[1]
here = os.path.dirname(os.path.abspath(__file__))


def write_png(path, array):
    """array: rows top to bottom, (h, w) or (h, w, c); uint8 or uint16."""
    h, w = array.shape[:2]
    comps = 1 if array.ndim == 2 else array.shape[2]
    image = vtk.vtkImageData()
    image.SetDimensions(w, h, 1)
    # VTK images start at the bottom row.
    flat = np.ascontiguousarray(array[::-1]).reshape(h * w, comps)
    image.GetPointData().SetScalars(numpy_to_vtk(flat, deep=1))
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()


# DICOM: a 5-slice CT series and a single CT slice, copied unchanged.
tests = os.path.join(dl, "pyd/pydicom/data/test_files")
for name in ["2062", "2392", "2693", "3023", "3353"]:
    shutil.copy(os.path.join(tests, "dicomdirtests/98892001/CT5N", name),
                os.path.join(here, "DICOM/CT5N", name + ".dcm"))
shutil.copy(os.path.join(tests, "CT_small.dcm"), os.path.join(here, "DICOM/CT_small/CT_small.dcm"))

# Depth map: Middlebury 2014 "Motorcycle" ground-truth disparity as shipped by
# scikit-image (741x500), every 2nd pixel, converted to depth in millimetres:
#   Z = f * B / (d + doffs), f = 994.978 px, B = 193.001 mm, doffs = 31.086 px.
disp = np.load(os.path.join(dl, "ski/skimage/data/motorcycle_disp.npz"))["arr_0"][::2, ::2]
depth = 994.978 * 193.001 / (disp + 31.086)
depth[~np.isfinite(disp)] = 0
depth_mm = np.round(depth).astype(np.uint16)
write_png(os.path.join(here, "DepthMaps/motorcycle_depth_mm.png"), depth_mm)
left = vtk.vtkPNGReader()
left.SetFileName(os.path.join(dl, "ski/skimage/data/motorcycle_left.png"))
left.Update()
li = left.GetOutput()
w, h, _ = li.GetDimensions()
from vtk.util.numpy_support import vtk_to_numpy
rgb = vtk_to_numpy(li.GetPointData().GetScalars()).reshape(h, w, -1)[::-1]
write_png(os.path.join(here, "DepthMaps/motorcycle_left.png"), np.ascontiguousarray(rgb[::2, ::2, :3]))

# Scanned point cloud: libLAS's simple.las (airborne LiDAR with RGB) as
# shipped in laspy's source distribution, written as text.
import laspy  # noqa: E402

las = laspy.read(os.path.join(dl, "laspy-2.5.4/tests/data/simple.las"))
xyz = np.column_stack([las.x, las.y, las.z])
rgb = np.column_stack([las.red, las.green, las.blue]).astype(int)
intensity = np.asarray(las.intensity, dtype=float)
with open(os.path.join(here, "PointClouds/simple_las.xyzrgbi"), "w") as f:
    f.write("# x y z r g b intensity\n")
    for p, c, i in zip(xyz, rgb, intensity):
        f.write("%.2f %.2f %.2f %d %d %d %d\n" % (p[0], p[1], p[2], c[0], c[1], c[2], i))

# The same scan in the thesis format: x y z r g b reflectivity refraction.
# Reflectivity is the LiDAR return intensity scaled to 0..1 (a stand-in: LAS
# intensity is the strength of the return, not a material reflectivity);
# refraction 0 = none.
with open(os.path.join(here, "Particles/lidar_simple.particles"), "w") as f:
    f.write("# x y z r g b reflectivity refraction\n")
    for p, c, i in zip(xyz, rgb, intensity / 255.0):
        f.write("%.2f %.2f %.2f %d %d %d %.4f 0\n" % (p[0], p[1], p[2], c[0], c[1], c[2], min(i, 1.0)))
