"""What `python3 -m octoray.render` and `python3 -m octoray.demo` share: reading
any input octoray knows, point normals, colouring points that carry no
colour, transfer-function presets, lights, camera and picture output.

Defaults a user would otherwise have to find:

- Slice stacks (a DICOM series, image slices) are drawn from the reader's
  image output (``vtkSliceStackReader.GetImageOutput()``): the mapper then
  knows the voxel spacing and fills the space between slices.
- CT presets by name (``ct-bone``, ``ct-skin``, ``ct-muscle``;
  ``vtkOctreeVolumePresets``): colour and opacity in Hounsfield units, and
  the value from which voxels are drawn in the surface modes.
- Points without colour are coloured through a lookup table by an array
  (``Intensity`` when the points have one, else their elevation z), over
  the 1st to 99th percentile of its values, so that a few bright returns
  (a laser scan's intensity is very skewed) do not wash out the rest.
- Shaded (phong) pictures of points without normals get normals from PCL
  (``vtkParticleNormals``, 16 nearest neighbours).
- Lights: a key light above and to the left of the camera, which casts the
  shadows, and a headlight that fills what the key light leaves in shadow
  (for point clouds the two are balanced: the key light's shadows on a
  noisy scan speckle, and the fill lifts the specks).
"""
import os
import re
import sys
import time

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

import octoray

# matplotlib's viridis (CC0), 9 samples: perceptually uniform, readable
# under shading, and printable in grey.
VIRIDIS = [
    (0.267, 0.005, 0.329), (0.279, 0.175, 0.483), (0.230, 0.322, 0.546),
    (0.173, 0.449, 0.558), (0.128, 0.567, 0.551), (0.153, 0.680, 0.510),
    (0.360, 0.785, 0.388), (0.668, 0.862, 0.196), (0.993, 0.906, 0.144),
]


class ProgressBar:
    """A text progress bar on stderr, fed by an algorithm's ProgressEvent.
    On a terminal it is redrawn in place; into a file or a pipe only the
    finished bar is written, one line, so that logs stay readable."""

    def __init__(self, label, stream=None):
        self.label = label
        self.shown = -1
        self.stream = stream or sys.stderr
        self.live = self.stream.isatty()
        self.failed = False

    def __call__(self, algorithm, event):
        self.show(algorithm.GetProgress())

    def fail(self, *_):
        """The algorithm failed: the bar stays where it was (VTK's pipeline
        still reports 100 % after a failed request)."""
        self.failed = True

    def show(self, fraction):
        percent = int(100 * fraction)
        if self.shown >= 100 or self.failed:
            return  # one bar: the pipeline may report a step again
        if percent != self.shown and (self.live or percent >= 100):
            self.shown = percent
            bar = "#" * (percent // 4)
            self.stream.write("%s%-10s [%-25s] %3d%%" % ("\r" if self.live else "", self.label, bar, percent))
            if percent >= 100:
                self.stream.write("\n")
            self.stream.flush()

    def finish(self):
        """Ends a bar left unfinished (a failed read), so that what is
        written next starts on its own line."""
        if 0 <= self.shown < 100:
            self.stream.write("\n")
            self.stream.flush()
            self.shown = 100


class Timer:
    """with Timer() as t: ...; t.seconds"""

    def __enter__(self):
        self.start = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.start


def input_kind(path):
    """'slices' (a folder or a printf pattern of slices), 'pcd' or 'particles'.
    A file that exists is read as a file, a % in its name or not."""
    if os.path.isdir(path) or ("%" in path and not os.path.isfile(path)):
        return "slices"
    if path.lower().endswith((".pcd", ".pcd.gz")):
        return "pcd"
    return "particles"


def pattern_range(pattern):
    """The lowest and highest numbers for which the printf pattern of slice
    names (one integer conversion, as in ct_%03d.png) names a file in its
    folder; None where it names none (the reader then says what is wrong
    with the pattern, or that it matches nothing)."""
    folder, name = os.path.split(pattern)
    conversion = re.search(r"%[-+ 0#]*[0-9]*[diu]", name)
    if conversion is None or not os.path.isdir(folder or "."):
        return None
    parts = [re.escape(part.replace("%%", "%")) for part in (name[:conversion.start()], name[conversion.end():])]
    names = re.compile(parts[0] + r"\s*([-+]?[0-9]+)" + parts[1] + "$")
    numbers = [int(m.group(1)) for m in map(names.match, os.listdir(folder or ".")) if m]
    numbers = [n for n in numbers if os.path.isfile(pattern % n)]
    return (min(numbers), max(numbers)) if numbers else None


def make_reader(path, file_range=None):
    """The reader for `path`; a pattern of slice names reads the numbers
    `file_range` (FIRST, LAST), by default every number it names a file for
    (pattern_range): the reader says which are missing between them."""
    kind = input_kind(path)
    if kind == "slices":
        reader = octoray.vtkSliceStackReader()
        if os.path.isdir(path):
            reader.SetDirectoryName(path)
        else:
            reader.SetFilePattern(path)
            reader.SetFileNameRange(*(file_range or pattern_range(path) or (0, 0)))
        return reader
    reader = octoray.vtkPCDReader() if kind == "pcd" else octoray.vtkParticleReader()
    reader.SetFileName(path)
    reader.SetOutputPointsPrecision(vtk.vtkAlgorithm.DOUBLE_PRECISION)
    return reader


def read(path, file_range=None, progress_label="reading", stream=None, configure=None,
         particles=False):
    """Reads `path` with a progress line; returns (reader, data, seconds).
    Slice stacks give the reader's image output (vtkImageData), or with
    `particles` its particles, and only that output is made; the others
    give the points (vtkPolyData). `configure(reader)` is called before
    reading.
    A failed read prints nothing (not VTK's pipeline report either): where
    nothing was read, the caller says reader.GetErrorMessage(), which names
    the file and the line or slice. Warnings are printed as they come."""
    reader = make_reader(path, file_range)
    bar = ProgressBar(progress_label, stream) if progress_label else None
    for source in (reader, reader.GetExecutive()):
        source.AddObserver("ErrorEvent", bar.fail if bar else lambda caller, event: None)
    if configure:
        configure(reader)
    if bar:
        reader.AddObserver("ProgressEvent", bar)
    port = 1 if isinstance(reader, octoray.vtkSliceStackReader) and not particles else 0
    with Timer() as t:
        reader.Update(port)
    if bar:
        bar.finish()
    return reader, reader.GetOutputDataObject(port), t.seconds


def has_colours(data):
    s = data.GetPointData().GetScalars()
    return s is not None and s.GetNumberOfComponents() in (3, 4)


def has_normals(data):
    n = data.GetPointData().GetNormals()
    return n is not None and n.GetNumberOfComponents() == 3


def normals_viewpoint(data):
    """Where normals should face: the PCD file's sensor origin when it has
    one, else a point above the middle of the data (an aerial scan's view).
    The renderer lights both faces alike; this only makes them consistent."""
    vp = data.GetFieldData().GetArray("PCDViewpoint")
    if vp is not None and vp.GetNumberOfTuples() * vp.GetNumberOfComponents() >= 3:
        return tuple(vp.GetComponent(0, c) if vp.GetNumberOfComponents() >= 3 else vp.GetValue(c)
                     for c in range(3))
    b = data.GetBounds()
    size = max(b[1] - b[0], b[3] - b[2], b[5] - b[4])
    return (0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), b[5] + 2.0 * size)


def estimate_normals(data, neighbours=16, progress_label="normals", stream=None):
    """PCL normals (vtkParticleNormals, k nearest neighbours); returns
    (output, seconds, points without a normal)."""
    f = octoray.vtkParticleNormals()
    f.SetInputData(data)
    f.SetNumberOfNeighbors(neighbours)
    f.SetViewPoint(*normals_viewpoint(data))
    if progress_label:
        bar = ProgressBar(progress_label, stream)
        f.AddObserver("ProgressEvent", bar)
    with Timer() as t:
        f.Update()
    if progress_label and bar.shown < 100:
        bar.show(1.0)
    return f.GetOutput(), t.seconds, f.GetNumberOfInvalidNormals()


def percentile_range(values, lo=1.0, hi=99.0):
    """The lo-th and hi-th percentiles of `values`, widened when equal."""
    a, b = (float(v) for v in np.percentile(np.asarray(values, dtype=np.float64), [lo, hi]))
    if not b > a:
        a, b = float(np.min(values)), float(np.max(values))
    if not b > a:
        a, b = a - 0.5, b + 0.5
    return a, b


def colormap(lo, hi, colours=VIRIDIS):
    ctf = vtk.vtkColorTransferFunction()
    for i, c in enumerate(colours):
        ctf.AddRGBPoint(lo + (hi - lo) * i / (len(colours) - 1), *c)
    ctf.ClampingOn()
    return ctf


def find_array(data, name):
    """A point array by name, without regard to case."""
    pd = data.GetPointData()
    for i in range(pd.GetNumberOfArrays()):
        a = pd.GetArray(i)
        if a is not None and a.GetName() and a.GetName().lower() == name.lower():
            return a
    return None


def choose_color_by(data, requested="auto"):
    """What colours the points: 'colors' (their RGB), 'none', 'z' (elevation)
    or an array name. 'auto': RGB colours when present, else an Intensity
    array, else z; an image is coloured through its scalars ('scalars')."""
    if isinstance(data, vtk.vtkImageData):
        return "scalars" if requested in ("auto", "scalars") else requested
    if requested != "auto":
        return requested
    if has_colours(data):
        return "colors"
    if find_array(data, "intensity") is not None:
        return "intensity"
    return "z"


def color_by(data, mapper, prop, what, percentiles=(1.0, 99.0)):
    """Sets up `mapper` and `prop` to colour `data` by `what` (see
    choose_color_by). Returns (data to draw, a sentence on what was done).
    Arrays and z are mapped through viridis over their percentile range;
    an array of several components by its magnitude, as ParaView colours
    vectors (the colour function's VectorMode, which the mapper follows)."""
    if what == "colors":
        if not has_colours(data):
            raise ValueError("the points carry no RGB colours (arrays: %s)" % array_names(data))
        prop.IndependentComponentsOff()
        return data, "colours: the points' own RGB"
    if what in ("none", "scalars"):
        return data, "no colour array" if what == "none" else "scalars through the transfer function"
    if what in ("z", "elevation"):
        z = vtk_to_numpy(data.GetPoints().GetData())[:, 2].astype(np.float32)
        copy = data.NewInstance()
        copy.ShallowCopy(data)
        arr = numpy_to_vtk(z, deep=1)
        arr.SetName("Elevation")
        copy.GetPointData().AddArray(arr)
        data, name, values = copy, "Elevation", z
    else:
        arr = find_array(data, what)
        if arr is None:
            raise ValueError("no point array %r (arrays: %s)" % (what, array_names(data)))
        name, values = arr.GetName(), vtk_to_numpy(arr)
    ramp_name = name
    if values.ndim > 1:
        values = np.linalg.norm(values.astype(float), axis=1)
        ramp_name = "%s (magnitude)" % name
    lo, hi = percentile_range(values, *percentiles)
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectScalarArray(name)
    ramp = colormap(lo, hi)
    ramp.SetVectorModeToMagnitude()
    prop.SetColor(ramp)
    opacity = vtk.vtkPiecewiseFunction()
    opacity.AddPoint(lo, 1.0)
    opacity.AddPoint(hi, 1.0)
    prop.SetScalarOpacity(opacity)
    return data, "%s through viridis over %g..%g (percentiles %g..%g of %g..%g)" % (
        ramp_name, lo, hi, percentiles[0], percentiles[1], float(np.min(values)), float(np.max(values)))


def array_names(data):
    pd = data.GetPointData()
    return ", ".join(pd.GetArrayName(i) or "?" for i in range(pd.GetNumberOfArrays())) or "none"


def add_lights(renderer, key_azimuth=-35.0, key_elevation=40.0, key=0.85, fill=0.35):
    """A key light above and to the side of the camera (it casts the visible
    shadows) and a headlight that fills the shadowed side. Both move with the
    camera. Returns the lights."""
    renderer.AutomaticLightCreationOff()
    renderer.RemoveAllLights()
    az, el = np.radians(key_azimuth), np.radians(key_elevation)
    keylight = vtk.vtkLight()
    keylight.SetLightTypeToCameraLight()
    # Camera-light coordinates: camera at (0, 0, 1) looking at the origin, y up.
    keylight.SetPosition(np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az))
    keylight.SetFocalPoint(0, 0, 0)
    keylight.SetIntensity(key)
    head = vtk.vtkLight()
    head.SetLightTypeToHeadlight()
    head.SetIntensity(fill)
    renderer.AddLight(keylight)
    renderer.AddLight(head)
    return keylight, head


def look_at(renderer, bounds, front, up, azimuth=0.0, elevation=0.0, zoom=1.0, view_angle=30.0):
    """Camera on the side `front` of the data (a unit vector from the centre
    towards the viewer), turned by `azimuth` about `up` and raised by
    `elevation` towards it, fitted to `bounds` and zoomed."""
    front = np.asarray(front, dtype=float)
    up = np.asarray(up, dtype=float)
    front /= np.linalg.norm(front)
    up /= np.linalg.norm(up)
    a, e = np.radians(azimuth), np.radians(elevation)
    side = np.cross(up, front)
    d = np.cos(a) * front + np.sin(a) * side
    d = np.cos(e) * d + np.sin(e) * up
    centre = np.array([0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5])])
    cam = renderer.GetActiveCamera()
    cam.SetViewAngle(view_angle)
    cam.SetFocalPoint(*centre)
    cam.SetPosition(*(centre + d))
    # The view-up: `up` where the camera is not looking along it, else (from
    # straight above or below) the far side of the data.
    view_up = up - np.dot(up, d) * d
    if np.linalg.norm(view_up) < 1e-6:
        view_up = -np.sign(np.dot(up, d)) * front
    cam.SetViewUp(*view_up)
    cam.OrthogonalizeViewUp()
    renderer.ResetCamera(bounds)
    cam.Zoom(zoom)
    renderer.ResetCameraClippingRange(bounds)
    return cam


def visible_bounds(image, threshold):
    """Bounds of the voxels above `threshold` (what the camera should frame)."""
    scalars = image.GetPointData().GetScalars()
    if scalars is None:
        return image.GetBounds()
    values = vtk_to_numpy(scalars)
    if values.ndim > 1:
        values = values.max(axis=1)  # the largest component, as the mapper compares colours
    nx, ny, nz = image.GetDimensions()
    above = (values > threshold).reshape(nz, ny, nx)
    if not above.any():
        return image.GetBounds()
    ks, js, is_ = (np.nonzero(above.any(axis=axes))[0] for axes in ((1, 2), (0, 2), (0, 1)))
    e = image.GetExtent()
    corners = []
    for i in (is_[0] - 0.5, is_[-1] + 0.5):
        for j in (js[0] - 0.5, js[-1] + 0.5):
            for k in (ks[0] - 0.5, ks[-1] + 0.5):
                p = [0.0, 0.0, 0.0]
                image.TransformContinuousIndexToPhysicalPoint(e[0] + i, e[2] + j, e[4] + k, p)
                corners.append(p)
    c = np.array(corners)
    lo, hi = c.min(axis=0), c.max(axis=0)
    return (lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])


def default_view(data, kind, reader=None):
    """(front, up) for the kind of data: a DICOM CT in patient coordinates
    (LPS: anterior is -y, superior +z) is seen from the front, head up; a
    PCD scan from its sensor (PCL's camera: looking along +z, y down, here
    towards the points); anything else from above and the -y side, z up."""
    if kind == "slices" and reader is not None and reader.GetIsDICOM():
        return (0, -1, 0), (0, 0, 1)
    if kind == "pcd":
        b = data.GetBounds()
        towards = -1.0 if 0.5 * (b[4] + b[5]) < 0 else 1.0  # the points lie along -z or +z
        return (0, 0, -towards), (0, -towards, 0)
    return (0, -1, 0), (0, 0, 1)


def add_label(renderer, text, size=18, position=(12, 10), colour=(0.92, 0.92, 0.92)):
    actor = vtk.vtkTextActor()
    actor.SetInput(text)
    p = actor.GetTextProperty()
    p.SetFontSize(size)
    p.SetColor(*colour)
    p.SetFontFamilyToArial()
    p.ShadowOn()
    actor.SetDisplayPosition(*position)
    renderer.AddActor2D(actor)
    return actor


def grab(window):
    """The window's picture as vtkImageData (RGB)."""
    g = vtk.vtkWindowToImageFilter()
    g.SetInput(window)
    g.ReadFrontBufferOff()
    g.SetInputBufferTypeToRGB()
    g.Update()
    out = vtk.vtkImageData()
    out.DeepCopy(g.GetOutput())
    return out


def write_png(image, path):
    """Writes the picture; OSError naming the file where it cannot."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise OSError("%s: cannot write the picture: no folder %s" % (path, folder))
    w = vtk.vtkPNGWriter()
    w.SetFileName(path)
    w.SetCompressionLevel(9)
    w.SetInputData(image)
    w.Write()
    if w.GetErrorCode() != 0:
        raise OSError("%s: cannot write the picture (see VTK's message above)" % path)


def side_by_side(images):
    app = vtk.vtkImageAppend()
    app.SetAppendAxis(0)
    for im in images:
        app.AddInputData(im)
    app.Update()
    return app.GetOutput()


def apply_preset(name, volume_property):
    """Applies the CT preset `name` to `volume_property` (see
    octoray.vtkOctreeVolumePresets); returns the value from which the
    preset shows voxels in the surface modes. ValueError naming the known
    presets for an unknown name."""
    return octoray.apply_preset(name, volume_property)
