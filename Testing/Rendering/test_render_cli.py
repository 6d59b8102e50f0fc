"""python3 -m octoray.render and the mappers from Python (label python, vtk).

Run under xvfb-run by ctest (the renderer opens an offscreen OpenGL window).
"""
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
import vtk
import octoray
from mapper_views import assert_said_once, gathered, offscreen_view
from octoray.png import read_png

DATA = os.environ.get("OCTORAY_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "Data"))
PARTICLES = os.path.join(DATA, "Particles", "lidar_simple.particles")


def run(*args):
    return subprocess.run([sys.executable, "-m", "octoray.render", *args],
                          capture_output=True, text=True, timeout=300)


def read_pixels(path):
    """width, height and the pixels, one row of components each."""
    rows = read_png(path)
    h, w = rows.shape[:2]
    return w, h, rows.reshape(h * w, -1)


def test_mappers_are_in_the_package():
    m = octoray.vtkOctreeVolumeMapper()
    assert isinstance(m, octoray.vtkOctreeVolumeMapper)
    assert m.GetRequestedBackend() == m.BACKEND_AUTO  # CUDA where usable, chosen at the first render
    assert m.GetCudaDevice() == -1 and m.GetUseCudaGLInterop()
    assert octoray.vtkCudaOctreeVolumeMapper().GetRequestedBackend() == m.BACKEND_CUDA
    cpu = octoray.vtkCPUOctreeVolumeMapper()
    assert cpu.GetRequestedBackend() == cpu.BACKEND_CPU
    cpu.SetLeafDepth(7)
    cpu.SetBlendModeToSurface()
    assert cpu.GetBlendMode() == octoray.vtkOctreeVolumeMapper.SURFACE_BLEND
    assert "LeafDepth: 7" in str(cpu)


def random_cloud(n, seed=1):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk
    cloud = vtk.vtkPolyData()
    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(np.random.default_rng(seed).random((n, 3)), deep=1))
    cloud.SetPoints(points)
    return cloud


def test_the_octree_getters_describe_the_current_input():
    """After the input becomes an empty one (which VTK does not even ask the
    mapper to draw), the getters describe no octree; the first input again
    gives its octree back without a rebuild."""
    import vtk
    cloud = random_cloud(3000)
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(cloud)
    window, said = offscreen_view(mapper)
    window.Render()
    built = (mapper.GetNumberOfOctreePoints(), mapper.GetOctreeDepth(), mapper.GetLeafSize())
    assert built[0] == 3000 and built[1] > 0 and built[2] > 0
    mapper.SetInputData(vtk.vtkPolyData())
    window.Render()
    assert (mapper.GetNumberOfOctreePoints(), mapper.GetOctreeDepth(), mapper.GetLeafSize()) == (0, 0, 0.0)
    mapper.SetInputData(cloud)
    window.Render()
    assert (mapper.GetNumberOfOctreePoints(), mapper.GetOctreeDepth(), mapper.GetLeafSize()) == built
    assert mapper.GetNumberOfBuilds() == 1 and said == [], said


def test_lights_past_the_engines_say_so_once():
    """The engine takes eight lights: with ten, one warning over frames,
    naming how many are ignored."""
    import vtk
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(random_cloud(1000))
    window, said = offscreen_view(mapper)
    ren = window.GetRenderers().GetFirstRenderer()
    for _ in range(10):
        ren.AddLight(vtk.vtkLight())
    assert_said_once(window, said, "takes at most 8 lights; 2 more are ignored.")


def test_clipping_planes_past_the_engines_say_so_once():
    """The engine takes twelve planes, a cropping box's six faces among
    them: with eight planes and a cropping box, one warning over frames,
    naming how many are ignored; the clipping planes clip."""
    import vtk
    mapper, window, said, whole = drawn_cloud()
    for _ in range(8):
        plane = vtk.vtkPlane()
        plane.SetOrigin(0.5, 0.5, 0.5)
        plane.SetNormal(1, 0, 0)
        mapper.AddClippingPlane(plane)
    mapper.SetCropping(1)
    mapper.SetCroppingRegionFlagsToSubVolume()
    mapper.SetCroppingRegionPlanes(0, 1, 0, 1, 0, 1)
    assert_said_once(window, said,
                     "takes at most 12 clipping planes, a cropping box's six faces among them; 2 more are ignored.")
    clipped = window_pixels(window)
    assert (clipped != whole).any(axis=1).sum() > 50


def test_cropping_regions_other_than_the_sub_volume_say_so_once():
    """VTK's fence, cross and inverted cropping regions are not convex: the
    engine does not crop to them, says so once, and draws the volume whole."""
    mapper, window, said, whole = drawn_cloud()
    mapper.SetCropping(1)
    mapper.SetCroppingRegionFlagsToCross()
    mapper.SetCroppingRegionPlanes(0.2, 0.8, 0.2, 0.8, 0.2, 0.8)
    assert_said_once(window, said, "crops to the sub-volume only (SetCroppingRegionFlagsToSubVolume); with "
                                   "CroppingRegionFlags 0x417410 the volume is drawn uncropped.")
    assert (window_pixels(window) == whole).all()


def drawn_cloud():
    """A CPU mapper drawing 1000 points in a 48x48 window, drawn once:
    (mapper, window, the messages it said, the pixels)."""
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(random_cloud(1000))
    window, said = offscreen_view(mapper, (48, 48))
    window.Render()
    return mapper, window, said, window_pixels(window)


def window_pixels(window):
    """The window's RGB pixels, one row each."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    return vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars()).reshape(-1, 3).copy()


def intensity_cloud_view():
    """1000 random points with a point array "Intensity" (all 1) drawn once
    by a CPU mapper: (mapper, window, the mapper's messages)."""
    import vtk
    cloud = random_cloud(1000)
    intensity = vtk.vtkFloatArray()
    intensity.SetName("Intensity")
    intensity.SetNumberOfTuples(1000)
    intensity.Fill(1.0)
    cloud.GetPointData().AddArray(intensity)
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(cloud)
    window, said = offscreen_view(mapper)
    window.Render()
    return mapper, window, said


def test_a_named_array_the_input_lacks_is_said_once():
    """ReflectivityArrayName set to a name the input has no array of (a
    misspelling): one warning over frames, naming the property, the name
    and the arrays there are. The default names missing say nothing: most
    inputs have no reflectivity."""
    mapper, window, said = intensity_cloud_view()
    assert said == []
    mapper.SetReflectivityArrayName("reflectivity")
    assert_said_once(window, said, "ReflectivityArrayName 'reflectivity' names no point array of the input "
                                   "(its arrays: Intensity); nothing reflects.")


@pytest.mark.parametrize("mode", ["SetScalarModeToUsePointFieldData", "SetScalarModeToUseCellFieldData"])
def test_a_scalar_array_the_input_lacks_is_said_once(mode):
    """SelectScalarArray naming an array the input lacks (a misspelling, or
    in ParaView an array that some blocks of composite data lack): the
    voxels are drawn as with no array, and one warning over frames names
    the array, which kind of array it looked for and those there are."""
    mapper, window, said = intensity_cloud_view()
    plain = window_pixels(window)
    getattr(mapper, mode)()
    mapper.SelectScalarArray("intensity")
    kind, arrays = ("cell", "none") if "Cell" in mode else ("point", "Intensity")
    assert_said_once(window, said, "SelectScalarArray 'intensity' names no %s array of the input (its arrays: %s); "
                                   "the voxels are drawn in their own colours, or white." % (kind, arrays))
    assert (window_pixels(window) == plain).all()


def test_a_cuda_request_without_cuda_keeps_the_cpu_octree():
    """Asking for CUDA where it cannot be had says why once and keeps the
    CPU engine drawing, octree and all (it made a new CPU engine and built
    again; the message said "not available" twice)."""
    if octoray.vtkOctreeVolumeMapper.IsCudaAvailable():
        pytest.skip("CUDA is available here")
    mapper = octoray.vtkOctreeVolumeMapper()
    mapper.SetInputData(random_cloud(1000))
    window, said = offscreen_view(mapper)
    window.Render()
    assert mapper.GetNumberOfBuilds() == 1 and said == []
    mapper.SetRequestedBackendToCuda()
    assert_said_once(window, said, "octoray: the CUDA backend is not available: ")
    assert said[0].rstrip().endswith("; using the CPU backend") and said[0].count("not available") == 1, said
    assert mapper.GetNumberOfBuilds() == 1 and mapper.GetLastUsedBackendName() == "CPU"


def test_composite_data_is_refused_once_by_name():
    """Composite data through a pipeline connection: one warning naming it
    and the filter that merges it (it was "No input." at every frame)."""
    group = vtk.vtkMultiBlockDataGroupFilter()
    group.AddInputData(random_cloud(100))
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputConnection(group.GetOutputPort())
    window, said = offscreen_view(mapper)
    executive = vtk.vtkStringOutputWindow()  # the pipeline's own complaint, kept off the test's output
    previous = vtk.vtkOutputWindow.GetInstance()
    vtk.vtkOutputWindow.SetInstance(executive)
    try:
        assert_said_once(window, said, "The input is composite data (a vtkMultiBlockDataSet), which the mapper "
                         "does not draw: merge its blocks into one point set first (vtkMergeBlocks")
    finally:
        vtk.vtkOutputWindow.SetInstance(previous)


def test_a_rectilinear_grid_is_refused_by_name():
    """SetInputData takes point sets and images: a rectilinear grid, which
    vtkVolumeMapper has an overload for, is an error naming its type, as any
    other data set is, and leaves no input (it printed pipeline errors at
    every frame)."""
    import vtk
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    said = gathered(mapper)
    mapper.SetInputData(vtk.vtkRectilinearGrid())
    assert len(said) == 1 and "not a vtkRectilinearGrid" in said[0], said
    assert mapper.GetInput() is None
    mapper.SetInputData(vtk.vtkImageData())
    assert mapper.GetInput().IsA("vtkImageData") and len(said) == 1


def test_root_bounds_that_miss_the_points_are_named_once():
    """RootBounds that do not hold the points: one warning naming them, no
    build tried (it said 'point 0 lies outside the root cube' at every
    frame)."""
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(random_cloud(1000))
    mapper.SetRootBounds(0, 0.5, 0, 1, 0, 1)
    window, said = offscreen_view(mapper)
    assert_said_once(window, said, "RootBounds (0, 0.5, 0, 1, 0, 1) do not hold the input's bounds")
    assert mapper.GetNumberOfBuilds() == 0


def test_a_failed_build_is_said_once_until_the_input_changes():
    """A build the engine refuses (a NaN coordinate) is not tried again at
    every frame: one error, until the input changes."""
    cloud = random_cloud(1000)
    cloud.GetPoints().SetPoint(5, float("nan"), 0, 0)
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(cloud)
    window, said = offscreen_view(mapper)
    assert_said_once(window, said, "point 5 has a non-finite coordinate")
    cloud.GetPoints().SetPoint(5, 0.5, 0.5, 0.5)
    cloud.GetPoints().Modified()
    window.Render()
    assert len(said) == 1 and mapper.GetNumberOfBuilds() == 1


def test_an_image_with_nothing_to_draw_is_not_scanned_again():
    """An image with every voxel at or below the background is said once
    and not scanned again at every frame (each frame scanned it, with 45
    progress events at 256^3), until the image changes."""
    from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    image = vtk.vtkImageData()
    image.SetDimensions(32, 32, 32)
    values = numpy_to_vtk(np.zeros(32 ** 3, np.float32), deep=1)
    image.GetPointData().SetScalars(values)
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(image)
    window, said = offscreen_view(mapper)
    window.Render()
    progress = []
    mapper.AddObserver("ProgressEvent", lambda caller, event: progress.append(1))
    assert_said_once(window, said, "Every voxel of the image is at or below the background 0; nothing to draw.")
    assert progress == [] and mapper.GetNumberOfBuilds() == 0
    vtk_to_numpy(values)[:100] = 5.0
    values.Modified()
    window.Render()
    assert progress and mapper.GetNumberOfBuilds() == 1 and mapper.GetNumberOfOctreePoints() == 100


def test_a_short_point_array_is_refused_by_name():
    """A point array with fewer tuples than points (the engine reads one a
    point) is refused, once, naming the array; nothing is drawn, nothing
    crashes."""
    import vtk
    cloud = random_cloud(20000)
    short = vtk.vtkFloatArray()
    short.SetName("Reflectivity")
    short.SetNumberOfTuples(1)
    cloud.GetPointData().AddArray(short)
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(cloud)
    window, said = offscreen_view(mapper)
    assert_said_once(window, said,
                     "The point array 'Reflectivity' has 1 tuples for 20000 points; nothing to draw.")
    assert mapper.GetNumberOfBuilds() == 0


def test_non_finite_scalars_leave_the_transfer_function_its_range():
    """A NaN or an infinity among the scalars: the transfer function spans
    the finite values (a NaN first failed the frame, an infinity turned the
    cloud one colour)."""
    from vtk.util.numpy_support import numpy_to_vtk
    rng = np.random.default_rng(2)
    for bad in (float("nan"), float("inf")):
        cloud = random_cloud(2000, seed=3)
        scalars = numpy_to_vtk(rng.random(2000).astype(np.float32), deep=1)
        scalars.SetValue(0, bad)
        cloud.GetPointData().SetScalars(scalars)
        rgb, said = coloured_by(cloud, ramp=((0.0, (1, 0, 0)), (1.0, (0, 0, 1))))[:2]
        rgb = rgb.astype(int)
        reddish = ((rgb[:, 0] > 2 * rgb[:, 2]) & (rgb[:, 0] > 60)).mean()
        bluish = ((rgb[:, 2] > 2 * rgb[:, 0]) & (rgb[:, 2] > 60)).mean()
        assert said == [] and reddish > 0.02 and bluish > 0.02, (bad, said, reddish, bluish)


@pytest.mark.parametrize("setter, kept", [
    ("DepthCue", 0.0), ("ImageSampleDistance", 1.0), ("LODPixelThreshold", 1.0), ("ImageBackground", 0.0)])
def test_a_nan_setting_is_refused_by_name(setter, kept):
    """vtkSetClampMacro lets a NaN through; these setters refuse it with an
    error naming the property, and keep the value."""
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    said = gathered(mapper)
    getattr(mapper, "Set" + setter)(float("nan"))
    assert getattr(mapper, "Get" + setter)() == kept
    assert len(said) == 1 and f"{setter} must be a number, not NaN; it stays {kept:g}." in said[0], said


def test_a_nan_shading_number_is_said_once_and_keeps_the_octree():
    """A NaN ambient (vtkVolumeProperty lets one through; it drew every pixel
    black): one error over frames naming it, nothing drawn, the octree kept;
    once it is a number again the cloud is drawn as before."""
    mapper, window, said, whole = drawn_cloud()
    prop = window.GetRenderers().GetFirstRenderer().GetVolumes().GetLastProp().GetProperty()
    ambient = prop.GetAmbient()
    prop.SetAmbient(float("nan"))
    assert_said_once(window, said, "the ambient coefficient must be a finite number, got nan")
    assert not window_pixels(window).any()
    prop.SetAmbient(ambient)
    window.Render()
    assert (window_pixels(window) == whole).all() and mapper.GetNumberOfBuilds() == 1 and len(said) == 1


def test_a_cropping_box_that_is_not_finite_is_said_once_and_keeps_the_octree():
    """CroppingRegionPlanes holding a NaN: one error over frames naming
    them, nothing drawn, the octree kept (before, the engine's error named
    "clipping plane 0", which the user never set); a finite box again crops
    as it did."""
    mapper, window, said, whole = drawn_cloud()
    mapper.SetCropping(1)
    mapper.SetCroppingRegionFlagsToSubVolume()
    mapper.SetCroppingRegionPlanes(-1e9, 1e9, -1e9, 1e9, -1e9, 1e9)
    window.Render()
    assert (window_pixels(window) == whole).all()
    mapper.SetCroppingRegionPlanes(float("nan"), 1e9, -1e9, 1e9, -1e9, 1e9)
    assert_said_once(window, said, "CroppingRegionPlanes (nan, 1e+09, -1e+09, 1e+09, -1e+09, 1e+09): each must be "
                     "finite; nothing is drawn.")
    assert not window_pixels(window).any()
    mapper.SetCroppingRegionPlanes(-1e9, 1e9, -1e9, 1e9, -1e9, 1e9)
    window.Render()
    assert (window_pixels(window) == whole).all() and mapper.GetNumberOfBuilds() == 1 and len(said) == 1


@pytest.mark.parametrize("mode, expected", [
    ("ISOSURFACE_BLEND", "BlendMode ISOSURFACE_BLEND is drawn as SURFACE_BLEND: the first voxel a ray meets, "
        "not the volume property's iso-values."),
    ("SLICE_BLEND", "BlendMode SLICE_BLEND is drawn as SURFACE_BLEND: the first voxel a ray meets, not the volume "
        "property's slice function."),
    (77, "BlendMode 77 is not one of VTK's; it is drawn as SURFACE_BLEND, the first voxel a ray meets."),
])
def test_a_blend_mode_the_engine_has_not_is_said_once(mode, expected):
    """Blend modes the engine has none of its own for draw the first hit,
    as SURFACE_BLEND does, and say so once over frames."""
    mapper, window, said, whole = drawn_cloud()
    mapper.SetBlendMode(getattr(mapper, mode) if isinstance(mode, str) else mode)
    assert_said_once(window, said, expected)
    assert (window_pixels(window) == whole).all()


@pytest.mark.parametrize("configure, expected", [
    (lambda p: p.SetGradientOpacity(ramp_up()),
     "The volume property's gradient opacity is not applied; the octree's opacity is the scalar opacity's alone"),
    (lambda p: p.SetTransferFunctionModeTo2D(),
     "The volume property's 2D transfer function (TransferFunctionMode TF_2D) is not applied"),
    (lambda p: (p.SetGradientOpacity(ramp_up()), p.DisableGradientOpacityOn()), None),
    (lambda p: p.GetGradientOpacity(), None),
])
def test_volume_property_parts_the_engine_does_not_apply_are_said_once(configure, expected):
    """A gradient opacity (VTK's CT examples set one) or a 2D transfer
    function: one warning over frames, the picture as without; a gradient
    opacity switched off says nothing, nor does VTK's default one, 1
    everywhere, which GetGradientOpacity makes (and DeepCopy with it)."""
    mapper, window, said, whole = drawn_cloud()
    configure(window.GetRenderers().GetFirstRenderer().GetVolumes().GetLastProp().GetProperty())
    if expected is None:
        for _ in range(3):
            window.Render()
        assert said == [], said
    else:
        assert_said_once(window, said, expected)
    assert (window_pixels(window) == whole).all()


def ramp_up():
    import vtk
    ramp = vtk.vtkPiecewiseFunction()
    ramp.AddPoint(0, 0.0)
    ramp.AddPoint(100, 1.0)
    return ramp


def coloured_by(cloud, configure=lambda ramp: None, ramp=((0.0, (0, 0, 1)), (3.0, (1, 0, 0)))):
    """(the RGB pixels, what the mapper said, the mapper, its colour
    function, the window) of `cloud` drawn by a CPU mapper in a 64x64
    window through `ramp`'s colours (blue to red by default), the colour
    function then given to `configure`."""
    import vtk
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(cloud)
    window, said = offscreen_view(mapper, (64, 64))
    function = vtk.vtkColorTransferFunction()
    for value, rgb in ramp:
        function.AddRGBPoint(value, *rgb)
    configure(function)
    window.GetRenderers().GetFirstRenderer().GetVolumes().GetLastProp().GetProperty().SetColor(function)
    window.Render()
    return window_pixels(window), said, mapper, function, window


def test_vector_scalars_are_drawn_as_the_colour_function_maps_vectors():
    """3-component scalars go through the transfer functions as the colour
    function's VectorMode and VectorComponent say (ParaView's colour map:
    Magnitude, X, Y, Z): each picture equals the one of a 1-component array
    holding that value, in float. Changing the mode rebuilds the octree."""
    from vtk.util.numpy_support import numpy_to_vtk
    vectors = np.random.default_rng(4).normal(size=(3000, 3))
    picks = {"magnitude": (lambda r: r.SetVectorModeToMagnitude(), np.linalg.norm(vectors, axis=1)),
             "component 2": (lambda r: (r.SetVectorModeToComponent(), r.SetVectorComponent(2)), vectors[:, 2])}
    for name, (configure, values) in picks.items():
        cloud = random_cloud(3000, seed=5)
        cloud.GetPointData().SetScalars(numpy_to_vtk(vectors, deep=1))
        drawn, said, mapper, ramp, window = coloured_by(cloud, configure)
        reference = random_cloud(3000, seed=5)
        reference.GetPointData().SetScalars(numpy_to_vtk(values.astype(np.float32), deep=1))
        expected = coloured_by(reference, lambda r: None)[0]
        assert said == [] and (drawn == expected).all(), (name, said, (drawn != expected).any(axis=1).sum())
    ramp.SetVectorModeToMagnitude()
    window.Render()
    assert mapper.GetNumberOfBuilds() == 2 and (window_pixels(window) != drawn).any()


@pytest.mark.parametrize("components, independent, configure, expected", [
    (3, True, lambda r: r.SetVectorComponent(3),
     "The colour function's VectorComponent 3 is not one of the 3 components of the scalars 'Velocity'; "
     "component 2 is drawn."),
    (2, False, lambda r: None,
     "The scalars 'Velocity' have 2 dependent components (IndependentComponents off), which the octree draws "
     "only as 3 or 4 (colours); it draws their component 0 through the transfer functions."),
])
def test_scalar_components_drawn_otherwise_are_said_once(components, independent, configure, expected):
    """A VectorComponent past the scalars' components is clamped, as
    vtkScalarsToColors clamps it; dependent components other than colours
    (VTK draws 2 as a value and its opacity) go through the transfer
    functions. Each is said once over frames."""
    from vtk.util.numpy_support import numpy_to_vtk
    cloud = random_cloud(1000)
    scalars = numpy_to_vtk(np.random.default_rng(6).random((1000, components)), deep=1)
    scalars.SetName("Velocity")
    cloud.GetPointData().SetScalars(scalars)
    drawn, said, mapper, ramp, window = coloured_by(cloud, configure)
    window.GetRenderers().GetFirstRenderer().GetVolumes().GetLastProp().GetProperty() \
        .SetIndependentComponents(independent)
    assert_said_once(window, said, expected)


def test_render_particles(tmp_path):
    out = tmp_path / "out.png"
    r = run(PARTICLES, "-o", str(out), "--backend", "cpu", "--size", "160x120", "--mode", "phong",
            "--azimuth", "30", "--elevation", "20")
    assert r.returncode == 0, r.stderr
    for word in ("backend: CPU", "load:", "build:", "render:"):
        assert word in r.stdout
    # The progress bar: into a pipe it is written once, finished, not redrawn.
    assert r.stderr.count("reading") == 1 and "100%" in r.stderr, r.stderr
    w, h, rgb = read_pixels(str(out))
    assert (w, h) == (160, 120)
    # The cloud covers a real part of the picture (the background is black).
    covered = (rgb[:, :3].max(axis=1) > 0).sum()
    assert covered > 0.05 * w * h


def test_render_modes_differ(tmp_path):
    pictures = []
    for mode in ("surface", "mip"):
        out = tmp_path / (mode + ".png")
        r = run(PARTICLES, "-o", str(out), "--backend", "cpu", "--size", "96x96", "--mode", mode)
        assert r.returncode == 0, r.stderr
        pictures.append(read_pixels(str(out))[2])
    assert (pictures[0] != pictures[1]).any()


def test_clip_and_crop_reach_the_mapper(tmp_path):
    """--clip's plane keeps the side its normal points to: below every point
    it keeps the picture as it was, above every point it leaves nothing;
    --crop to the low half in x leaves part of the cloud."""
    def drawn(*cut):
        out = tmp_path / ("cut%d.png" % len(list(tmp_path.iterdir())))
        r = run(PARTICLES, "-o", str(out), "--backend", "cpu", "--size", "96x96", *cut)
        assert r.returncode == 0, r.stderr
        return read_pixels(str(out))[2][:, :3], r.stdout
    whole, _ = drawn()
    kept, said = drawn("--clip", "0", "0", "-1000000000", "0", "0", "1")
    assert (kept == whole).all() and "cut: 1 clipping plane" in said, said
    nothing, _ = drawn("--clip", "0", "0", "1e9", "0", "0", "1")
    assert not nothing.any()
    half, said = drawn("--crop", "0", "0.5", "0", "1", "0", "1")
    covered = [(p.max(axis=1) > 0).sum() for p in (whole, half)]
    assert 0.2 * covered[0] < covered[1] < 0.8 * covered[0], covered
    assert "cut: 0 clipping planes, cropped to a box" in said, said


@pytest.mark.parametrize("cut, expected", [
    (("--clip", "0", "0", "0", "0", "0", "0"), "--clip needs a finite origin and a non-zero normal, got 0 0 0 0 0 0"),
    (("--clip", "nan", "0", "0", "0", "0", "1"),
     "--clip needs a finite origin and a non-zero normal, got nan 0 0 0 0 1"),
    (("--crop", "0.5", "0.2", "0", "1", "0", "1"),
     "--crop needs fractions 0 <= low < high <= 1 on each axis, got 0.5 0.2 0 1 0 1"),
])
def test_bad_cuts_are_errors_naming_the_option(tmp_path, cut, expected):
    r = run(PARTICLES, "-o", str(tmp_path / "x.png"), *cut)
    assert r.returncode == 2 and expected in r.stderr, r.stderr
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("option, expected", [
    (("--size", "100000x100000"), "argument --size: at most 16384 pixels a side (OpenGL's usual limit), got "
     "'100000x100000'"),
    (("--zoom", "0"), "argument --zoom: expected a number above 0, got '0'"),
    (("--zoom", "-1"), "argument --zoom: expected a number above 0, got '-1'"),
    (("--zoom", "nan"), "argument --zoom: expected a finite number, got 'nan'"),
    (("--azimuth", "nan"), "argument --azimuth: expected a finite number, got 'nan'"),
    (("--elevation", "inf"), "argument --elevation: expected a finite number, got 'inf'"),
])
def test_bad_view_options_are_errors_naming_the_option(tmp_path, option, expected):
    """A size past OpenGL's textures flooded its errors and crashed; --zoom 0
    or -1 were ignored; NaN angles or zoom made the camera singular."""
    r = run(PARTICLES, "-o", str(tmp_path / "x.png"), *option)
    assert r.returncode == 2 and expected in r.stderr, r.stderr
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("name, expected", [
    ("", "-o names a folder, {tmp}/; give the PNG file to write"),
    ("out.jpg", "-o writes a PNG picture; name the file .png, got {tmp}/out.jpg"),
    ("missing/out.png", "-o: no folder {tmp}/missing to write out.png into"),
])
def test_a_bad_output_is_said_before_reading(tmp_path, name, expected):
    """Said first, not after reading and drawing: a folder got VTK's "Ran
    out of disk space", a .jpg name PNG bytes."""
    r = run(PARTICLES, "-o", str(tmp_path) + "/" + name)
    assert r.returncode == 2 and expected.format(tmp=tmp_path) in r.stderr, r.stderr
    assert "load:" not in r.stdout and "reading" not in r.stderr


def test_render_dicom_folder(tmp_path):
    out = tmp_path / "ct.png"
    r = run(os.path.join(DATA, "DICOM", "CT_small"), "-o", str(out), "--backend", "cpu", "--size", "96x96",
            "--mode", "mip", "--background", "-5000", "-500")
    assert r.returncode == 0, r.stderr
    assert "backend: CPU" in r.stdout
    assert read_pixels(str(out))[2][:, :3].max() > 0


def test_slice_stack_particles_shade_by_the_gradient(tmp_path):
    """--particles --mode phong: the reader's gradient normals (the image
    output's, which python.slice_stack_closed compares), not PCL's, which
    striped a CT along its lattice's rows; --normals none draws without
    them, by the octree's occupancy."""
    pictures = {}
    for normals in ("auto", "none"):
        out = tmp_path / ("ct-%s.png" % normals)
        r = run(os.path.join(DATA, "DICOM", "CT_small"), "-o", str(out), "--backend", "cpu", "--size", "96x96",
                "--mode", "phong", "--preset", "ct-bone", "--particles", "--normals", normals)
        assert r.returncode == 0, r.stderr
        assert "normals:" not in r.stdout, r.stdout
        pictures[normals] = read_pixels(str(out))[2]
    assert pictures["auto"][:, :3].max() > 0 and (pictures["auto"] != pictures["none"]).any()


def test_render_slice_stack_closed(tmp_path):
    """A CT series (slices 2.5 mm apart, pixels 0.488 mm): filled between
    slices, leaves of the pixel size; the same points from the stack's
    volume (--image); unfilled, leaves of the slice spacing."""
    folder = os.path.join(DATA, "DICOM", "CT5N")
    common = ["--backend", "cpu", "--size", "96x96", "--background", "-10000", "-500", "--parallel"]

    def values(stdout):
        return {k: v.split()[0] for k, v in (line.split(": ", 1) for line in stdout.splitlines() if ": " in line)}

    runs = {}
    for name, extra in (("particles", []), ("image", ["--image"]), ("unfilled", ["--no-fill"])):
        r = run(folder, "-o", str(tmp_path / (name + ".png")), *common, *extra)
        assert r.returncode == 0, r.stderr
        runs[name] = values(r.stdout)
    assert abs(float(runs["particles"]["leaf"]) - 0.488281) < 1e-4
    assert runs["image"]["points"] == runs["particles"]["points"]
    assert runs["image"]["leaf"] == runs["particles"]["leaf"]
    assert abs(float(runs["unfilled"]["leaf"]) - 2.5) < 1e-4
    assert int(runs["unfilled"]["points"]) * 4 < int(runs["particles"]["points"])


def test_a_pattern_reads_every_slice_it_names(tmp_path):
    """A printf pattern of slice names without --range reads from the
    lowest number it names a file for to the highest (it read slice 0 alone
    before), and a gap between them is the reader's error naming the file."""
    from vtk.util.numpy_support import numpy_to_vtk
    for k in range(3, 7):
        image = vtk.vtkImageData()
        image.SetDimensions(8, 6, 1)
        image.GetPointData().SetScalars(numpy_to_vtk(np.full(48, 200, np.uint8), deep=1))
        writer = vtk.vtkPNGWriter()
        writer.SetInputData(image)
        writer.SetFileName(str(tmp_path / ("s_%02d.png" % k)))
        writer.Write()
    pattern = str(tmp_path / "s_%02d.png")
    r = run(pattern, "-o", str(tmp_path / "p.png"), "--backend", "cpu", "--size", "64x48")
    assert r.returncode == 0, r.stderr
    assert "input: 192 voxels (8 x 6 x 4)" in r.stdout
    os.remove(str(tmp_path / "s_05.png"))
    r = run(pattern, "-o", str(tmp_path / "p.png"), "--backend", "cpu", "--size", "64x48")
    assert r.returncode == 1
    assert r.stderr.splitlines()[-1].startswith("error: slice file '%s' is missing" % (tmp_path / "s_05.png"))


def test_a_file_with_a_percent_sign_is_read_as_a_file(tmp_path):
    folder = tmp_path / "100%done"
    folder.mkdir()
    shutil.copy(PARTICLES, str(folder / "scan_50%s.particles"))
    r = run(str(folder / "scan_50%s.particles"), "-o", str(tmp_path / "x.png"), "--backend", "cpu",
            "--size", "64x48")
    assert r.returncode == 0, r.stderr
    assert "input: " in r.stdout and "points" in r.stdout


def test_missing_input_is_an_error(tmp_path):
    r = run(str(tmp_path / "nothing.particles"), "-o", str(tmp_path / "x.png"))
    assert r.returncode != 0
    assert "no such file" in r.stderr
    assert not (tmp_path / "x.png").exists()


def test_bad_line_is_named_once(tmp_path):
    """A file the reader refuses: the reader's message, with file, line and
    column, as the last line; no VTK pipeline report, and no progress bar
    that claims the read finished (VTK reports 100 % after a failure too)."""
    bad = tmp_path / "bad.txt"
    bad.write_text("1 2 3\n4 abc 6\n")
    r = run(str(bad), "-o", str(tmp_path / "x.png"), "--backend", "cpu")
    assert r.returncode == 1
    assert r.stderr.splitlines()[-1] == "error: %s:2:3: expected a number for column 2 (y), found 'abc'" % bad
    assert "vtkExecutive" not in r.stderr, r.stderr
    assert "100%" not in r.stderr, r.stderr
    assert not (tmp_path / "x.png").exists()


def test_points_at_one_place_show_their_voxel(tmp_path):
    """The camera frames the voxels, not only the points: points all at one
    place fill a leaf with a corner at them, seen whole inside the frame."""
    same = tmp_path / "same.txt"
    same.write_text("1 2 3\n1 2 3\n1 2 3\n")
    out = tmp_path / "same.png"
    r = run(str(same), "-o", str(out), "--backend", "cpu", "--size", "80x60")
    assert r.returncode == 0, r.stderr
    w, h, rgb = read_pixels(str(out))
    drawn = rgb[:, :3].max(axis=1).reshape(h, w) > 0
    assert 0.1 < drawn.mean() < 0.7, drawn.mean()
    assert not (drawn[0].any() or drawn[-1].any() or drawn[:, 0].any() or drawn[:, -1].any())



def test_render_pcd(tmp_path):
    """A .pcd file goes to vtkPCDReader: a binary PCD of a coloured 20 x 20
    grid written here."""
    import struct
    pcd = tmp_path / "grid.pcd"
    n = 400
    body = b"".join(struct.pack("<fffI", i % 20, i // 20, 0.0, 0xFF0000 | (i % 256) << 8)
                    for i in range(n))
    pcd.write_bytes(("VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
                     "WIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA binary\n"
                     % (n, n)).encode() + body)
    out = tmp_path / "grid.png"
    r = run(str(pcd), "-o", str(out), "--backend", "cpu", "--size", "96x96")
    assert r.returncode == 0, r.stderr
    assert "points: 400" in r.stdout
    w, h, rgb = read_pixels(str(out))
    # The grid's colours are red with some green, never blue.
    drawn = rgb[:, :3].max(axis=1) > 0
    assert drawn.sum() > 0.2 * w * h
    assert rgb[drawn, 0].mean() > 100 and rgb[drawn, 2].max() < 40


# ---- Defaults: presets, colouring, normals.

def drawn_pixels(rgb):
    """Pixels that are not the background (the renderer's default black)."""
    return rgb[:, :3].max(axis=1) > 0


def test_preset_on_a_ct(tmp_path):
    """--preset on a DICOM slice (CT_small, -896..1167 HU): the preset's
    colours and its threshold; ct-skin (from -750 HU) draws more than
    ct-bone (from 306 HU)."""
    folder = os.path.join(DATA, "DICOM", "CT_small")
    covered = {}
    for preset in ("ct-bone", "ct-skin"):
        out = tmp_path / (preset + ".png")
        r = run(folder, "-o", str(out), "--backend", "cpu", "--size", "96x96", "--mode", "phong",
                "--preset", preset, "--elevation", "90")  # a single axial slice: seen from above
        assert r.returncode == 0, r.stderr
        assert "colour: preset %s" % preset in r.stdout
        threshold = {"ct-bone": 306, "ct-skin": -750}[preset]
        assert "threshold: %g " % threshold in r.stdout
        rgb = read_pixels(str(out))[2].astype(int)
        drawn = drawn_pixels(rgb)
        covered[preset] = drawn.sum()
        mean = rgb[drawn, :3].mean(axis=0)
        assert mean[0] > mean[1] > mean[2], mean  # ivory / skin: red > green > blue
    assert covered["ct-skin"] > 2 * covered["ct-bone"] > 0


def test_unknown_preset_names_the_known_ones(tmp_path):
    r = run(os.path.join(DATA, "DICOM", "CT_small"), "-o", str(tmp_path / "x.png"), "--preset", "ct-lung")
    assert r.returncode == 2
    for name in ("ct-lung", "ct-bone", "ct-skin", "ct-muscle"):
        assert name in r.stderr
    assert not (tmp_path / "x.png").exists()


def write_pcd(path, n=40, outlier=True):
    """A binary PCD of a 40 x 40 grid with a bump (z), no colours, no
    normals, and an intensity that is 0..50 except for one point at 1000."""
    import struct
    rows = []
    for i in range(n * n):
        x, y = (i % n) / (n - 1.0), (i // n) / (n - 1.0)
        z = 0.3 * np.exp(-((x - 0.5) ** 2 + (y - 0.5) ** 2) / 0.05)
        intensity = 1000.0 if (outlier and i == 0) else float(i % 51)
        rows.append(struct.pack("<ffff", x, y, z, intensity))
    path.write_bytes(("VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
                      "WIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA binary\n"
                      % (n * n, n * n)).encode() + b"".join(rows))
    return path


def test_color_by(tmp_path):
    pcd = write_pcd(tmp_path / "bump.pcd")
    pictures = {}
    for what, expect in (("auto", "Intensity through viridis over "), ("intensity", "Intensity through"),
                         ("z", "Elevation through viridis")):
        out = tmp_path / (what + ".png")
        r = run(str(pcd), "-o", str(out), "--backend", "cpu", "--size", "96x96", "--color-by", what,
                "--elevation", "60")
        assert r.returncode == 0, r.stderr
        line = next(l for l in r.stdout.splitlines() if l.startswith("colour:"))
        assert expect in line, line
        pictures[what] = read_pixels(str(out))[2]
        if what == "auto":
            # The range comes from the 1st..99th percentile: the one point
            # at 1000 does not stretch it.
            lo, hi = (float(v) for v in line.split(" over ")[1].split(" ")[0].split(".."))
            assert 0 <= lo < 5 and 45 < hi <= 50, line
            assert "percentiles 1..99 of 0..1000" in line
    assert (pictures["auto"] == pictures["intensity"]).all()
    assert (pictures["z"] != pictures["intensity"]).any()

    r = run(str(pcd), "-o", str(tmp_path / "x.png"), "--color-by", "colour_of_nothing")
    assert r.returncode == 1
    assert "colour_of_nothing" in r.stderr and "Intensity" in r.stderr  # names the arrays there are
    r = run(str(pcd), "-o", str(tmp_path / "x.png"), "--color-by", "colors")
    assert r.returncode == 1 and "no RGB colours" in r.stderr


def test_color_by_a_vector_array_is_by_its_magnitude():
    """scene.color_by (octoray.render's --color-by) colours an array of
    several components by its magnitude, as ParaView colours vectors: the
    range is the magnitudes' and the picture that of a 1-component array of
    the magnitudes (it was component 0's)."""
    import vtk
    from octoray import scene
    from vtk.util.numpy_support import numpy_to_vtk
    velocity = np.random.default_rng(8).normal(size=(3000, 3))
    magnitude = np.linalg.norm(velocity, axis=1)
    pictures, sentences = [], []
    for values in (velocity, magnitude):
        cloud = random_cloud(3000, seed=9)
        array = numpy_to_vtk(values, deep=1)
        array.SetName("Velocity")
        cloud.GetPointData().AddArray(array)
        mapper = octoray.vtkCPUOctreeVolumeMapper()
        window, said = offscreen_view(mapper, (64, 64))
        prop = window.GetRenderers().GetFirstRenderer().GetVolumes().GetLastProp().GetProperty()
        data, sentence = scene.color_by(cloud, mapper, prop, "Velocity")
        mapper.SetInputData(data)
        window.Render()
        pictures.append(window_pixels(window))
        sentences.append(sentence)
        assert said == [], said
    lo, hi = np.percentile(magnitude, (1, 99))
    assert sentences[0].startswith("Velocity (magnitude) through viridis over %g..%g" % (lo, hi)), sentences[0]
    assert (pictures[0] == pictures[1]).all(), (pictures[0] != pictures[1]).any(axis=1).sum()


def test_normals(tmp_path):
    """--mode phong lights points without normals by the mapper's fit to the
    voxels (auto, voxels); --normals pcl estimates PCL's normals, none
    lights the voxels by their occupancy; flat modes need none."""
    pcd = write_pcd(tmp_path / "bump.pcd", outlier=False)
    pictures = {}
    # (mode, --normals, PCL's normals made, the mapper's fitted)
    for mode, normals, pcl, fitted in (("phong", "auto", False, True), ("phong", "none", False, False),
                                       ("phong", "voxels", False, True), ("phong", "pcl", True, False),
                                       ("surface", "auto", False, False), ("surface", "pcl", True, False)):
        out = tmp_path / ("%s-%s.png" % (mode, normals))
        r = run(str(pcd), "-o", str(out), "--backend", "cpu", "--size", "96x96", "--mode", mode,
                "--normals", normals, "--elevation", "60")
        assert r.returncode == 0, r.stderr
        assert ("normals: " in r.stdout and "(PCL, 16 neighbours)" in r.stdout) == pcl, r.stdout
        assert ("normals" in r.stderr) == pcl  # PCL's progress line
        assert ("(fitted to the voxels, in the first frame)" in r.stdout) == fitted, r.stdout
        pictures[(mode, normals)] = read_pixels(str(out))[2]
    def apart(a, b):
        """The fraction of pixels whose colours differ by more than 16."""
        return (np.abs(pictures[a].astype(int) - pictures[b].astype(int)) > 16).any(axis=-1).mean()
    # PCL's normals shade the bump differently from the octree's occupancy,
    # and alike the normals fitted to the voxels, which auto draws.
    print("phong pixels apart from PCL's: occupancy %.3f, voxels %.3f"
          % (apart(("phong", "pcl"), ("phong", "none")), apart(("phong", "pcl"), ("phong", "voxels"))))
    assert apart(("phong", "pcl"), ("phong", "none")) > 0.01
    assert apart(("phong", "pcl"), ("phong", "voxels")) < 0.5 * apart(("phong", "pcl"), ("phong", "none"))
    assert (pictures[("phong", "auto")] == pictures[("phong", "voxels")]).all()
