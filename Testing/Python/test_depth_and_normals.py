"""vtkDepthMapReader (pinhole back-projection) and vtkParticleNormals (PCL),
against data whose answer is known."""
import os
import subprocess

import numpy as np
import pytest
import vtk
import octoray
from octoray.png import read_png, write_png
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

from conftest import Messages, array, points

# Data/README.md: intrinsics of the subsampled Middlebury depth map.
FX = FY = 497.489
CX, CY = 155.5965, 127.4385


def depth_reader(path, **options):
    r = octoray.vtkDepthMapReader()
    msgs = Messages(r)
    r.SetFileName(path)
    for key, value in options.items():
        v = value if isinstance(value, tuple) else (value,)
        getattr(r, "Set" + key)(*v)
    r.Update()
    return r, r.GetOutput(), msgs


def test_real_depth_map(data_dir):
    depth_path = os.path.join(data_dir, "DepthMaps", "motorcycle_depth_mm.png")
    color_path = os.path.join(data_dir, "DepthMaps", "motorcycle_left.png")
    r, out, msgs = depth_reader(depth_path, ColorFileName=color_path,
                                Intrinsics=(FX, FY, CX, CY), DepthScale=0.001)
    assert not msgs.errors, msgs.errors
    d = read_png(depth_path)[..., 0].astype(np.float64)
    rgb = read_png(color_path)
    valid = d > 0
    assert out.GetNumberOfPoints() == np.count_nonzero(valid)
    assert r.GetNumberOfInvalidPixels() == np.count_nonzero(~valid)
    v, u = np.nonzero(valid)
    z = d[valid] * 0.001
    expected = np.column_stack([(u - CX) * z / FX, (v - CY) * z / FY, z])
    np.testing.assert_allclose(points(out), expected, rtol=1e-6, atol=1e-6)
    np.testing.assert_array_equal(array(out, "Colors"), rgb[valid])
    # The scene is a motorcycle 2-3 m in front of the camera.
    assert 1.5 < np.median(z) < 4.0


def test_plane_depth(tmp_path):
    path = os.path.join(str(tmp_path), "plane.png")
    depth = np.full((40, 60), 2000, np.uint16)
    depth[0, :] = 0  # no measurement
    write_png(path, depth)
    r, out, msgs = depth_reader(path, Intrinsics=(100.0, 100.0, 30.0, 20.0), DepthScale=0.001,
                                Stride=2)
    p = points(out)
    assert out.GetNumberOfPoints() == 19 * 30  # rows 2, 4, ..., 38 of 0..39; 30 columns
    assert r.GetNumberOfInvalidPixels() == 30
    np.testing.assert_allclose(p[:, 2], 2.0)
    assert p[:, 0].min() == pytest.approx((0 - 30) * 2.0 / 100)
    assert p[:, 1].max() == pytest.approx((38 - 20) * 2.0 / 100)
    r.SetMaximumDepth(1.5)
    r.Update()
    assert r.GetOutput().GetNumberOfPoints() == 0


def test_exr_depth_with_nan(tmp_path):
    depth = np.full((3, 4), 1.25, np.float32)
    depth[1, 1] = np.nan
    depth[2, 3] = np.inf
    tif = os.path.join(str(tmp_path), "d.tif")
    image = vtk.vtkImageData()
    image.SetDimensions(4, 3, 1)
    image.GetPointData().SetScalars(numpy_to_vtk(np.ascontiguousarray(depth[::-1]).ravel(), deep=1))
    w = vtk.vtkTIFFWriter()
    w.SetInputData(image)
    w.SetFileName(tif)
    w.Write()
    exr = tif.replace(".tif", ".exr")
    subprocess.run(["oiiotool", tif, "-o", exr], check=True)
    r, out, msgs = depth_reader(exr, Intrinsics=(1.0, 1.0, 0.0, 0.0))
    assert out.GetNumberOfPoints() == 10
    assert r.GetNumberOfInvalidPixels() == 2
    np.testing.assert_allclose(array(out, "Depth"), 1.25)


def test_depth_errors(tmp_path, data_dir):
    missing = os.path.join(str(tmp_path), "nothing.png")
    r, out, msgs = depth_reader(missing, Intrinsics=(1.0, 1.0, 0.0, 0.0))
    assert r.GetErrorMessage().startswith("cannot read depth image '%s'" % missing)
    depth_path = os.path.join(data_dir, "DepthMaps", "motorcycle_depth_mm.png")
    r, out, msgs = depth_reader(depth_path)
    assert r.GetErrorMessage() == (depth_path + ": the focal lengths fx and fy must be set and "
                                   "positive (pixels); got fx=0.000000, fy=0.000000")
    small = os.path.join(str(tmp_path), "small.png")
    write_png(small, np.ones((2, 2), np.uint16))
    r, out, msgs = depth_reader(depth_path, ColorFileName=small, Intrinsics=(1.0, 1.0, 0.0, 0.0))
    assert r.GetErrorMessage() == ("colour image '%s' is 2x2 but depth image '%s' is 371x250"
                                   % (small, depth_path))
    assert out.GetNumberOfPoints() == 0
    # Settings under which no pixel can be a point (they read as an image of
    # invalid pixels, without a word).
    for options, message in (
            ({"DepthScale": -0.001}, "DepthScale must be finite and positive (output units per stored value); "
                                     "got -0.001"),
            ({"DepthScale": float("nan")}, "DepthScale must be finite and positive (output units per stored "
                                           "value); got nan"),
            ({"MinimumDepth": 5.0, "MaximumDepth": 1.0}, "MinimumDepth (5) must lie below MaximumDepth (1)")):
        r, out, msgs = depth_reader(depth_path, Intrinsics=(1.0, 1.0, 0.0, 0.0), **options)
        assert r.GetErrorMessage() == depth_path + ": " + message
        assert len(msgs.errors) == 1 and out.GetNumberOfPoints() == 0


def polydata(xyz):
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(xyz, dtype=np.float32), deep=1))
    pd = vtk.vtkPolyData()
    pd.SetPoints(pts)
    return pd


def normals_of(pd, **options):
    f = octoray.vtkParticleNormals()
    msgs = Messages(f)
    f.SetInputData(pd)
    for key, value in options.items():
        v = value if isinstance(value, tuple) else (value,)
        getattr(f, "Set" + key)(*v)
    f.Update()
    return f, f.GetOutput(), msgs


def test_normals_plane():
    rng = np.random.default_rng(4)
    xy = rng.uniform(-1, 1, size=(3000, 2))
    # A tilted plane z = 0.3 x - 0.2 y + 1; its unit normal is known.
    xyz = np.column_stack([xy, 0.3 * xy[:, 0] - 0.2 * xy[:, 1] + 1])
    n_true = np.array([-0.3, 0.2, 1.0]) / np.linalg.norm([-0.3, 0.2, 1.0])
    f, out, msgs = normals_of(polydata(xyz), NumberOfNeighbors=10, ViewPoint=(0.0, 0.0, 10.0))
    n = vtk_to_numpy(out.GetPointData().GetNormals())
    assert out.GetPointData().GetNormals().GetName() == "Normals"
    assert n.shape == (3000, 3)
    # Oriented towards the viewpoint above the plane: +n_true everywhere.
    assert (n @ n_true).min() > 0.9999
    assert np.abs(array(out, "Curvature")).max() < 1e-4
    # From below, all flip.
    f.SetViewPoint(0, 0, -10)
    f.Update()
    n = vtk_to_numpy(f.GetOutput().GetPointData().GetNormals())
    assert (n @ n_true).max() < -0.9999


def test_normals_sphere_radius():
    rng = np.random.default_rng(9)
    p = rng.normal(size=(5000, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    xyz = 3.0 * p + [1.0, 2.0, 3.0]
    # Viewpoint at the centre: normals point inwards, along -radial.
    f, out, msgs = normals_of(polydata(xyz), Radius=0.5, ViewPoint=(1.0, 2.0, 3.0))
    assert f.GetNumberOfInvalidNormals() == 0
    n = vtk_to_numpy(out.GetPointData().GetNormals())
    cos = np.sum(n * -p, axis=1)
    assert cos.min() > 0.99
    assert np.median(cos) > 0.999
    # k neighbours, viewpoint far outside on +x: all normals face it, i.e.
    # the ones on the +x side point outwards.
    f, out, msgs = normals_of(polydata(xyz), NumberOfNeighbors=12, ViewPoint=(100.0, 2.0, 3.0))
    n = vtk_to_numpy(out.GetPointData().GetNormals())
    facing = np.sum(n * ([100.0, 2.0, 3.0] - xyz), axis=1)
    assert (facing >= 0).all()
    near_side = p[:, 0] > 0.5
    assert np.sum(n[near_side] * p[near_side], axis=1).min() > 0.99


def test_normals_too_few_neighbours_are_reported():
    xyz = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [50, 50, 50]], float)
    f, out, msgs = normals_of(polydata(xyz), Radius=2.0)
    assert f.GetNumberOfInvalidNormals() == 1
    n = vtk_to_numpy(out.GetPointData().GetNormals())
    assert n[4].tolist() == [0, 0, 0]
    np.testing.assert_allclose(np.abs(n[:4, 2]), 1.0, atol=1e-6)
    assert len(msgs.warnings) == 1 and "1 of 5 points had too few neighbours" in msgs.warnings[0]


def test_normals_on_real_scan(data_dir):
    r = octoray.vtkParticleReader()
    r.SetFileName(os.path.join(data_dir, "Particles", "lidar_simple.particles"))
    f = octoray.vtkParticleNormals()
    f.SetInputConnection(r.GetOutputPort())
    f.SetNumberOfNeighbors(8)
    f.Update()
    out = f.GetOutput()
    assert out.GetNumberOfPoints() == 1065
    n = vtk_to_numpy(out.GetPointData().GetNormals())
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)
    # Input arrays pass through.
    assert out.GetPointData().GetArray("Colors") is not None
