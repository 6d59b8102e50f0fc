#!/usr/bin/python3
"""Checks Data/External/HeadCT with the project's reader and with pydicom,
and draws its mid-sagittal and mid-axial slices (not run by make data; it
needs the build):

    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 \\
        scripts/data/check_headct.py [Data/External/HeadCT] [build/headct-check.png]

vtkSliceStackReader reads the DICOM series (ordered by image position) and
the PNG slices; pydicom reads the DICOM files on its own. All three must give
the same volume: HU from the DICOM files (the PNG values are HU + png_offset,
rows bottom-up as the reader stores pictures), the geometry of volume.json.
"""
import glob
import json
import os
import sys

import numpy as np
import pydicom
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import octoray

here = sys.argv[1] if len(sys.argv) > 1 else "Data/External/HeadCT"
picture = sys.argv[2] if len(sys.argv) > 2 else "build/headct-check.png"
info = json.load(open(os.path.join(here, "volume.json")))
failures = []


def check(what, ok):
    print("%-70s %s" % (what, "ok" if ok else "FAILED"))
    if not ok:
        failures.append(what)


def read(directory):
    r = octoray.vtkSliceStackReader()
    r.SetDirectoryName(directory)
    r.Update()
    img = r.GetImageOutput()
    nx, ny, nz = img.GetDimensions()
    values = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(nz, ny, nx)
    return r, img, values


# DICOM through the project's reader
r, img, hu = read(os.path.join(here, "DICOM"))
dims, spacing, origin = img.GetDimensions(), img.GetSpacing(), img.GetOrigin()
direction = [img.GetDirectionMatrix().GetElement(i, j) for i in range(3) for j in range(3)]
print("octoray DICOM: dimensions %s, spacing %s, origin %s, direction %s, HU %g..%g"
      % (dims, spacing, origin, direction, hu.min(), hu.max()))
nz, ny, nx = info["shape_zyx"]
check("dimensions %dx%dx%d" % (nx, ny, nz), dims == (nx, ny, nz))
check("spacing %s (volume.json, from main.plist)" % info["spacing_xyz_mm"],
      np.allclose(spacing, info["spacing_xyz_mm"], rtol=0, atol=1e-9))
check("origin %s" % info["origin_xyz_mm"], np.allclose(origin, info["origin_xyz_mm"], atol=1e-9))
check("direction identity (rows along +x, columns along +y, slices along +z)",
      direction == [1, 0, 0, 0, 1, 0, 0, 0, 1])
check("HU range %d..%d" % tuple(info["hu_range"]),
      [hu.min(), hu.max()] == info["hu_range"])

# Slice order comes from the positions, not the names: the same files named
# in reverse order give the same volume.
import tempfile
with tempfile.TemporaryDirectory() as tmp:
    for k in range(nz):
        os.symlink(os.path.abspath(os.path.join(here, "DICOM", "slice_%03d.dcm" % k)),
                   os.path.join(tmp, "x%03d.dcm" % (nz - 1 - k)))
    check("octoray: files named in reverse order give the same volume",
          np.array_equal(read(tmp)[2], hu))

# pydicom on its own: sort by position along the slice normal
slices = [pydicom.dcmread(f) for f in glob.glob(os.path.join(here, "DICOM", "*.dcm"))]
slices.sort(key=lambda d: float(d.ImagePositionPatient[2]))
ref = np.stack([d.pixel_array * float(d.RescaleSlope) + float(d.RescaleIntercept) for d in slices])
z = [float(d.ImagePositionPatient[2]) for d in slices]
uids = {(d.StudyInstanceUID, d.SeriesInstanceUID, d.FrameOfReferenceUID) for d in slices}
check("pydicom: %d files, one study/series/frame of reference, %d SOP instance UIDs"
      % (len(slices), len({d.SOPInstanceUID for d in slices})),
      len(uids) == 1 and len({d.SOPInstanceUID for d in slices}) == len(slices) == nz)
check("pydicom: instance numbers 1..%d in position order" % nz,
      [int(d.InstanceNumber) for d in slices] == list(range(1, nz + 1)))
check("pydicom: positions advance by %g mm" % info["spacing_xyz_mm"][2],
      np.allclose(np.diff(z), info["spacing_xyz_mm"][2]))
check("pydicom: explicit VR little endian, CT, MONOCHROME2",
      all(d.file_meta.TransferSyntaxUID == pydicom.uid.ExplicitVRLittleEndian and
          d.Modality == "CT" and d.PhotometricInterpretation == "MONOCHROME2" for d in slices))
check("octoray volume == pydicom volume (every voxel)", np.array_equal(hu, ref))

# PNG slices through the project's reader
_, pimg, png = read(os.path.join(here, "PNG"))
print("octoray PNG: dimensions %s, values %g..%g" % (pimg.GetDimensions(), png.min(), png.max()))
check("PNG == DICOM HU + %d, rows bottom-up" % info["png_offset"],
      np.array_equal(png[:, ::-1, :], hu + info["png_offset"]))

# Pictures: sagittal (anterior left, superior up) and axial (anterior up,
# patient's right on the left, as radiologists look at it) in world mm.
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
dx, dy, dz = spacing
fig, ax = plt.subplots(1, 3, figsize=(15, 5.5))
sag = hu[:, :, nx // 2]  # (z, y)
ax[0].imshow(sag, cmap="gray", vmin=-200, vmax=1200, origin="lower",
             extent=[origin[1], origin[1] + (ny - 1) * dy, origin[2], origin[2] + (nz - 1) * dz])
ax[0].set_xlabel("y (mm, posterior →)"); ax[0].set_ylabel("z (mm, superior ↑)")
ax[0].set_title("DICOM via octoray: sagittal x = %d" % (nx // 2))
for a, k in ((ax[1], 12), (ax[2], 60)):
    a.imshow(hu[k], cmap="gray", vmin=-200, vmax=1200, origin="upper",
             extent=[origin[0], origin[0] + (nx - 1) * dx, origin[1] + (ny - 1) * dy, origin[1]])
    a.set_xlabel("x (mm, patient's left →)"); a.set_ylabel("y (mm, posterior ↓)")
    a.set_title("axial slice %d, z = %g mm" % (k, origin[2] + k * dz))
fig.tight_layout()
os.makedirs(os.path.dirname(picture) or ".", exist_ok=True)
fig.savefig(picture, dpi=70)
print("wrote", picture)
sys.exit("FAILED: " + "; ".join(failures) if failures else 0)
