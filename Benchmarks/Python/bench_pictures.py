"""The octree mapper against what a VTK user would do today with the same points.

For each scene (the bundled LiDAR tile, the bundled CT stack's points above
a threshold, a synthetic field of spheres) the same points are drawn in the
same window size from the same orbiting camera by

  octoray      vtkOctreeVolumeMapper (New(): CUDA when usable, else CPU)
  interp-G     vtkPointInterpolator (Gaussian kernel) onto a vtkImageData with
               G voxels along the longest side, then vtkSmartVolumeMapper
  splat-G      vtkGaussianSplatter onto the same grid, then vtkSmartVolumeMapper
  pointgauss   vtkPointGaussianMapper (ParaView's "Sphere" splat shader)

and per method it measures the time to the first picture (from the points in
memory: octree build, or interpolation/splatting, plus the first render),
the splatting/interpolation alone, the median frame time over an orbit, and
the peak resident memory the method added (Linux: VmHWM after resetting it
through /proc/self/clear_refs). The first frame of each method is written to
IMAGES/<scene>-<method>.png; the figures go to JSON.

    PYTHONPATH=build/lib/python3/dist-packages xvfb-run -a /usr/bin/python3 \\
        Benchmarks/Python/bench_pictures.py --json build/report/pictures.json --images build/report/pictures
"""
import argparse
import gc
import json
import os
import statistics
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support

import octoray

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from bench_mapper import lidar, sphere_field  # noqa: E402
DATA = os.environ.get("OCTORAY_DATA", os.path.join(HERE, "..", "..", "Data"))

BACKGROUND = (0.1, 0.1, 0.12)


# ------------------------------------------------------------------ scenes

class Scene:
    """Points plus how to colour them: `rgb` (the Colors array, direct
    colours) or `scalar` (the active scalars through `ctf` with a range)."""

    def __init__(self, name, title, points, colouring, radius, elevation):
        self.name, self.title, self.points = name, title, points
        self.colouring = colouring
        # Splat radius in data units, chosen per scene from the point spacing
        # (as a user would): Gaussian kernel, splatter and point Gaussian.
        self.radius = radius
        self.elevation = elevation
        self.bounds = points.GetBounds()
        r = points.GetPointData().GetScalars().GetRange(0)
        self.range = r

    def ctf(self):
        lo, hi = self.range
        f = vtk.vtkColorTransferFunction()
        f.AddRGBPoint(lo, 0.2, 0.3, 0.9)
        f.AddRGBPoint(0.5 * (lo + hi), 0.9, 0.8, 0.3)
        f.AddRGBPoint(hi, 1.0, 1.0, 1.0)
        return f


def only_array(poly, name):
    """The points with one point-data array: interpolators and splatters then
    carry only what is drawn (the LiDAR tile also has reflectivity and
    refraction, which they would otherwise interpolate too)."""
    out = vtk.vtkPolyData()
    out.SetPoints(poly.GetPoints())
    out.SetVerts(poly.GetVerts())
    a = poly.GetPointData().GetArray(name)
    out.GetPointData().SetScalars(a)
    return out


def ct_points(threshold):
    r = octoray.vtkSliceStackReader()
    r.SetDirectoryName(os.path.join(DATA, "DICOM", "CT5N"))
    r.SetBackgroundRange(-1e30, threshold)  # air and below: background
    r.SetFillBetweenSlices(False)  # the scene is the voxels as points, as RESULTS.md has it
    r.Update()
    return r.GetOutput(), r.GetOutputDataObject(1)


def make_scenes(names, n_spheres):
    scenes = []
    for name in names:
        if name == "lidar":
            p = only_array(lidar(), "Colors")
            scenes.append(Scene("lidar", "LiDAR tile (Data/Particles/lidar_simple.particles)", p, "rgb",
                                radius=60.0, elevation=35))
        elif name == "ct":
            threshold = -300.0
            p, _ = ct_points(threshold)
            p = only_array(p, "Scalars")
            scene = Scene("ct", "CT stack points above %g (Data/DICOM/CT5N)" % threshold, p, "scalar",
                          radius=0.5, elevation=25)
            scene.threshold = threshold
            scenes.append(scene)
        elif name == "spheres":
            p = sphere_field(n_spheres)
            scenes.append(Scene("spheres", "48 spheres, points on their surfaces (synthetic)", p, "rgb",
                                radius=0.015, elevation=30))
        else:
            raise SystemExit("unknown scene %r" % name)
    return scenes


# ------------------------------------------------------------------ memory

def rss_kb(field):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    return 0


def reset_peak():
    """Resets VmHWM to the current RSS (Linux >= 4.0); False where it cannot."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


# ------------------------------------------------------------------ grids

def grid_for(scene, longest, pad):
    """An image grid over the points' bounds (padded by `pad` in data units)
    with `longest` voxels along the longest side and the same spacing on every
    axis: what one sets up for vtkPointInterpolator / vtkGaussianSplatter."""
    b = scene.bounds
    lo = np.array([b[0], b[2], b[4]]) - pad
    hi = np.array([b[1], b[3], b[5]]) + pad
    h = (hi - lo).max() / (longest - 1)
    dims = np.maximum(np.ceil((hi - lo) / h).astype(int) + 1, 2)
    return lo, h, dims


def volume_property(scene, opacity_range, colour=None, shade=True):
    """Scalar data: the scene's colour map (or one colour) and an opacity ramp
    over opacity_range."""
    prop = vtk.vtkVolumeProperty()
    prop.SetShade(shade)
    prop.SetInterpolationTypeToLinear()
    lo, hi = opacity_range
    o = vtk.vtkPiecewiseFunction()
    o.AddPoint(lo, 0.0)
    o.AddPoint(hi, 1.0)
    prop.SetScalarOpacity(o)
    if colour is not None:
        c = vtk.vtkColorTransferFunction()
        c.AddRGBPoint(lo, *colour)
        c.AddRGBPoint(hi, *colour)
        prop.SetColor(c)
    else:
        prop.SetColor(scene.ctf())
    return prop


def rgba_property():
    """4-component unsigned char data: RGB drawn directly, A through the opacity.
    Unshaded: with dependent RGBA components, VTK 9.2's GPU ray caster (here
    on Mesa) lit the samples with the ambient term only (checked on a solid
    ball: 0.1 x its colour), so shading would only darken the picture."""
    prop = vtk.vtkVolumeProperty()
    prop.ShadeOff()
    prop.SetInterpolationTypeToLinear()
    prop.IndependentComponentsOff()
    o = vtk.vtkPiecewiseFunction()
    o.AddPoint(0, 0.0)
    o.AddPoint(255, 1.0)
    prop.SetScalarOpacity(o)
    return prop


def spread_colours(rgb, valid, dims):
    """Gives each empty voxel beside a filled one that voxel's colour. The ray
    caster interpolates colour and opacity separately (not premultiplied), so
    the empty voxels' colour (black) would otherwise bleed into every blob's
    rim, and blobs a few voxels wide would look black."""
    shape = (dims[2], dims[1], dims[0])
    rgb = rgb.reshape(shape + (3,))
    valid = valid.reshape(shape)
    out = rgb.copy()
    filled = valid.copy()
    for axis in range(3):
        for step in (1, -1):
            src_rgb = np.roll(rgb, step, axis=axis)
            src_ok = np.roll(valid, step, axis=axis)
            take = src_ok & ~filled
            out[take] = src_rgb[take]
            filled |= take
    return out.reshape(-1, 3)


# ------------------------------------------------------------------ methods
# Each returns (prop to add to the renderer, prepared seconds or None, info);
# prepare time = the interpolation / splatting that precedes the first render.

def method_octoray(scene, grid):
    mapper = octoray.vtkOctreeVolumeMapper()
    mapper.SetInputData(scene.points)
    prop = vtk.vtkVolumeProperty()
    prop.ShadeOn()
    if scene.colouring == "rgb":
        prop.IndependentComponentsOff()
    else:
        prop.SetColor(scene.ctf())
        o = vtk.vtkPiecewiseFunction()
        o.AddPoint(scene.range[0], 1.0)
        o.AddPoint(scene.range[1], 1.0)
        prop.SetScalarOpacity(o)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    return volume, None, {"mapper": mapper}


def smart_volume(image, prop):
    mapper = vtk.vtkSmartVolumeMapper()
    mapper.SetInputData(image)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    return volume, mapper


def method_interp(scene, longest):
    radius = scene.radius
    lo, h, dims = grid_for(scene, longest, pad=2 * radius)
    radius = max(radius, h)  # a kernel narrower than a voxel misses points
    t0 = time.perf_counter()
    image = vtk.vtkImageData()
    image.SetDimensions(*dims)
    image.SetOrigin(*lo)
    image.SetSpacing(h, h, h)
    kernel = vtk.vtkGaussianKernel()
    kernel.SetRadius(radius)
    kernel.SetSharpness(2.0)
    interp = vtk.vtkPointInterpolator()
    interp.SetInputData(image)
    interp.SetSourceData(scene.points)
    interp.SetKernel(kernel)
    interp.SetNullPointsStrategyToMaskPoints()
    interp.Update()
    interpolated = time.perf_counter() - t0
    out = interp.GetOutput()
    # The volume: RGBA, with the interpolated colours (or the interpolated
    # scalar through the scene's colour map) and as alpha the interpolator's
    # mask of voxels that had points within the kernel's radius. An
    # interpolated scalar drawn through an opacity ramp instead gives every
    # blob a rim of the colour map's low end (the null value blends in).
    name = scene.points.GetPointData().GetScalars().GetName()
    values = out.GetPointData().GetArray(name)
    if scene.colouring == "rgb":
        rgb = numpy_support.vtk_to_numpy(values).reshape(-1, 3)
    else:
        mapped = scene.ctf().MapScalars(values, vtk.VTK_COLOR_MODE_MAP_SCALARS, -1)
        rgb = numpy_support.vtk_to_numpy(mapped)[:, :3]
    valid = numpy_support.vtk_to_numpy(out.GetPointData().GetArray(interp.GetValidPointsMaskArrayName())) != 0
    rgba = np.empty((rgb.shape[0], 4), np.uint8)
    rgba[:, :3] = spread_colours(np.clip(rgb, 0, 255).astype(np.uint8), valid, dims)
    rgba[:, 3] = np.where(valid, 255, 0)
    vol_image = vtk.vtkImageData()
    vol_image.CopyStructure(out)
    arr = numpy_support.numpy_to_vtk(rgba, deep=True)
    arr.SetName("RGBA")
    vol_image.GetPointData().SetScalars(arr)
    prepare = time.perf_counter() - t0
    volume, mapper = smart_volume(vol_image, rgba_property())
    return volume, prepare, {"mapper": mapper, "dims": [int(d) for d in dims], "spacing": h, "radius": radius,
                             "interpolate_s": interpolated}


def method_splat(scene, longest):
    radius = scene.radius
    lo, h, dims = grid_for(scene, longest, pad=2 * radius)
    radius = max(radius, h)
    hi = lo + (dims - 1) * h
    t0 = time.perf_counter()
    splat = vtk.vtkGaussianSplatter()
    splat.SetInputData(scene.points)
    splat.SetSampleDimensions(*[int(d) for d in dims])
    splat.SetModelBounds(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
    # Radius is a fraction of the longest side of the sampled box.
    splat.SetRadius(radius / (hi - lo).max())
    splat.ScalarWarpingOff()
    splat.NormalWarpingOff()
    splat.Update()
    out = splat.GetOutput()
    prepare = time.perf_counter() - t0
    # The splatter gives a density only: one colour, opacity by density.
    colour = (0.85, 0.8, 0.7)
    prop = volume_property(scene, (0.02, 0.2), colour=colour)
    volume, mapper = smart_volume(out, prop)
    return volume, prepare, {"mapper": mapper, "dims": [int(d) for d in dims], "spacing": h, "radius": radius}


# ParaView's "Sphere" preset of the Point Gaussian representation: a lit,
# opaque disc shaded as a sphere; the default Gaussian blur is translucent.
SPHERE_SHADER = """//VTK::Color::Impl
float dist = dot(offsetVCVSOutput.xy, offsetVCVSOutput.xy);
if (dist > 1.0) { discard; } else {
  float scale = (1.0 - dist);
  ambientColor *= scale;
  diffuseColor *= scale;
}
"""


def method_pointgauss(scene, grid):
    mapper = vtk.vtkPointGaussianMapper()
    mapper.SetInputData(scene.points)
    mapper.SetScaleFactor(scene.radius)
    mapper.EmissiveOff()
    mapper.SetSplatShaderCode(SPHERE_SHADER)
    if scene.colouring == "rgb":
        mapper.SetColorModeToDirectScalars()
    else:
        mapper.SetLookupTable(scene.ctf())
        mapper.SetScalarRange(*scene.range)
        mapper.UseLookupTableScalarRangeOn()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    return actor, None, {"mapper": mapper}


def method_stack(scene, grid):
    """The CT stack as the image it is (vtkSliceStackReader's output 1):
    what a VTK user does with a CT, no points involved. The same colour map;
    opacity steps up at the threshold that made the points."""
    _, image = ct_points(scene.threshold)
    prop = volume_property(scene, (scene.threshold, scene.threshold + 1.0))
    volume, mapper = smart_volume(image, prop)
    return volume, None, {"mapper": mapper}


METHODS = {
    "octoray": ("vtkOctreeVolumeMapper", method_octoray),
    "interp": ("vtkPointInterpolator (Gaussian) + vtkSmartVolumeMapper", method_interp),
    "splat": ("vtkGaussianSplatter + vtkSmartVolumeMapper", method_splat),
    "pointgauss": ("vtkPointGaussianMapper", method_pointgauss),
    "stack": ("the CT image itself + vtkSmartVolumeMapper", method_stack),
}


# ------------------------------------------------------------------ one run

def save_png(window, path):
    w2i = vtk.vtkWindowToImageFilter()
    w2i.SetInput(window)
    w2i.ReadFrontBufferOff()
    w2i.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputConnection(w2i.GetOutputPort())
    writer.Write()


def place_camera(ren, scene, camera):
    c = ren.GetActiveCamera()
    c.SetFocalPoint(camera["focal"])
    c.SetPosition(camera["position"])
    c.SetViewUp(camera["up"])
    c.SetViewAngle(camera["angle"])
    c.SetClippingRange(camera["clip"])
    return c


def reference_camera(scene, size):
    """One camera for every method: VTK's ResetCamera of the points' bounds,
    raised by the scene's elevation; clipping range from the bounds padded by
    the splat grid's margin, so no method's volume is clipped."""
    ren = vtk.vtkRenderer()
    b = scene.bounds
    ren.ResetCamera(b)
    c = ren.GetActiveCamera()
    c.Elevation(scene.elevation)
    c.OrthogonalizeViewUp()
    pad = 4 * scene.radius
    d = np.linalg.norm(np.array(c.GetPosition()) - np.array(c.GetFocalPoint()))
    diag = np.linalg.norm([b[1] - b[0] + 2 * pad, b[3] - b[2] + 2 * pad, b[5] - b[4] + 2 * pad])
    clip = (max(d - diag, 1e-3 * d), d + diag)
    return dict(focal=c.GetFocalPoint(), position=c.GetPosition(), up=c.GetViewUp(),
                angle=c.GetViewAngle(), clip=clip)


# vtkSMPTools backend per method: each VTK filter at its faster setting.
# vtkPointInterpolator gains from threads (the backend --smp names, the same
# 2 cores as octoray's CPU backend); vtkGaussianSplatter with STDThread took
# 65 s instead of 0.8 s on the 200 k-point sphere field here (its threaded
# splat contends), so it keeps ParaView's default, Sequential.
SMP_BACKEND = {"interp": "STDThread"}


def run_method(scene, key, grid, size, frames, camera, images):
    label, build = METHODS[key]
    smp_backend = SMP_BACKEND.get(key, "Sequential")
    vtk.vtkSMPTools.SetBackend(smp_backend)
    tag = key if grid is None else "%s-%d" % (key, grid)
    gc.collect()
    peak_ok = reset_peak()
    rss0 = rss_kb("VmRSS")

    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(*size)
    ren = vtk.vtkRenderer()
    ren.SetBackground(*BACKGROUND)
    win.AddRenderer(ren)
    place_camera(ren, scene, camera)

    # Time to first picture: from the points in memory to the first frame.
    t0 = time.perf_counter()
    prop, prepare, info = build(scene, grid)
    if isinstance(prop, vtk.vtkVolume):
        ren.AddVolume(prop)
    else:
        ren.AddActor(prop)
    win.Render()
    win.WaitForCompletion()
    first = time.perf_counter() - t0

    path = os.path.join(images, "%s-%s.png" % (scene.name, tag))
    save_png(win, path)

    cam = ren.GetActiveCamera()
    times = []
    for _ in range(frames):
        cam.Azimuth(360.0 / frames)
        t = time.perf_counter()
        win.Render()
        win.WaitForCompletion()
        times.append(time.perf_counter() - t)
    peak = rss_kb("VmHWM") - rss0 if peak_ok else None

    rec = dict(scene=scene.name, method=key, grid=grid, label=label, image=os.path.basename(path), smp=smp_backend,
               first_s=first, prepare_s=prepare, frame_s=statistics.median(times), frames=frames,
               peak_mb=None if peak is None else peak / 1024.0)
    mapper = info.pop("mapper")
    if key == "octoray":
        rec["backend"] = mapper.GetLastUsedBackendName()
        rec["backend_description"] = mapper.GetBackendDescription()
        rec["build_s"] = mapper.GetLastBuildSeconds()
        rec["leaf_size"] = mapper.GetLeafSize()
    elif isinstance(mapper, vtk.vtkSmartVolumeMapper):
        rec["render_mode"] = {0: "default", 1: "ray cast (CPU)", 2: "GPU", 3: "undefined",
                              4: "OSPRay", 5: "ANARI"}.get(mapper.GetLastUsedRenderMode(),
                                                          str(mapper.GetLastUsedRenderMode()))
    rec.update(info)
    print("%-8s %-14s first %8.1f ms (prepare %s), frame %8.1f ms, peak +%s MB" % (
        scene.name, tag, first * 1e3, "-" if prepare is None else "%.1f ms" % (prepare * 1e3),
        rec["frame_s"] * 1e3, "?" if peak is None else "%.0f" % (peak / 1024.0)), flush=True)
    ren.RemoveAllViewProps()
    win.Finalize()
    del win, ren, prop, mapper
    return rec


def warm_up(images):
    """Draws a small cloud once with every method before anything is timed:
    the first OpenGL context of the process loads Mesa and compiles its
    shaders, the first use of a mapper loads its libraries; whichever method
    came first would otherwise pay for all of them."""
    scene = Scene("warmup", "warm-up", sphere_field(2000), "rgb", radius=0.05, elevation=30)
    camera = reference_camera(scene, (64, 64))
    for key in ("octoray", "interp", "splat", "pointgauss"):
        grid = 16 if key in ("interp", "splat") else None
        run_method(scene, key, grid, (64, 64), 1, camera, images)
    for name in os.listdir(images):
        if name.startswith("warmup-"):
            os.remove(os.path.join(images, name))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--json", required=True)
    p.add_argument("--images", required=True, help="folder for the first frame of every method")
    p.add_argument("--size", default="640x480")
    p.add_argument("--frames", type=int, default=4, help="orbit frames (median reported)")
    p.add_argument("--grids", default="128,256",
                   help="voxels along the longest side of the splat grids (the CT scene takes the first only)")
    p.add_argument("--scenes", default="lidar,ct,spheres")
    p.add_argument("--points", type=int, default=200000, help="points of the sphere field")
    p.add_argument("--smp", default="STDThread",
                   help="vtkSMPTools backend for vtkPointInterpolator (Debian's ParaView VTK defaults to Sequential)")
    args = p.parse_args()
    smp = vtk.vtkSMPTools()
    if not smp.SetBackend(args.smp):
        raise SystemExit("vtkSMPTools has no backend %r" % args.smp)
    SMP_BACKEND["interp"] = args.smp
    smp_threads = smp.GetEstimatedNumberOfThreads()
    size = tuple(int(v) for v in args.size.split("x"))
    grids = [int(g) for g in args.grids.split(",")]
    os.makedirs(args.images, exist_ok=True)

    warm_up(args.images)
    records, scenes_out = [], []
    for scene in make_scenes(args.scenes.split(","), args.points):
        camera = reference_camera(scene, size)
        scenes_out.append(dict(name=scene.name, title=scene.title, points=scene.points.GetNumberOfPoints(),
                               colouring=scene.colouring, radius=scene.radius, bounds=list(scene.bounds)))
        records.append(run_method(scene, "octoray", None, size, args.frames, camera, args.images))
        # The CT stack has 16 x 16 x 5 samples: its first grid is already 8
        # times finer than the data, a second one would only cost time.
        scene_grids = grids[:1] if scene.name == "ct" else grids
        for g in scene_grids:
            records.append(run_method(scene, "interp", g, size, args.frames, camera, args.images))
        for g in scene_grids:
            records.append(run_method(scene, "splat", g, size, args.frames, camera, args.images))
        records.append(run_method(scene, "pointgauss", None, size, args.frames, camera, args.images))
        if scene.name == "ct":
            records.append(run_method(scene, "stack", None, size, args.frames, camera, args.images))

    with open(args.json, "w") as f:
        json.dump(dict(size=list(size), frames=args.frames, grids=grids, scenes=scenes_out,
                       smp_backend=args.smp, smp_threads=smp_threads,
                       records=records), f, indent=1)
    print("wrote %s" % args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
