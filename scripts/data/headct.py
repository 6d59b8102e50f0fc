#!/usr/bin/python3
"""Head CT of Data/External/HeadCT from InVesalius' example project.

    /usr/bin/python3 scripts/data/headct.py Cranium.inv3 OUT_DIR PACKAGE VERSION MEMBER

(MEMBER: the file's path in the package, for the messages and volume.json.)

Cranium.inv3 (package invesalius-examples) is a gzipped tar of an InVesalius
project: main.plist names the volume file (matrix.dat) and gives its numpy
dtype, shape (slices, rows, columns) and spacing (x, y, z in mm); the volume
is raw little-endian, in Hounsfield units. Writes into OUT_DIR:

  DICOM/slice_000.dcm ...  one CT image per slice (explicit VR little endian),
                           unsigned 16-bit stored values, rescale slope 1 and
                           intercept = the lowest HU (-1024 here), so that
                           stored * slope + intercept gives the HU back exactly
  PNG/slice_000.png ...    the same stored values (HU - intercept, i.e. HU + 1024)
                           as 16-bit grey PNG, first row = first DICOM row
  volume.json              shape, spacing, origin, direction, offset, HU range

Orientation. InVesalius keeps the rows of each slice bottom-up (VTK's image
order): in matrix.dat the face is at the last rows and the CT head rest at
the first, which for a patient lying on the head rest (supine) is posterior.
The rows are reversed here, so that DICOM row 0 is anterior as in any CT
(ImageOrientationPatient 1\\0\\0\\0\\1\\0: columns go to the patient's left,
rows to posterior). The slices run from the chin (slice 0: teeth) to the
vertex (slice 107: air above the head), so slice k is at z = k * spacing,
z pointing to the head (DICOM's patient coordinates). Left and right cannot be
checked from the data (the original DICOM files are not in the package).

Everything written is checked by reading it back (pydicom for the DICOM files,
VTK's PNG reader for the PNG files) against the raw matrix.
"""
import hashlib
import io
import json
import os
import plistlib
import sys
import tarfile

import numpy as np


def fail(msg):
    sys.exit("fetch-data: " + msg)


def ds(value):
    """A DICOM decimal string (at most 16 characters) for a float."""
    for digits in range(15, 0, -1):
        s = "%.*g" % (digits, value)
        if len(s) <= 16:
            return s
    raise ValueError(value)


def read_project(path, where):
    with tarfile.open(path, "r:gz") as tar:
        members = {os.path.basename(m.name): m for m in tar.getmembers() if m.isfile()}
        if "main.plist" not in members:
            fail("%s: no main.plist in the InVesalius project (members: %s)"
                 % (where, ", ".join(sorted(members))))
        plist = plistlib.load(tar.extractfile(members["main.plist"]))
        m = plist.get("matrix", {})
        for key in ("filename", "dtype", "shape"):
            if key not in m:
                fail("%s: main.plist has no matrix/%s" % (where, key))
        if "spacing" not in plist:
            fail("%s: main.plist has no spacing" % where)
        if m["filename"] not in members:
            fail("%s: main.plist names %s, which is not in the project" % (where, m["filename"]))
        dtype = np.dtype(m["dtype"]).newbyteorder("<")
        shape = tuple(int(n) for n in m["shape"])
        raw = tar.extractfile(members[m["filename"]]).read()
    if len(shape) != 3 or len(raw) != dtype.itemsize * np.prod(shape):
        fail("%s: %s has %d bytes, main.plist says %s of %s"
             % (where, m["filename"], len(raw), "x".join(map(str, shape)), m["dtype"]))
    # InVesalius: 1 = axial (slices along z); the others are not converted.
    if plist.get("orientation", 1) not in (1, "AXIAL"):
        fail("%s: orientation %r is not axial" % (where, plist.get("orientation")))
    volume = np.frombuffer(raw, dtype).reshape(shape)
    return plist, [float(s) for s in plist["spacing"]], volume


def write_png(path, rows):
    """rows: 2-D uint16, first row at the top of the picture."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk
    h, w = rows.shape
    image = vtk.vtkImageData()
    image.SetDimensions(w, h, 1)
    # VTK images start at the bottom row.
    image.GetPointData().SetScalars(numpy_to_vtk(np.ascontiguousarray(rows[::-1]).ravel(), deep=1))
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()
    if writer.GetErrorCode():
        fail("cannot write %s" % path)


def read_png(path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    reader = vtk.vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    img = reader.GetOutput()
    w, h, _ = img.GetDimensions()
    return vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w)[::-1]


def main():
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    inv3, out, package, version, member = sys.argv[1:]
    where = "%s %s, %s" % (package, version, member)
    plist, spacing, matrix = read_project(inv3, where)
    # Rows top-down (see the docstring); slice 0 = lowest z.
    hu = matrix[:, ::-1, :]
    nz, ny, nx = hu.shape
    dx, dy, dz = spacing
    lo, hi = int(hu.min()), int(hu.max())
    intercept = min(lo, 0)
    if hi - intercept > 65535:
        fail("%s: HU range %d..%d does not fit 16 bits" % (where, lo, hi))
    stored = (hu.astype(np.int32) - intercept).astype(np.uint16)
    # Centred in x and y, first slice at z = 0; the DICOM strings are what
    # readers see, so the positions are computed from them.
    origin = [float(ds(-(nx - 1) / 2 * dx)), float(ds(-(ny - 1) / 2 * dy)), 0.0]
    z = [float(ds(k * dz)) for k in range(nz)]

    import pydicom
    from pydicom.dataset import FileDataset, FileMetaDataset
    from pydicom.uid import (CTImageStorage, ExplicitVRLittleEndian,
                             PYDICOM_IMPLEMENTATION_UID, generate_uid)

    # UIDs under pydicom's root, derived from the data: a second run writes
    # identical files.
    digest = hashlib.sha256(matrix.tobytes()).hexdigest()
    uid = lambda *what: generate_uid(entropy_srcs=["octoray", package, version, digest, *what])
    study, series, frame = uid("study"), uid("series"), uid("frame of reference")
    name = str(plist.get("name", "Cranium"))
    for sub in ("DICOM", "PNG"):
        os.makedirs(os.path.join(out, sub), exist_ok=True)
    for k in range(nz):
        sop = uid("image", str(k))
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CTImageStorage
        meta.MediaStorageSOPInstanceUID = sop
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        meta.ImplementationClassUID = PYDICOM_IMPLEMENTATION_UID
        path = os.path.join(out, "DICOM", "slice_%03d.dcm" % k)
        d = FileDataset(path, {}, file_meta=meta, preamble=b"\0" * 128)
        d.is_little_endian, d.is_implicit_VR = True, False
        d.SpecificCharacterSet = "ISO_IR 100"
        d.ImageType = ["DERIVED", "SECONDARY", "AXIAL"]
        d.SOPClassUID, d.SOPInstanceUID = CTImageStorage, sop
        d.StudyDate = d.StudyTime = d.AccessionNumber = d.ReferringPhysicianName = ""
        d.Modality = "CT"
        d.Manufacturer = ""
        d.StudyDescription = "InVesalius example Cranium.inv3"
        d.SeriesDescription = "%s (%s %s)" % (name, package, version)
        d.PatientName = "Cranium^InVesalius"
        d.PatientID = "invesalius-examples-Cranium"
        d.PatientBirthDate = d.PatientSex = ""
        d.KVP = ""
        d.SliceThickness = ds(dz)
        d.PatientPosition = ""  # not recorded in the project
        d.StudyInstanceUID, d.SeriesInstanceUID = study, series
        d.StudyID, d.SeriesNumber, d.AcquisitionNumber, d.InstanceNumber = "1", 1, 1, k + 1
        d.ImagePositionPatient = [ds(origin[0]), ds(origin[1]), ds(z[k])]
        d.ImageOrientationPatient = ["1", "0", "0", "0", "1", "0"]
        d.FrameOfReferenceUID = frame
        d.PositionReferenceIndicator = ""
        d.SliceLocation = ds(z[k])
        d.SamplesPerPixel = 1
        d.PhotometricInterpretation = "MONOCHROME2"
        d.Rows, d.Columns = ny, nx
        d.PixelSpacing = [ds(dy), ds(dx)]  # between rows, between columns
        d.BitsAllocated, d.BitsStored, d.HighBit, d.PixelRepresentation = 16, 16, 15, 0
        if "window_level" in plist and "window_width" in plist:
            d.WindowCenter, d.WindowWidth = ds(plist["window_level"]), ds(plist["window_width"])
        d.RescaleIntercept, d.RescaleSlope, d.RescaleType = ds(intercept), "1", "HU"
        d.PixelData = stored[k].astype("<u2").tobytes()
        d.save_as(path, write_like_original=False)
        write_png(os.path.join(out, "PNG", "slice_%03d.png" % k), stored[k])

    # Read everything back.
    for k in range(nz):
        path = os.path.join(out, "DICOM", "slice_%03d.dcm" % k)
        d = pydicom.dcmread(path)
        back = d.pixel_array.astype(np.int32) * int(d.RescaleSlope) + int(d.RescaleIntercept)
        if (d.file_meta.TransferSyntaxUID != ExplicitVRLittleEndian or
                not np.array_equal(back, hu[k]) or
                [float(v) for v in d.ImagePositionPatient] != [origin[0], origin[1], z[k]]):
            fail("%s does not read back as slice %d of %s" % (path, k, where))
        png = os.path.join(out, "PNG", "slice_%03d.png" % k)
        if not np.array_equal(read_png(png), stored[k]):
            fail("%s does not read back as slice %d of %s" % (png, k, where))

    info = {
        "source": "%s %s, %s: %s of main.plist %s"
                  % (package, version, member, plist["matrix"]["filename"], json.dumps(plist["matrix"])),
        "shape_zyx": [nz, ny, nx],
        "spacing_xyz_mm": [float(ds(dx)), float(ds(dy)), float(ds(dz))],
        "origin_xyz_mm": [origin[0], origin[1], z[0]],
        "direction": "ImageOrientationPatient 1\\0\\0\\0\\1\\0; slice k at z = k * spacing; "
                     "DICOM/PNG row 0 = anterior, column 0 = patient's right",
        "hu_range": [lo, hi],
        "rescale_intercept": intercept,
        "png_value": "HU - (%d), i.e. HU + %d" % (intercept, -intercept),
        "png_offset": -intercept,
    }
    with open(os.path.join(out, "volume.json"), "w") as f:
        f.write("{\n" + ",\n".join(" %s: %s" % (json.dumps(k), json.dumps(v))
                                    for k, v in info.items()) + "\n}\n")
    print("fetch-data: HeadCT: %d DICOM + %d PNG slices of %dx%d, spacing %s mm, HU %d..%d, "
          "read back exactly" % (nz, nz, nx, ny, "x".join(ds(s) for s in (dx, dy, dz)), lo, hi))


if __name__ == "__main__":
    main()
