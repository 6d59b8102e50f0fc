"""vtkSliceStackReader: picture stacks through OpenImageIO, DICOM series
through GDCM, background threshold against NumPy, errors by message."""
import os
import shutil
import subprocess

import numpy as np
import pydicom
import pytest
import vtk
import octoray
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

from conftest import Messages, array, points


def vtk_image(slices):
    """slices: (k, h, w[, c]) array, rows top to bottom as in a picture."""
    k, h, w = slices.shape[:3]
    comps = 1 if slices.ndim == 3 else slices.shape[3]
    image = vtk.vtkImageData()
    image.SetDimensions(w, h, k)
    flat = np.ascontiguousarray(slices[:, ::-1]).reshape(-1, comps)  # VTK: bottom row first
    image.GetPointData().SetScalars(numpy_to_vtk(flat, deep=1))
    return image


def write_slices(writer_class, folder, pattern, slices):
    os.makedirs(folder, exist_ok=True)
    paths = []
    for k, s in enumerate(slices):
        w = writer_class()
        w.SetInputData(vtk_image(s[None]))
        path = os.path.join(folder, pattern % k)
        w.SetFileName(path)
        w.Write()
        paths.append(path)
    return paths


def stack_of(reader):
    """The image output as (k, h, w[, c]) with rows top to bottom."""
    im = reader.GetImageOutput()
    w, h, k = im.GetDimensions()
    c = im.GetNumberOfScalarComponents()
    a = vtk_to_numpy(im.GetPointData().GetScalars()).reshape(k, h, w, c)[:, ::-1]
    return a[..., 0] if c == 1 else a


def reader_for(**options):
    r = octoray.vtkSliceStackReader()
    msgs = Messages(r)
    for key, value in options.items():
        if key == "Files":
            for f in value:
                r.AddFileName(f)
        elif isinstance(value, tuple):
            getattr(r, "Set" + key)(*value)
        else:
            getattr(r, "Set" + key)(value)
    r.Update()
    return r, r.GetOutput(), msgs


def test_16bit_tiff_stack_pattern(tmp_path):
    rng = np.random.default_rng(7)
    vol = rng.integers(0, 4000, size=(6, 20, 30)).astype(np.uint16)
    vol[vol < 1500] = 0  # a background of zeros
    folder = os.path.join(str(tmp_path), "tif")
    write_slices(vtk.vtkTIFFWriter, folder, "ct_%02d.tif", vol)
    # The slices' pixels only (FillBetweenSlices off): test_fill_* below
    # check the particles between slices.
    r, out, msgs = reader_for(FilePattern=os.path.join(folder, "ct_%02d.tif"),
                              FileNameRange=(0, 5), Spacing=(0.5, 0.25, 2.0),
                              Origin=(10.0, 20.0, 30.0), FillBetweenSlices=False)
    assert not msgs.errors, msgs.errors
    im = r.GetImageOutput()
    assert im.GetDimensions() == (30, 20, 6)
    assert im.GetScalarType() == vtk.VTK_UNSIGNED_SHORT
    np.testing.assert_array_equal(stack_of(r), vol)
    # Default background [0, 0]: every non-zero pixel is a particle.
    assert out.GetNumberOfPoints() == np.count_nonzero(vol)
    assert out.GetNumberOfVerts() == out.GetNumberOfPoints()
    # Positions: origin + (i*sx, j*sy, k*sz), j counted from the bottom row.
    k, row, i = np.nonzero(vol)
    j = vol.shape[1] - 1 - row
    expected = np.column_stack([10 + i * 0.5, 20 + j * 0.25, 30 + k * 2.0])
    got = points(out)
    order_got = np.lexsort(got.T[::-1])
    order_exp = np.lexsort(expected.T[::-1])
    np.testing.assert_allclose(got[order_got], expected[order_exp], rtol=0, atol=1e-5)
    np.testing.assert_array_equal(np.sort(array(out, "Scalars")), np.sort(vol[vol > 0]))
    # A background range: [0, 2500] against NumPy's count of the same pixels.
    r.SetBackgroundRange(0, 2500)
    r.Update()
    assert r.GetOutput().GetNumberOfPoints() == np.count_nonzero(vol > 2500)
    # Filled (the default): the same particles on the slices, and planes
    # between them 0.5 apart (the second-coarsest spacing: x) with values
    # interpolated from the two neighbouring slices.
    r.SetBackgroundRange(0, 0)
    r.SetFillBetweenSlices(True)
    r.Update()
    filled = points(r.GetOutput())
    on_slices = np.isclose((filled[:, 2] - 30.0) / 2.0, np.round((filled[:, 2] - 30.0) / 2.0), atol=1e-6)
    np.testing.assert_allclose(np.sort(array(r.GetOutput(), "Scalars")[on_slices]), np.sort(vol[vol > 0]))
    np.testing.assert_allclose(np.unique(np.round(filled[:, 2], 4)), 30.0 + 0.5 * np.arange(21), atol=1e-4)


def test_rgb_png_stack_directory_natural_order(tmp_path):
    rng = np.random.default_rng(11)
    vol = rng.integers(0, 256, size=(12, 8, 9, 3)).astype(np.uint8)
    vol[rng.uniform(size=vol.shape[:3]) < 0.4] = 0
    folder = os.path.join(str(tmp_path), "png")
    # Names whose plain sort would put 10 and 11 before 2.
    write_slices(vtk.vtkPNGWriter, folder, "slice%d.png", vol)
    with open(os.path.join(folder, "notes.txt"), "w") as f:
        f.write("not an image")
    r, out, msgs = reader_for(DirectoryName=folder)
    assert not msgs.errors, msgs.errors
    assert [os.path.basename(r.GetSliceFileName(k)) for k in range(r.GetNumberOfSlices())] == \
        ["slice%d.png" % k for k in range(12)]
    np.testing.assert_array_equal(stack_of(r), vol)
    nonbg = vol.sum(axis=3) > 0  # intensity = mean of R, G, B; background [0, 0]
    assert out.GetNumberOfPoints() == np.count_nonzero(nonbg)
    # Colours and scalars come from the pixels, in stack order (k, then j up, then i).
    flipped = vol[:, ::-1]
    sel = flipped.sum(axis=3) > 0
    np.testing.assert_array_equal(array(out, "Colors"), flipped[sel])
    np.testing.assert_allclose(array(out, "Scalars"), flipped[sel].mean(axis=1), rtol=1e-6)
    # Background by intensity range, against NumPy.
    r.SetBackgroundRange(0, 100)
    r.Update()
    assert r.GetOutput().GetNumberOfPoints() == np.count_nonzero(vol.mean(axis=3) > 100)


def test_roi_and_stride(tmp_path):
    vol = np.arange(1, 5 * 6 * 7 + 1, dtype=np.uint16).reshape(5, 6, 7)
    files = write_slices(vtk.vtkTIFFWriter, str(tmp_path), "s%d.tif", vol)
    r, out, msgs = reader_for(Files=files, RegionOfInterest=(1, 5, 0, 3, 1, 4), Stride=(2, 3, 2),
                              FillBetweenSlices=False)
    assert not msgs.errors
    flipped = vol[:, ::-1]  # index j counts up from the bottom row
    sub = flipped[1:5:2, 0:4:3, 1:6:2]
    assert out.GetNumberOfPoints() == sub.size
    np.testing.assert_array_equal(array(out, "Scalars"), sub.ravel())


def test_multipage_tiff(tmp_path):
    vol = np.random.default_rng(2).integers(0, 3, size=(4, 5, 6)).astype(np.uint8)
    w = vtk.vtkTIFFWriter()
    w.SetInputData(vtk_image(vol))
    path = os.path.join(str(tmp_path), "pages.tif")
    w.SetFileName(path)
    w.Write()
    r, out, msgs = reader_for(Files=[path])
    assert not msgs.errors
    assert r.GetNumberOfSlices() == 4
    assert r.GetSliceFileName(1) == path + "#2"
    assert out.GetNumberOfPoints() == np.count_nonzero(vol)


def test_rgba_alpha_is_background(tmp_path):
    vol = np.zeros((1, 2, 2, 4), np.uint8)
    vol[0, 0, 0] = (10, 20, 30, 255)
    vol[0, 0, 1] = (10, 20, 30, 0)  # transparent: background
    vol[0, 1, 0] = (0, 0, 0, 255)   # black: background by intensity
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "a%d.png", vol)
    r, out, msgs = reader_for(Files=files)
    assert out.GetNumberOfPoints() == 1
    assert array(out, "Colors").tolist() == [[10, 20, 30]]


@pytest.mark.parametrize("ext,writer", [("bmp", vtk.vtkBMPWriter), ("jpg", vtk.vtkJPEGWriter)])
def test_bmp_and_jpeg(tmp_path, ext, writer):
    vol = np.zeros((3, 16, 16, 3), np.uint8)
    vol[:, 4:12, 4:12] = 200
    write_slices(writer, str(tmp_path), "x%d." + ext, vol)
    r, out, msgs = reader_for(DirectoryName=str(tmp_path), BackgroundRange=(0, 50))
    assert not msgs.errors
    assert r.GetImageOutput().GetDimensions() == (16, 16, 3)
    # JPEG is lossy but a flat 200 square on 0 stays far from the threshold.
    assert out.GetNumberOfPoints() == 3 * 8 * 8


def test_exr(tmp_path):
    vol = np.zeros((2, 4, 5), np.float32)
    vol[0, 1, 2] = 0.5
    vol[1, 3, 4] = 2.0
    tifs = write_slices(vtk.vtkTIFFWriter, str(tmp_path), "f%d.tif", vol)
    exrs = []
    for t in tifs:
        e = t.replace(".tif", ".exr")
        subprocess.run(["oiiotool", t, "-d", "half", "-o", e], check=True)
        exrs.append(e)
    r, out, msgs = reader_for(Files=exrs)
    assert not msgs.errors, msgs.errors
    assert r.GetImageOutput().GetScalarType() == vtk.VTK_FLOAT
    np.testing.assert_array_equal(stack_of(r), vol)
    assert sorted(array(out, "Scalars").tolist()) == [0.5, 2.0]


def test_dicom_series_out_of_order(tmp_path, data_dir):
    src = os.path.join(data_dir, "DICOM", "CT5N")
    # Names that say nothing about position: natural name order is not z order.
    names = {"2062.dcm": "img_7.dcm", "2392.dcm": "img_10.dcm", "2693.dcm": "img_1.dcm",
             "3023.dcm": "img_30.dcm", "3353.dcm": "img_4.dcm"}
    folder = os.path.join(str(tmp_path), "ct")
    os.makedirs(folder)
    for a, b in names.items():
        shutil.copy(os.path.join(src, a), os.path.join(folder, b))
    r, out, msgs = reader_for(DirectoryName=folder, BackgroundRange=(-10000, -500),
                              FillBetweenSlices=False)
    assert not msgs.errors, msgs.errors
    assert r.GetIsDICOM()
    # Reference from pydicom: sort by ImagePositionPatient z (axial, normal +z).
    ds = [pydicom.dcmread(os.path.join(folder, n)) for n in names.values()]
    ds.sort(key=lambda d: float(d.ImagePositionPatient[2]))
    order = [os.path.basename(r.GetSliceFileName(k)) for k in range(r.GetNumberOfSlices())]
    assert order == [os.path.basename(d.filename) for d in ds]
    assert order == ["img_4.dcm", "img_30.dcm", "img_1.dcm", "img_10.dcm", "img_7.dcm"]
    im = r.GetImageOutput()
    assert im.GetDimensions() == (16, 16, 5)
    np.testing.assert_allclose(im.GetSpacing(), [0.488281, 0.488281, 2.5], rtol=1e-6)
    np.testing.assert_allclose(im.GetOrigin(), [float(v) for v in ds[0].ImagePositionPatient],
                               rtol=1e-6)
    hu = np.stack([d.pixel_array * float(d.RescaleSlope) + float(d.RescaleIntercept) for d in ds])
    assert im.GetScalarType() == vtk.VTK_FLOAT
    # DICOM rows stay top-down (j follows the column direction cosines).
    got = vtk_to_numpy(im.GetPointData().GetScalars()).reshape(5, 16, 16)
    np.testing.assert_array_equal(got, hu.astype(np.float32))
    assert out.GetNumberOfPoints() == np.count_nonzero(hu > -500)
    # Particle positions are patient coordinates: origin + i*dx*row + j*dy*col + k*dz*normal.
    k, j, i = np.nonzero(hu > -500)
    ipp = np.array([float(v) for v in ds[0].ImagePositionPatient])
    expected = ipp + np.column_stack([i * 0.488281, j * 0.488281, k * 2.5])
    np.testing.assert_allclose(points(out), expected, atol=1e-4)
    # Filled: 6 planes per 2.5 mm (2.5 / 0.488 = 5.1), the slices' particles
    # among them unchanged, values between slices linear in z.
    r.SetFillBetweenSlices(True)
    r.Update()
    filled = points(r.GetOutput())
    zs = np.unique(np.round(filled[:, 2] - ipp[2], 5))
    np.testing.assert_allclose(np.diff(zs), 2.5 / 6, atol=1e-4)
    assert len(zs) == 4 * 6 + 1
    on_slices = np.isclose(filled[:, 2] - ipp[2], np.round((filled[:, 2] - ipp[2]) / 2.5) * 2.5, atol=1e-4)
    np.testing.assert_allclose(filled[on_slices], expected, atol=1e-4)
    t = 2.0 / 6  # the plane 2/6 of the way from slice 1 to slice 2
    between = hu[1] * (1 - t) + hu[2] * t
    jj, ii = np.nonzero(between > -500)
    sel = np.isclose(filled[:, 2], ipp[2] + 2.5 * (1 + t), atol=1e-4)
    assert sel.sum() == len(ii)
    np.testing.assert_allclose(array(r.GetOutput(), "Scalars")[sel], between[jj, ii], rtol=1e-5, atol=1e-3)


def ct5n_copy(tmp_path, data_dir, change=None):
    """CT5N's five slices copied into a folder; change(name, dataset) may
    edit each with pydicom first (returning False leaves a file out)."""
    src = os.path.join(data_dir, "DICOM", "CT5N")
    folder = os.path.join(str(tmp_path), "ct")
    os.makedirs(folder)
    for name in sorted(os.listdir(src)):
        d = pydicom.dcmread(os.path.join(src, name))
        if change is None or change(name, d) is not False:
            d.save_as(os.path.join(folder, name))
    return folder


def test_dicom_slice_without_position_is_named(tmp_path, data_dir):
    """GDCM puts a slice without Image Position (Patient) at 0, which
    stacked it out of order without a word."""
    def drop(name, d):
        if name == "2693.dcm":
            del d.ImagePositionPatient
    folder = ct5n_copy(tmp_path, data_dir, drop)
    r, out, msgs = reader_for(DirectoryName=folder)
    assert r.GetErrorMessage() == ("DICOM slice '%s' has no Image Position (Patient) (0020,0032), so its place "
                                   "in the stack is unknown" % os.path.join(folder, "2693.dcm"))


def test_dicom_two_series_in_a_folder_are_named(tmp_path, data_dir):
    """Two series in one folder were interleaved into one volume."""
    def other_series(name, d):
        if name in ("2062.dcm", "2392.dcm"):
            d.SeriesInstanceUID = "1.2.3.4.5"
    folder = ct5n_copy(tmp_path, data_dir, other_series)
    r, out, msgs = reader_for(DirectoryName=folder)
    assert "belong to two series (Series Instance UID " in r.GetErrorMessage()
    assert "'1.2.3.4.5'" in r.GetErrorMessage() and "2062.dcm" in r.GetErrorMessage()
    assert out.GetNumberOfPoints() == 0


def test_dicom_slice_of_another_pixel_spacing_is_named(tmp_path, data_dir):
    def wider(name, d):
        if name == "3023.dcm":
            d.PixelSpacing = [0.6, 0.6]
    folder = ct5n_copy(tmp_path, data_dir, wider)
    r, out, msgs = reader_for(DirectoryName=folder)
    assert r.GetErrorMessage() == ("DICOM slice '%s' has a pixel spacing of 0.6 x 0.6 but slice '%s' has "
                                   "0.488281 x 0.488281; a stack needs one pixel spacing"
                                   % (os.path.join(folder, "3023.dcm"), os.path.join(folder, "2062.dcm")))


def test_dicom_gap_names_its_slices(tmp_path, data_dir):
    """A slice missing from a series: a warning names the slices around the
    widest gap and how far the mean spacing puts slices from their places."""
    folder = ct5n_copy(tmp_path, data_dir, lambda name, d: name != "2693.dcm")
    r, out, msgs = reader_for(DirectoryName=folder)
    assert r.GetErrorMessage() == ""
    z = {name: float(pydicom.dcmread(os.path.join(folder, name)).ImagePositionPatient[2])
         for name in os.listdir(folder)}
    around = sorted(z, key=z.get)
    k = int(np.argmax(np.diff([z[n] for n in around])))
    mean = (z[around[-1]] - z[around[0]]) / 3
    worst = max(abs(z[n] - z[around[0]] - i * mean) for i, n in enumerate(around))
    assert len(msgs.warnings) == 1, msgs.warnings
    assert ("to 5 (between '%s' and '%s': a slice missing there?); the volume uses the mean, %g, which puts slices "
            "up to %g from their positions" % (os.path.join(folder, around[k]), os.path.join(folder, around[k + 1]),
                                               mean, worst)) in msgs.warnings[0], msgs.warnings


def test_dicom_single_ct_slice(data_dir):
    path = os.path.join(data_dir, "DICOM", "CT_small", "CT_small.dcm")
    r, out, msgs = reader_for(Files=[path], BackgroundRange=(-5000, 0))
    assert not msgs.errors
    d = pydicom.dcmread(path)
    hu = d.pixel_array * float(d.RescaleSlope) + float(d.RescaleIntercept)
    assert r.GetImageOutput().GetDimensions() == (128, 128, 1)
    assert out.GetNumberOfPoints() == np.count_nonzero(hu > 0)


# --- a closed volume: filling between slices -------------------------------

def block_stack(tmp_path, slices=6, h=10, w=12, value=1000):
    """A solid block (value inside, 0 around) written as 16-bit PNG slices:
    slices 1..slices-2, rows 2..h-3, columns 2..w-3."""
    vol = np.zeros((slices, h, w), np.uint16)
    vol[1:slices - 1, 2:h - 2, 2:w - 2] = value
    folder = os.path.join(str(tmp_path), "block")
    write_slices(vtk.vtkPNGWriter, folder, "b%02d.png", vol)
    return folder, vol


def lattice_of(out):
    a = out.GetFieldData().GetArray("PointLattice")
    assert a is not None and a.GetNumberOfComponents() == 15 and a.GetNumberOfTuples() == 1
    t = np.array(a.GetTuple(0))
    return t[0:3], t[3:12].reshape(3, 3), t[12:15]


def test_fill_closes_a_block(tmp_path):
    """Slices 3 pixel spacings apart: the particles are no farther apart
    along the slice axis than across it, the background test applies to
    the interpolated values, and the slices' own particles are unchanged."""
    folder, vol = block_stack(tmp_path)
    r, out, msgs = reader_for(DirectoryName=folder, Spacing=(0.5, 0.5, 1.5), Origin=(1.0, 2.0, 3.0),
                              BackgroundRange=(0, 500))
    assert not msgs.errors, msgs.errors
    assert r.GetFillBetweenSlices()  # the default
    np.testing.assert_array_equal(stack_of(r), vol)  # output 1: the stack as read
    p = points(out)
    zs = np.unique(np.round(p[:, 2], 6))
    # Planes 0.5 apart; the block (slices 1..4) reaches a third of the way to
    # the empty slices 0 and 5, where the interpolated value 1000 * 2/3
    # is still above 500 and 1000 * 1/3 is not.
    np.testing.assert_allclose(zs, 3.0 + 0.5 * np.arange(2, 14), atol=1e-5)
    assert out.GetNumberOfPoints() == 8 * 6 * 12
    assert out.GetNumberOfVerts() == out.GetNumberOfPoints()
    xs, ys = np.unique(np.round(p[:, 0], 6)), np.unique(np.round(p[:, 1], 6))
    np.testing.assert_allclose(np.diff(xs), 0.5)
    np.testing.assert_allclose(np.diff(ys), 0.5)
    scalars = array(out, "Scalars")
    np.testing.assert_allclose(np.unique(np.round(scalars, 3)), [666.667, 1000.0], atol=1e-3)
    # The lattice the mapper reads: origin, step vectors, counts (16 planes).
    origin, steps, counts = lattice_of(out)
    np.testing.assert_allclose(origin, (1.0, 2.0, 3.0))
    np.testing.assert_allclose(steps, np.diag((0.5, 0.5, 0.5)))
    np.testing.assert_array_equal(counts, (12, 10, 16))

    # Off: the slices' pixels only, as before filling existed.
    r.SetFillBetweenSlices(False)
    r.Update()
    out = r.GetOutput()
    assert out.GetNumberOfPoints() == 8 * 6 * 4
    np.testing.assert_allclose(np.unique(np.round(points(out)[:, 2], 6)), 3.0 + 1.5 * np.arange(1, 5))
    origin, steps, counts = lattice_of(out)
    np.testing.assert_allclose(steps, np.diag((0.5, 0.5, 1.5)))
    np.testing.assert_array_equal(counts, (12, 10, 6))


def test_fill_interpolates_between_neighbouring_slices(tmp_path):
    """Values between slices come from the two slices around each plane,
    also with a stride along the slices (which fills the wider gaps); a
    region of interest moves the lattice's origin."""
    vol = np.stack([np.full((4, 5), 100 * (k + 1), np.uint16) for k in range(5)])
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "s%d.png", vol)
    r, out, msgs = reader_for(Files=files, Spacing=(1.0, 1.0, 2.0))
    z = np.round(points(out)[:, 2], 6)
    s = array(out, "Scalars")
    assert sorted(set(z)) == [float(v) for v in range(9)]  # 2 planes per slice gap
    np.testing.assert_allclose(s[z == 1.0], 150.0)
    np.testing.assert_allclose(s[z == 8.0], 500.0)
    # Stride 2 along the slices: slices 0, 2, 4 selected, 4 mm apart, filled
    # every 1 mm from the real slices in between.
    r.SetStride(1, 1, 2)
    r.Update()
    z = np.round(points(r.GetOutput())[:, 2], 6)
    s = array(r.GetOutput(), "Scalars")
    assert sorted(set(z)) == [float(v) for v in range(9)]
    np.testing.assert_allclose(s[z == 1.0], 150.0)
    np.testing.assert_allclose(s[z == 3.0], 250.0)
    # A region of interest from slice 1: the lattice starts there.
    r.SetStride(1, 1, 1)
    r.SetRegionOfInterest(1, 3, -1, -1, 1, 3)
    r.Update()
    origin, steps, counts = lattice_of(r.GetOutput())
    np.testing.assert_allclose(origin, (1.0, 0.0, 2.0))
    np.testing.assert_array_equal(counts, (3, 4, 5))
    assert r.GetOutput().GetNumberOfPoints() == 3 * 4 * 5


def test_gradient_normals_point_out_of_a_ball(tmp_path):
    """A ball whose intensity falls linearly from its centre, slices two
    pixel spacings apart: with GradientNormals (off by default) every
    particle's Normals point away from the centre (the negated gradient), the
    filled planes' too; off, and for a colour stack, there are none."""
    k, j, i = np.mgrid[:12, :24, :24]
    radius = np.sqrt((i - 11.5) ** 2 + (j - 11.5) ** 2 + (2 * (k - 5.5)) ** 2)
    vol = np.clip(1000 * (1 - radius / 11), 0, None).astype(np.uint16)
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "ball%02d.png", vol)
    assert octoray.vtkSliceStackReader().GetGradientNormals() is False
    r, out, msgs = reader_for(Files=files, Spacing=(1.0, 1.0, 2.0), GradientNormals=True)
    assert not msgs.errors
    p = points(out)
    normals = array(out, "Normals")
    assert out.GetPointData().GetNormals() is not None and normals.shape == p.shape
    centre = p.mean(axis=0)
    np.testing.assert_allclose(centre, (11.5, 11.5, 11.0), atol=0.05)
    outward = p - centre
    distance = np.linalg.norm(outward, axis=1)
    far = distance > 2.0  # the peak's neighbours see a kink in the cone
    cosine = (normals[far] * outward[far]).sum(axis=1) / distance[far]
    between = np.abs(np.round(p[far, 2], 6) % 2.0) > 0  # the filled planes
    assert between.any() and cosine.min() > 0.97, cosine.min()
    np.testing.assert_allclose(np.linalg.norm(normals[far], axis=1), 1.0, atol=1e-5)
    r.SetGradientNormals(False)
    r.Update()
    assert r.GetOutput().GetPointData().GetNormals() is None
    colour = np.zeros((2, 4, 4, 3), np.uint8)
    colour[:, 1:3, 1:3] = (200, 100, 50)
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path / "colour"), "c%d.png", colour)
    assert reader_for(Files=files, GradientNormals=True)[1].GetPointData().GetNormals() is None


def test_image_output_alone(tmp_path):
    """GenerateParticles off (on by default): output 0 has no points, and
    the stack's volume is the same; options that only the particles use
    are not looked at."""
    folder, vol = block_stack(tmp_path)
    r, out, msgs = reader_for(DirectoryName=folder)
    assert r.GetGenerateParticles() and out.GetNumberOfPoints() > 0
    r2, out2, msgs2 = reader_for(DirectoryName=folder, GenerateParticles=False, Stride=(0, 1, 1))
    assert not msgs2.errors, msgs2.errors
    assert out2.GetNumberOfPoints() == 0
    np.testing.assert_array_equal(stack_of(r2), stack_of(r))


def test_fill_colours(tmp_path):
    vol = np.zeros((2, 2, 2, 3), np.uint8)
    vol[0] = (10, 20, 30)
    vol[1] = (41, 51, 61)
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "c%d.png", vol)
    r, out, msgs = reader_for(Files=files, Spacing=(1.0, 1.0, 2.0))
    z = np.round(points(out)[:, 2], 6)
    colors = array(out, "Colors")
    assert sorted(set(z)) == [0.0, 1.0, 2.0]
    np.testing.assert_array_equal(colors[z == 0.0], [[10, 20, 30]] * 4)
    np.testing.assert_array_equal(colors[z == 1.0], [[26, 36, 46]] * 4)  # 25.5, 35.5, 45.5 rounded
    np.testing.assert_allclose(array(out, "Scalars")[z == 1.0], 35.5)


def test_fill_single_slice_and_equal_spacing(tmp_path):
    """Nothing to fill: one slice, or slices as far apart as the pixels."""
    vol = np.ones((1, 3, 3), np.uint8)
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "o%d.png", vol)
    r, out, msgs = reader_for(Files=files, Spacing=(0.5, 0.5, 5.0))
    assert out.GetNumberOfPoints() == 9
    vol = np.ones((3, 3, 3), np.uint8)
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "e%d.png", vol)
    r, out, msgs = reader_for(Files=files, Spacing=(0.7, 0.7, 0.7))
    assert out.GetNumberOfPoints() == 27


@pytest.mark.parametrize("dtype", [np.int8, np.int32, np.uint32, np.float64])
def test_tiff_slices_keep_their_pixel_type(tmp_path, dtype):
    """Integer and double TIFF slices are read as they are stored, in the
    VTK type of theirs: OpenImageIO's float scaled integers to 0..1 and
    rounded doubles (int32 2147483647 came back as 1.0)."""
    import tifffile
    info = np.iinfo(dtype) if np.issubdtype(dtype, np.integer) else np.finfo(dtype)
    values = np.array([[info.max, info.min + 1, 5], [16777217 % int(info.max), 0, 3]], dtype)
    if dtype == np.float64:
        values = np.array([[1e300, 0.1, 1.0000000001], [-2.5, 0.0, 3.0]])
    for k in range(2):
        tifffile.imwrite(os.path.join(str(tmp_path), "s%d.tif" % k), values + dtype(k))
    r, out, msgs = reader_for(DirectoryName=str(tmp_path))
    assert r.GetErrorMessage() == ""
    got = stack_of(r)
    assert got.dtype == dtype
    assert (got == np.stack([values + dtype(k) for k in range(2)])).all(), got


# --- errors ----------------------------------------------------------------

def test_error_missing_slice_in_pattern(tmp_path):
    vol = np.ones((3, 4, 4), np.uint8)
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "m%d.png", vol)
    os.remove(files[1])
    r, out, msgs = reader_for(FilePattern=os.path.join(str(tmp_path), "m%d.png"),
                              FileNameRange=(0, 2))
    assert out.GetNumberOfPoints() == 0
    assert r.GetErrorMessage().startswith("slice file '%s' is missing" % files[1])
    assert msgs.errors and files[1] in msgs.errors[0]


def test_error_missing_listed_file(tmp_path):
    r, out, msgs = reader_for(Files=[os.path.join(str(tmp_path), "gone.png")])
    assert "slice file '%s' does not exist" % os.path.join(str(tmp_path), "gone.png") \
        == r.GetErrorMessage()


def test_error_pattern_matches_nothing(tmp_path):
    pattern = os.path.join(str(tmp_path), "none_%03d.tif")
    r, out, msgs = reader_for(FilePattern=pattern, FileNameRange=(1, 9))
    assert r.GetErrorMessage() == \
        "the file pattern '%s' with numbers 1 to 9 matches no file" % pattern
    assert out.GetNumberOfPoints() == 0


@pytest.mark.parametrize("name, wrong", [
    ("s_%s.png", "has '%s'; it takes one integer conversion, such as %d or %03d (%% for a percent sign)"),
    ("s_%n.png", "has '%n'; it takes one integer conversion"),
    ("s_%5.2f.png", "has '%5.2f'; it takes one integer conversion"),
    ("s_%03d_%d.png", "has 2 integer conversions; it takes one, such as %d or %03d, for the slice number"),
    ("s.png", "has 0 integer conversions; it takes one")])
def test_error_pattern_without_one_integer(tmp_path, name, wrong):
    """A pattern is filled by snprintf with the slice number alone: any
    other conversion would read an argument that is not there (%s and %n
    crashed the reader), so the reader names it before filling."""
    write_slices(vtk.vtkPNGWriter, str(tmp_path), "s_%d.png", np.ones((2, 4, 4), np.uint8))
    pattern = os.path.join(str(tmp_path), name)
    r, out, msgs = reader_for(FilePattern=pattern, FileNameRange=(0, 1))
    assert r.GetErrorMessage().startswith("the file pattern '%s' %s" % (pattern, wrong))
    assert out.GetNumberOfPoints() == 0


def test_pattern_with_a_percent_sign(tmp_path):
    folder = os.path.join(str(tmp_path), "100%")
    write_slices(vtk.vtkPNGWriter, folder, "s_%d.png", np.full((2, 4, 4), 9, np.uint8))
    r, out, msgs = reader_for(FilePattern=os.path.join(str(tmp_path), "100%%", "s_%d.png"),
                              FileNameRange=(0, 1))
    assert r.GetErrorMessage() == ""
    assert r.GetImageOutput().GetDimensions() == (4, 4, 2)


def test_error_empty_directory(tmp_path):
    folder = os.path.join(str(tmp_path), "empty")
    os.makedirs(folder)
    with open(os.path.join(folder, "readme.txt"), "w") as f:
        f.write("x")
    r, out, msgs = reader_for(DirectoryName=folder)
    assert r.GetErrorMessage() == "the directory '%s' has no image or DICOM files" % folder
    assert len(msgs.errors) == 1


def test_error_unreadable_slice(tmp_path):
    vol = np.ones((2, 4, 4), np.uint8)
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "u%d.png", vol)
    with open(files[1], "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n garbage")
    r, out, msgs = reader_for(Files=files)
    assert r.GetErrorMessage().startswith("cannot read slice '%s'" % files[1])
    assert out.GetNumberOfPoints() == 0
    assert r.GetImageOutput().GetNumberOfPoints() == 0


def test_error_different_sizes(tmp_path):
    a = write_slices(vtk.vtkPNGWriter, str(tmp_path), "a%d.png", np.ones((1, 4, 5), np.uint8))
    b = write_slices(vtk.vtkPNGWriter, str(tmp_path), "b%d.png", np.ones((1, 6, 7), np.uint8))
    r, out, msgs = reader_for(Files=a + b)
    assert r.GetErrorMessage() == (
        "slice '%s' is 7x6 grey uint8 but slice '%s' is 5x4 grey uint8; "
        "all slices must have one size and type" % (b[0], a[0]))


def test_error_different_types(tmp_path):
    a = write_slices(vtk.vtkPNGWriter, str(tmp_path), "a%d.png", np.ones((1, 4, 4), np.uint8))
    b = write_slices(vtk.vtkPNGWriter, str(tmp_path), "b%d.png", np.ones((1, 4, 4), np.uint16))
    c = write_slices(vtk.vtkPNGWriter, str(tmp_path), "c%d.png", np.ones((1, 4, 4, 3), np.uint8))
    r, out, msgs = reader_for(Files=a + b)
    assert "is 4x4 grey uint16 but slice '%s' is 4x4 grey uint8" % a[0] in r.GetErrorMessage()
    r, out, msgs = reader_for(Files=a + c)
    assert "is 4x4 RGB uint8 but slice '%s' is 4x4 grey uint8" % a[0] in r.GetErrorMessage()


@pytest.mark.parametrize("options,message", [
    (dict(Spacing=(1.0, 1.0, 0.0)), "Spacing (1, 1, 0): each must be finite and above zero"),
    (dict(Spacing=(1.0, float("nan"), 1.0)), "Spacing (1, nan, 1): each must be finite and above zero"),
    (dict(Origin=(0.0, float("inf"), 0.0)), "Origin (0, inf, 0): each must be finite"),
    (dict(Stride=(1, 0, 1)), "Stride 0 on y (pixels up): a stride is at least 1"),
    (dict(RegionOfInterest=(4, 2, -1, -1, -1, -1)),
     "RegionOfInterest 4..2 on x (pixels across): its minimum lies above its maximum"),
    (dict(RegionOfInterest=(-1, -1, -1, -1, 1, 3)),
     "RegionOfInterest 1..3 on z (slices) reaches past the stack's 3 (indices 0..2; -1: to the edge)"),
])
def test_error_settings_no_stack_can_have(tmp_path, options, message):
    """Settings that fit no stack, or not this one, are refused by name:
    nothing is read into the outputs, and the message says which property
    and why (they used to be clamped or passed through without a word)."""
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "s%d.png", np.ones((3, 4, 5), np.uint8))
    r, out, msgs = reader_for(Files=files, **options)
    assert r.GetErrorMessage() == message
    assert len(msgs.errors) == 1 and message in msgs.errors[0]
    assert out.GetNumberOfPoints() == 0 and r.GetImageOutput().GetNumberOfPoints() == 0


def scalars_address(reader):
    """Where the image output's values live: the same after an update that
    did not read the volume again."""
    return reader.GetImageOutput().GetPointData().GetScalars().GetVoidPointer(0)


def particle_positions(out):
    return vtk_to_numpy(out.GetPoints().GetData()) if out.GetPoints() else np.zeros((0, 3))


def test_particles_only_where_asked_for(tmp_path):
    """An update of output 1 alone makes no particles (and does not look at
    their options); output 0 asked for afterwards gets them from the same
    volume, not read again, equal to a fresh reader's."""
    folder, vol = block_stack(tmp_path)
    r = octoray.vtkSliceStackReader()
    msgs = Messages(r)
    r.SetDirectoryName(folder)
    r.SetStride(0, 1, 1)
    r.Update(1)
    assert not msgs.errors, msgs.errors
    assert r.GetOutput().GetNumberOfPoints() == 0
    np.testing.assert_array_equal(stack_of(r), vol)
    volume = scalars_address(r)
    r.Update(0)
    assert msgs.errors and "Stride" in msgs.errors[-1], msgs.errors
    del msgs.errors[:]
    r.SetStride(1, 1, 1)
    r.Update(0)
    assert not msgs.errors, msgs.errors
    assert scalars_address(r) == volume
    fresh = reader_for(DirectoryName=folder)[1]
    assert r.GetOutput().GetNumberOfPoints() == fresh.GetNumberOfPoints() > 0
    np.testing.assert_array_equal(particle_positions(r.GetOutput()), particle_positions(fresh))


def test_volume_read_again_only_when_it_changes(tmp_path):
    """A particle option's change makes the particles again from the volume
    already read; Spacing and a slice changed on disk read it again."""
    folder, vol = block_stack(tmp_path)
    r, out, msgs = reader_for(DirectoryName=folder)
    volume = scalars_address(r)
    r.SetBackgroundRange(0, 999)  # the block's 1000 is not background
    r.Update()
    assert scalars_address(r) == volume
    assert out.GetNumberOfPoints() == reader_for(DirectoryName=folder, BackgroundRange=(0, 999))[1].GetNumberOfPoints()
    r.SetBackgroundRange(0, 1000)
    r.Update()
    assert out.GetNumberOfPoints() == 0 and scalars_address(r) == volume
    r.SetSpacing(1.0, 1.0, 2.0)
    r.Update()
    assert scalars_address(r) != volume
    np.testing.assert_array_equal(stack_of(r), vol)
    volume = scalars_address(r)
    changed = vol.copy()
    changed[2, 4, 5] = 7
    write_slices(vtk.vtkPNGWriter, folder, "b%02d.png", changed)
    r.Update()
    assert scalars_address(r) != volume
    np.testing.assert_array_equal(stack_of(r), changed)
    assert not msgs.errors, msgs.errors


def test_error_nothing_given():
    r, out, msgs = reader_for()
    assert r.GetErrorMessage() == "no slices given: set file names, a directory or a file pattern"


def test_progress_per_slice(tmp_path):
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "p%d.png", np.ones((5, 3, 3), np.uint8))
    r = octoray.vtkSliceStackReader()
    for f in files:
        r.AddFileName(f)
    progress = []
    r.AddObserver("ProgressEvent", lambda o, e: progress.append(o.GetProgress()))
    r.Update()
    assert len(progress) >= 7  # start, one per slice, end
    assert progress[-1] == 1.0


def test_volume_port_in_a_pipeline(tmp_path):
    """Output 1 announces its whole extent before reading, and a VTK image
    filter downstream gets the whole stack (as VTK's volume mappers would)."""
    vol = np.random.default_rng(3).integers(0, 100, size=(4, 6, 5)).astype(np.uint8)
    files = write_slices(vtk.vtkPNGWriter, str(tmp_path), "v%d.png", vol)
    r = octoray.vtkSliceStackReader()
    for f in files:
        r.AddFileName(f)
    r.UpdateInformation()
    info = r.GetOutputInformation(1)
    assert info.Get(vtk.vtkStreamingDemandDrivenPipeline.WHOLE_EXTENT()) == (0, 4, 0, 5, 0, 3)
    shift = vtk.vtkImageShiftScale()
    shift.SetInputConnection(r.GetOutputPort(1))
    shift.SetShift(1)
    shift.SetOutputScalarTypeToUnsignedShort()
    shift.Update()
    out = shift.GetOutput()
    assert out.GetDimensions() == (5, 6, 4)
    got = vtk_to_numpy(out.GetPointData().GetScalars()).reshape(4, 6, 5)[:, ::-1]
    np.testing.assert_array_equal(got, vol.astype(np.uint16) + 1)
