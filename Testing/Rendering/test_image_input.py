"""vtkOctreeVolumeMapper on vtkImageData, as the demo's CT uses it (label
python, vtk; run under a display by ctest):

- LeafDepth 0 chooses the depth from the spacing: the leaf is the finest
  spacing, and the voxel centres are leaf centres, also where the extent
  does not start at 0;
- with slices farther apart than the pixels the octree has no empty layers
  between slices (FillBetweenSlices), and values are interpolated linearly
  between slices;
- with RootBounds around the voxel centres (what parallel ranks set) the
  build succeeds;
- gradient normals (ImageGradientNormals): a sphere's shading follows the
  sphere (Lambert's law), not the voxels;
- an image with nothing above ImageBackground says why (its values, or no
  scalars selected) once for an input, not at every frame;
- ImageBackground is compared exactly: a change in the seventh decimal
  rebuilds.
"""
import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

import octoray
from mapper_views import offscreen_view


def image(values, spacing, origin=(0.0, 0.0, 0.0), cells=False, extent_start=(0, 0, 0)):
    """vtkImageData holding a (nz, ny, nx) array: its point scalars
    "Scalars", or with `cells` the cell scalars "CellValues" of an image one
    point larger along each axis of more than one value (a single slice
    stays flat, one layer of points)."""
    counts = values.shape[::-1]
    im = vtk.vtkImageData()
    extent = []
    for lo, n in zip(extent_start, counts):
        extent += [lo, lo + n - 1 + (1 if cells and n > 1 else 0)]
    im.SetExtent(*extent)
    im.SetSpacing(*spacing)
    im.SetOrigin(*origin)
    arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).ravel(), deep=1)
    arr.SetName("CellValues" if cells else "Scalars")
    (im.GetCellData() if cells else im.GetPointData()).SetScalars(arr)
    return im


def render(data, size=(64, 64), configure=None, camera=None, lights=None):
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(data)
    if configure:
        configure(mapper)
    window, said = offscreen_view(mapper, size)
    ren = window.GetRenderers().GetFirstRenderer()
    if lights:
        lights(ren, ren.GetVolumes().GetLastProp().GetProperty())
    ren.ResetCamera()
    if camera:
        camera(ren.GetActiveCamera())
        ren.ResetCameraClippingRange()
    window.Render()
    assert mapper.GetLastUsedBackend() == mapper.BACKEND_CPU, said
    return mapper, window


def leaves(mapper):
    pd = vtk.vtkPolyData()
    mapper.GetLeafVoxels(pd)
    return vtk_to_numpy(pd.GetPoints().GetData()).astype(float), pd


def test_depth_from_the_spacing_and_leaves_on_the_voxels():
    # 10 x 10 x 10 voxels of 0.5: boxes 5 wide, depth ceil(log2(10)) = 4,
    # the leaf the spacing, one leaf per voxel, at the voxel.
    im = image(np.ones((10, 10, 10)), (0.5, 0.5, 0.5), origin=(3.0, -2.0, 100.0))
    mapper, _ = render(im)
    assert mapper.GetOctreeDepth() == 4
    assert mapper.GetLeafSize() == pytest.approx(0.5, rel=1e-5)
    assert mapper.GetNumberOfOctreePoints() == 1000
    centres, _ = leaves(mapper)
    assert len(centres) == 1000
    # Every leaf centre is a voxel centre (to float precision).
    grid = (centres - np.array([3.0, -2.0, 100.0])) / 0.5
    assert np.abs(grid - np.round(grid)).max() < 1e-3
    assert grid.min() > -1e-3 and grid.max() < 9 + 1e-3


def test_leaves_at_the_voxels_of_an_extent_not_starting_at_0():
    # Voxel (i, j, k) of an extent lies at Origin + (i, j, k) * spacing
    # whatever the extent's first index (the Wavelet source's -10..10, the
    # pieces of an image split over ranks); before, the octree was drawn as
    # if the extent began at 0, 5 spacings off here. The leaves' centres
    # are the voxels' positions, and the octree's bounds the image's.
    im = image(np.ones((4, 4, 4)), (0.5, 0.5, 0.5), origin=(1.0, 2.0, 3.0))
    im.SetExtent(-5, -2, 3, 6, 10, 13)
    mapper, _ = render(im)
    centres, _ = leaves(mapper)
    expected = np.array([[1.0 + 0.5 * i, 2.0 + 0.5 * j, 3.0 + 0.5 * k]
                         for k in range(10, 14) for j in range(3, 7) for i in range(-5, -1)])
    order = lambda p: p[np.lexsort((p[:, 0], p[:, 1], p[:, 2]))]
    assert len(centres) == 64
    np.testing.assert_allclose(order(centres), order(expected), atol=1e-4)
    voxel = [0.0] * 6
    mapper.GetVoxelBounds(voxel)
    bounds = im.GetBounds()
    for a in range(3):
        assert voxel[2 * a] == pytest.approx(bounds[2 * a] - 0.25, abs=1e-4)
        assert voxel[2 * a + 1] == pytest.approx(bounds[2 * a + 1] + 0.25, abs=1e-4)


@pytest.mark.parametrize("shape", [(3, 4, 5), (1, 4, 5)], ids=["volume", "one slice"])
def test_cell_scalars_draw_the_cells_as_voxels(shape):
    # Cell scalars of an image (ParaView colouring by a CELLS array, VTK's
    # ScalarModeToUseCellData): each cell is a voxel at its centre, with its
    # value, as the point image of the cells' centres draws: the same
    # leaves and values. A flat image's cells lie in its plane. Before, the
    # voxels were drawn without the values, and a warning said so.
    values = np.arange(np.prod(shape), dtype=float).reshape(shape) + 1.0
    spacing, origin = (0.5, 0.5, 0.5), (1.0, 2.0, 3.0)
    start = (-2, 0, 4)
    cells = image(values, spacing, origin, cells=True, extent_start=start)
    flat = (False, False, shape[0] == 1)  # an axis without cells: its one layer of points
    centre = [origin[a] + spacing[a] * (start[a] + (0.0 if flat[a] else 0.5)) for a in range(3)]
    points = image(values, spacing, origin=centre)
    got = []
    for data, mode in ((cells, "SetScalarModeToUseCellData"), (points, "SetScalarModeToDefault")):
        mapper, _ = render(data, configure=lambda m: getattr(m, mode)())
        centres, pd = leaves(mapper)
        scalars = vtk_to_numpy(pd.GetPointData().GetArray("Scalars")).astype(float)
        order = np.lexsort((centres[:, 0], centres[:, 1], centres[:, 2]))
        got.append((centres[order], scalars[order]))
    assert len(got[0][0]) == values.size
    np.testing.assert_allclose(got[0][0], got[1][0], atol=1e-4)
    np.testing.assert_allclose(got[0][1], got[1][1], rtol=1e-3)
    np.testing.assert_allclose(np.sort(got[0][1]), np.sort(values.ravel()), rtol=1e-3)


def test_a_short_cell_array_is_named():
    im = image(np.ones((2, 3, 3)), (1.0, 1.0, 1.0), cells=True)
    short = numpy_to_vtk(np.ones(5, dtype=np.float32), deep=1)
    short.SetName("Short")
    im.GetCellData().SetScalars(short)
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(im)
    mapper.SetScalarModeToUseCellData()
    window, said = offscreen_view(mapper, (32, 32))
    window.Render()
    assert any("The cell array 'Short' has 5 tuples for 18 cells; nothing to draw." in m for m in said), said


def test_no_empty_layers_between_slices():
    # 8 x 8 voxels of 1, 4 slices 2.5 apart (z 0 .. 7.5): planes of points
    # are filled in between, the leaf is the pixel (1), and every leaf layer
    # from the first slice to the last holds points: 9 of them.
    im = image(np.full((4, 8, 8), 100.0), (1.0, 1.0, 2.5))
    mapper, _ = render(im, configure=lambda m: m.SetImageBackground(50.0))
    assert mapper.GetLeafSize() == pytest.approx(1.0, rel=1e-5)
    centres, _ = leaves(mapper)
    layers = np.unique(np.round(centres[:, 2], 3))
    assert len(layers) == 9, layers
    assert np.allclose(np.diff(layers), 1.0, rtol=1e-4)
    assert layers[0] == pytest.approx(0.0, abs=1e-3) and layers[-1] == pytest.approx(8.0, abs=1e-3)
    assert len(centres) == 8 * 8 * 9


def test_values_are_interpolated_between_slices():
    # Two slices 4 apart, 0 and 100: the planes between them take the values
    # in between (25, 50, 75), and only those above the background (40) are
    # kept: the planes at z = 2, 3, 4 with 50, 75 and 100.
    values = np.zeros((2, 4, 4))
    values[1] = 100.0
    im = image(values, (1.0, 1.0, 4.0))
    mapper, _ = render(im, configure=lambda m: m.SetImageBackground(40.0))
    centres, pd = leaves(mapper)
    scalars = vtk_to_numpy(pd.GetPointData().GetArray("Scalars"))
    assert sorted(np.unique(np.round(scalars, 3))) == [50.0, 75.0, 100.0]
    assert sorted(np.unique(np.round(centres[:, 2], 3))) == [2.0, 3.0, 4.0]
    assert len(centres) == 3 * 16


def test_root_bounds_around_the_voxel_centres():
    # What parallel ranks set (the data's bounds): the voxels' boxes reach
    # past them, and their points must still lie inside the cube.
    im = image(np.full((3, 6, 6), 10.0), (1.0, 1.0, 3.0))
    b = im.GetBounds()
    errors = []
    mapper, _ = render(im, configure=lambda m: (m.SetRootBounds(b), m.SetImageBackground(1.0),
                                                  m.AddObserver("ErrorEvent", lambda *a: errors.append(a))))
    assert not errors
    assert mapper.GetNumberOfOctreePoints() > 6 * 6 * 3


def sphere(n=40, radius=15.0):
    c = (n - 1) / 2.0
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(float)
    d = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
    # A smooth edge (4 voxels wide), as a CT has: the iso-surface at 50 is the sphere.
    return image(100.0 * np.clip((radius - d) / 4.0 + 0.5, 0.0, 1.0), (1.0, 1.0, 1.0)), c, radius


def lambert_profile(gradient_normals):
    """The sphere seen down -z with a headlight, flat white, no ambient:
    brightness against the analytic cos of the angle to the viewer."""
    im, c, radius = sphere()

    def lights(ren, prop):
        prop.ShadeOn()
        prop.SetAmbient(0.0)
        prop.SetDiffuse(1.0)
        prop.SetSpecular(0.0)
        ctf = vtk.vtkColorTransferFunction()
        ctf.AddRGBPoint(0, 1, 1, 1)
        ctf.AddRGBPoint(100, 1, 1, 1)
        prop.SetColor(ctf)

    def camera(cam):
        cam.ParallelProjectionOn()
        cam.SetParallelScale(radius * 1.1)

    mapper, window = render(im, size=(120, 120), lights=lights, camera=camera,
                            configure=lambda m: (m.SetImageBackground(50.0),
                                                 m.SetImageGradientNormals(gradient_normals)))
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    rgb = vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars()).reshape(120, 120, -1)[:, :, 0] / 255.0
    # Pixel centres in data units (the parallel scale is half the height).
    u = (np.arange(120) + 0.5) / 120 * 2 * radius * 1.1 - radius * 1.1
    xx, yy = np.meshgrid(u, u)
    r = np.sqrt(xx ** 2 + yy ** 2) / radius
    inside = r < 0.9
    expected = np.sqrt(1 - r[inside] ** 2)
    return np.corrcoef(rgb[inside], expected)[0, 1], np.abs(rgb[inside] - expected).mean()


def test_gradient_normals_follow_the_sphere():
    correlation, error = lambert_profile(True)
    assert correlation > 0.97 and error < 0.04, (correlation, error)
    # Off, the normals come from the octree's occupancy: blockier.
    off_correlation, off_error = lambert_profile(False)
    assert off_error > 2 * error, (off_error, error)


@pytest.mark.parametrize("select,expected", [
    (None, ["Every voxel of the image is at or below the background 5; nothing to draw."]),
    ("NoSuchArray", ["SelectScalarArray 'NoSuchArray' names no point array of the input (its arrays: Scalars)",
                     "The image has no point scalars selected, so every voxel counts as 1, at or below the "
                     "background 5; nothing to draw. Select a point array"]),
])
def test_nothing_to_draw_is_said_once_with_its_reason(select, expected):
    """An image with no voxel above ImageBackground draws nothing and says
    why (its values, or no scalars selected: then the name selected is
    said too) once for that input, not at every frame; a modified input is
    said again."""
    data = image(np.ones((4, 4, 4)), (1.0, 1.0, 1.0))
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(data)
    mapper.SetImageBackground(5)
    if select:
        mapper.SetScalarModeToUsePointFieldData()
        mapper.SelectScalarArray(select)
    window, said = offscreen_view(mapper)
    ren = window.GetRenderers().GetFirstRenderer()
    for azimuth in (0, 10, 20):
        ren.GetActiveCamera().Azimuth(azimuth)
        window.Render()
    n = len(expected)
    assert len(said) == n and all(text in message for text, message in zip(expected, said)), said
    data.Modified()
    window.Render()
    window.Render()
    assert len(said) == 2 * n and all(text in message for text, message in zip(expected, said[n:])), said


def test_a_small_change_of_the_background_rebuilds():
    """ImageBackground is compared exactly: a change in the seventh decimal
    (a float image of densities) gives the octree of the new threshold."""
    z, y, x = np.mgrid[:20, :20, :20]
    values = np.maximum(0, 10 - np.sqrt((x - 9.5) ** 2 + (y - 9.5) ** 2 + (z - 9.5) ** 2)) * 1e-8
    data = image(values, (1.0, 1.0, 1.0))

    def configure(mapper):
        mapper.SetImageBackground(1e-9)
    mapper, window = render(data, configure=configure)
    low = mapper.GetNumberOfOctreePoints()
    mapper.SetImageBackground(5e-8)
    window.Render()
    assert mapper.GetNumberOfBuilds() == 2
    assert mapper.GetNumberOfOctreePoints() == int((values > 5e-8).sum()) < low


def test_vector_voxels_go_by_the_value_the_colour_function_reads():
    """A 3-component image through the transfer functions in Magnitude
    mode: a voxel is a point where its magnitude is above ImageBackground,
    and the picture equals that of a 1-component image of the magnitudes
    (float). Before, the largest component was compared and component 0
    drawn."""
    vectors = np.random.default_rng(7).normal(size=(12, 12, 12, 3)).astype(np.float32)
    magnitude = np.linalg.norm(vectors.astype(float), axis=3)
    vector_image = image(magnitude, (1.0, 1.0, 1.0))
    components = numpy_to_vtk(vectors.reshape(-1, 3), deep=1)
    components.SetName("Velocity")
    vector_image.GetPointData().SetScalars(components)

    def draw(data):
        def lights(ren, prop):
            ramp = vtk.vtkColorTransferFunction()
            ramp.AddRGBPoint(0.0, 0, 0, 1)
            ramp.AddRGBPoint(3.0, 1, 0, 0)
            ramp.SetVectorModeToMagnitude()
            prop.SetColor(ramp)
        mapper, window = render(data, configure=lambda m: m.SetImageBackground(1.5), lights=lights)
        grab = vtk.vtkWindowToImageFilter()
        grab.SetInput(window)
        grab.Update()
        return mapper, vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars()).copy()
    mapper, drawn = draw(vector_image)
    expected_mapper, expected = draw(image(magnitude, (1.0, 1.0, 1.0)))
    assert mapper.GetNumberOfOctreePoints() == int((magnitude.astype(np.float32) > 1.5).sum())
    assert expected_mapper.GetNumberOfOctreePoints() == mapper.GetNumberOfOctreePoints()
    assert (drawn == expected).all(), (drawn != expected).any(axis=1).sum()
