"""octoray's demo: real data at real size, Phong with shadows.

    python3 -m octoray.demo [--data Data] [--out build/demo] [--backend auto|cuda|cpu]
                            [--scale F] [--thumbnails DIR]

1. The head CT of Data/External/HeadCT (108 DICOM slices of 256 x 256,
   -1024..2986 HU) through vtkSliceStackReader: the CT-Bone and CT-Skin
   presets drawn from the reader's image output (surface, Phong, shadows),
   and CT-Bone side by side with VTK's vtkSmartVolumeMapper on the same
   image, camera, lights and transfer function; then CT-Bone cut open by
   the mapper's cropping box (the same octree, traced again).
2. The PCL laser scan table_scene_lms400.pcd (460,400 points with
   intensity) through vtkPCDReader, coloured by intensity.
3. The thesis example Data/Particles/lidar_simple.particles (1065 airborne
   LiDAR points with RGB) through vtkParticleTextReader.
The points have no normals: the mapper fits them to the voxels, in the
first frame (EstimateNormals).

Each step prints what it cost (read, normals, build, render) and the backend;
the pictures go to --out. --scale shrinks the pictures (for a quick run);
--thumbnails writes well-compressed copies (640 pixels wide, the comparison
960, 256 colours, with Pillow) for the README.
"""
import argparse
import os
import sys
import time

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import octoray
from octoray import scene

BACKGROUND = ((0.08, 0.08, 0.10), (0.24, 0.25, 0.29))  # bottom, top


def log(text=""):
    print(text)
    sys.stdout.flush()


def new_mapper(backend):
    return {"auto": octoray.vtkOctreeVolumeMapper,
            "cuda": octoray.vtkCudaOctreeVolumeMapper,
            "cpu": octoray.vtkCPUOctreeVolumeMapper}[backend]()


def new_view(size, key=0.85, fill=0.35):
    ren = vtk.vtkRenderer()
    ren.GradientBackgroundOn()
    ren.SetBackground(*BACKGROUND[0])
    ren.SetBackground2(*BACKGROUND[1])
    scene.add_lights(ren, key=key, fill=fill)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*size)
    window.AddRenderer(ren)
    return ren, window


def scaled(size, scale):
    return tuple(max(32, int(round(s * scale))) for s in size)


def render_octree(ren, window, mapper):
    """The first render (build and trace); returns its wall time."""
    with scene.Timer() as t:
        window.Render()
    return t.seconds


def octree_line(mapper):
    return "%s points in the octree, depth %d, leaf %.3g" % (
        format(mapper.GetNumberOfOctreePoints(), ","), mapper.GetOctreeDepth(), mapper.GetLeafSize())


def render_line(mapper, wall, size):
    return "trace %.2f s (+ depth read, upload and draw %.2f s; first frame %.2f s) at %dx%d, %s" % (
        mapper.GetLastTraceSeconds(),
        mapper.GetLastDepthReadSeconds() + mapper.GetLastUploadSeconds() + mapper.GetLastDrawSeconds(),
        wall, size[0], size[1], "Phong + shadows" if mapper.GetShadows() else "Phong")


def automatic_depth(data, backend):
    """The leaf level LeafDepth 0 chooses for `data` (a build and a 2 x 2 trace)."""
    mapper = new_mapper(backend)
    mapper.SetInputData(data)
    prop = vtk.vtkVolumeProperty()
    if scene.has_colours(data):
        prop.IndependentComponentsOff()
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren, window = new_view((2, 2))
    ren.AddVolume(volume)
    ren.ResetCamera()
    window.Render()
    return mapper.GetOctreeDepth(), mapper.GetLeafSize()


# ---------------------------------------------------------------------------
def head_ct(args, timings, pictures):
    folder = os.path.join(args.data, "External", "HeadCT", "DICOM")
    log("[1/3] head CT: %s (DICOM series) through vtkSliceStackReader" % folder)
    # The image output is drawn, not the particles: they are not made.
    reader, image, seconds = scene.read(folder, progress_label="  reading")
    if image is None or image.GetNumberOfPoints() == 0:
        raise RuntimeError("no CT read from %s: %s" % (folder, reader.GetErrorMessage()))
    dims, spacing = image.GetDimensions(), image.GetSpacing()
    lo, hi = image.GetScalarRange()
    log("  read     %.2f s: %d slices, %d x %d x %d voxels, spacing %.4g x %.4g x %.4g mm, %g..%g HU"
        % (seconds, reader.GetNumberOfSlices(), dims[0], dims[1], dims[2], *spacing, lo, hi))
    timings.append(("head CT", "read", seconds))
    size = scaled((960, 960), args.scale)
    front, up = scene.default_view(image, "slices", reader)
    # A three-quarter view from the patient's right front, a little above.
    azimuth, elevation, zoom = -35.0, 12.0, 1.2
    results = {}
    for preset in ("ct-bone", "ct-skin"):
        mapper = new_mapper(args.backend)
        mapper.SetInputData(image)
        prop = vtk.vtkVolumeProperty()
        threshold = octoray.apply_preset(preset, prop)
        mapper.SetImageBackground(threshold)
        mapper.SetShadows(True)
        mapper.SetMaximumBounces(0)
        mapper.AddObserver("ProgressEvent", scene.ProgressBar("  building"))
        volume = vtk.vtkVolume()
        volume.SetMapper(mapper)
        volume.SetProperty(prop)
        ren, window = new_view(size)
        ren.AddVolume(volume)
        bounds = scene.visible_bounds(image, threshold)
        scene.look_at(ren, bounds, front, up, azimuth, elevation, zoom)
        wall = render_octree(ren, window, mapper)
        path = os.path.join(args.out, "ct-%s.png" % preset[3:])
        scene.write_png(scene.grab(window), path)
        log("  %-8s threshold %g HU (voxels the preset makes visible): %s%s"
            % (preset, threshold, octree_line(mapper),
               " (chosen from the spacing)" if mapper.GetLeafDepth() == 0 else ""))
        log("           build %.2f s, %s, backend %s" % (mapper.GetLastBuildSeconds(), render_line(mapper, wall, size),
                                                        mapper.GetLastUsedBackendName()))
        log("           -> %s" % path)
        timings.append(("head CT %s" % preset, "build", mapper.GetLastBuildSeconds()))
        timings.append(("head CT %s" % preset, "render", mapper.GetLastTraceSeconds()))
        pictures.append(path)
        results[preset] = (mapper, prop, ren, window, volume, bounds)

    # Side by side: octoray and vtkSmartVolumeMapper on the same image, the
    # same camera, lights and volume property (CT-Bone).
    mapper, prop, ren, window, volume, bounds = results["ct-bone"]
    panel = scaled((800, 800), args.scale)
    window.SetSize(*panel)
    scene.look_at(ren, bounds, front, up, azimuth, elevation, zoom)
    octo_label = scene.add_label(ren, "octoray (%s): surface, Phong + shadows, voxels above %g HU"
                                 % (mapper.GetLastUsedBackendName(), mapper.GetImageBackground()),
                                 size=max(10, int(16 * args.scale)))
    with scene.Timer() as t:
        window.Render()
    left = scene.grab(window)
    octo_trace = mapper.GetLastTraceSeconds()

    smart = vtk.vtkSmartVolumeMapper()
    smart.SetInputData(image)
    smart.SetBlendModeToComposite()
    vtk_volume = vtk.vtkVolume()
    vtk_volume.SetMapper(smart)
    vtk_volume.SetProperty(prop)  # the same property: transfer functions, shading
    vren, vwindow = new_view(panel)
    vren.AddVolume(vtk_volume)
    vren.GetActiveCamera().DeepCopy(ren.GetActiveCamera())
    vren.ResetCameraClippingRange()
    gl = gl_renderer(window)  # the same OpenGL as octoray's window
    scene.add_label(vren, "VTK vtkSmartVolumeMapper (%s): composite, shaded" % gl,
                    size=max(10, int(16 * args.scale)))
    with scene.Timer() as first:
        vwindow.Render()
    modes = {0: "default", 1: "CPU ray cast", 2: "GPU ray cast", 3: "OSPRay", 4: "ANARI"}
    mode = modes.get(smart.GetLastUsedRenderMode(), "?")
    right = scene.grab(vwindow)
    path = os.path.join(args.out, "ct-compare.png")
    scene.write_png(scene.side_by_side([left, right]), path)
    log("  compare  CT-Bone, %dx%d each, same image, camera, lights and volume property: octoray trace %.2f s; "
        "vtkSmartVolumeMapper (%s on %s) first frame %.2f s (with the upload)"
        % (panel[0], panel[1], octo_trace, mode, gl, first.seconds))
    log("           -> %s" % path)
    timings.append(("head CT vtkSmartVolumeMapper", "first frame", first.seconds))
    pictures.append(path)
    octo_label.SetVisibility(0)
    cut_open(args, timings, pictures, results["ct-bone"], size, (front, up, azimuth, elevation, zoom))


def cut_open(args, timings, pictures, drawn, size, view):
    """CT-Bone's octree cut open by the mapper's cropping box: the back 55 %
    of the head from the same view, its inside lit and shadowed; the octree
    is not built again."""
    mapper, prop, ren, window, volume, bounds = drawn
    builds = mapper.GetNumberOfBuilds()
    b = bounds
    mapper.SetCropping(1)
    mapper.SetCroppingRegionFlagsToSubVolume()
    mapper.SetCroppingRegionPlanes(b[0], b[1], b[2] + 0.45 * (b[3] - b[2]), b[3], b[4], b[5])
    window.SetSize(*size)
    front, up, azimuth, elevation, zoom = view
    scene.look_at(ren, bounds, front, up, azimuth, elevation, zoom)
    wall = render_octree(ren, window, mapper)
    path = os.path.join(args.out, "ct-bone-cut.png")
    scene.write_png(scene.grab(window), path)
    log("  cut      CT-Bone cropped to the back 55 %% of the head (SetCroppingRegionPlanes), %d build%s: %s"
        % (mapper.GetNumberOfBuilds(), "" if mapper.GetNumberOfBuilds() == 1 else "s", render_line(mapper, wall, size)))
    log("           -> %s" % path)
    if mapper.GetNumberOfBuilds() != builds:
        raise RuntimeError("cropping rebuilt the octree")
    timings.append(("head CT ct-bone cut", "render", mapper.GetLastTraceSeconds()))
    pictures.append(path)


def gl_renderer(window):
    caps = window.ReportCapabilities() or ""
    for line in caps.splitlines():
        if "renderer string" in line:
            return line.split(":", 1)[1].strip().split(" (")[0]
    return "OpenGL"


# ---------------------------------------------------------------------------
def points_picture(args, timings, pictures, step, title, path, name, reader_name, size, view, depth_from_auto,
                   lights, zoom, prop_settings):
    log("[%s] %s: %s through %s" % (step, title, path, reader_name))
    reader, data, seconds = scene.read(path, progress_label="  reading")
    if data is None or data.GetNumberOfPoints() == 0:
        raise RuntimeError("no points read from %s" % path)
    arrays = scene.array_names(data)
    log("  read     %.2f s: %s points (arrays: %s)" % (seconds, format(data.GetNumberOfPoints(), ","), arrays))
    timings.append((title, "read", seconds))
    auto, auto_leaf = automatic_depth(data, args.backend)
    depth = max(1, auto + depth_from_auto)
    mapper = new_mapper(args.backend)
    mapper.SetLeafDepth(depth)
    mapper.SetShadows(True)
    mapper.SetMaximumBounces(0)
    mapper.AddObserver("ProgressEvent", scene.ProgressBar("  building"))
    prop = vtk.vtkVolumeProperty()
    prop.ShadeOn()
    for key, value in prop_settings.items():
        getattr(prop, "Set" + key)(value)
    data, colouring = scene.color_by(data, mapper, prop, scene.choose_color_by(data))
    mapper.SetInputData(data)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    size = scaled(size, args.scale)
    ren, window = new_view(size, *lights)
    ren.AddVolume(volume)
    kind = scene.input_kind(path)
    front, up = scene.default_view(data, kind, reader)
    scene.look_at(ren, data.GetBounds(), front, up, view[0], view[1], zoom)
    wall = render_octree(ren, window, mapper)
    fitted = mapper.GetLastNormalEstimateSeconds()  # that frame's: the picture's grab draws again
    out = os.path.join(args.out, name)
    scene.write_png(scene.grab(window), out)
    if not scene.has_normals(data):
        log("  normals  %.2f s: fitted to the voxels, in the first frame (EstimateNormals)"
            % fitted)
        timings.append((title, "normals", fitted))
    log("  colour   %s" % colouring)
    log("  octree   %s; LeafDepth 0 picks depth %d (leaf %.3g)%s"
        % (octree_line(mapper), auto, auto_leaf,
           "" if depth == auto else ", %d used: %s" % (depth, "one level coarser closes the holes between "
                                                                "scan lines" if depth < auto else "finer")))
    log("  build    %.2f s, %s, backend %s" % (mapper.GetLastBuildSeconds(), render_line(mapper, wall, size),
                                               mapper.GetLastUsedBackendName()))
    log("           -> %s" % out)
    timings.append((title, "build", mapper.GetLastBuildSeconds()))
    timings.append((title, "render", mapper.GetLastTraceSeconds()))
    pictures.append(out)


def laser_scan(args, timings, pictures):
    points_picture(args, timings, pictures, "2/3", "laser scan",
                   os.path.join(args.data, "External", "PCL", "table_scene_lms400.pcd"), "scan.png",
                   "vtkPCDReader", (1200, 900), view=(18.0, 12.0), depth_from_auto=-1,
                   # Key and fill balanced: on a noisy scan the key
                   # light's shadows add dots where single voxels stand
                   # above their neighbours (README, "Shadows on voxels").
                   lights=(0.55, 0.6), zoom=1.5,
                   prop_settings={"Ambient": 0.12, "Diffuse": 0.88, "Specular": 0.1, "SpecularPower": 20})


def thesis_lidar(args, timings, pictures):
    points_picture(args, timings, pictures, "3/3", "thesis LiDAR",
                   os.path.join(args.data, "Particles", "lidar_simple.particles"), "lidar.png",
                   "vtkParticleTextReader", (1200, 900), view=(-30.0, 45.0), depth_from_auto=0,
                   lights=(0.85, 0.35), zoom=1.05,
                   prop_settings={"Ambient": 0.15, "Diffuse": 0.85, "Specular": 0.1, "SpecularPower": 20})


def thumbnails(pictures, folder):
    try:
        from PIL import Image
    except ImportError:
        log("thumbnails: Pillow is not importable (python3-pil); none written")
        return
    os.makedirs(folder, exist_ok=True)
    for path in pictures:
        im = Image.open(path).convert("RGB")
        width = 960 if im.width > 1.5 * im.height else 640  # the side-by-side picture wider
        if im.width > width:
            im = im.resize((width, round(im.height * width / im.width)), Image.LANCZOS)
        out = os.path.join(folder, "demo-" + os.path.basename(path))
        im.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.FLOYDSTEINBERG).save(
            out, optimize=True)
        log("thumbnail %s (%d KB)" % (out, os.path.getsize(out) // 1024))


def main(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m octoray.demo", description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    p.add_argument("--data", default=os.environ.get("OCTORAY_DATA", "Data"), help="the Data folder")
    p.add_argument("--out", default=os.path.join("build", "demo"), help="folder for the pictures")
    p.add_argument("--backend", choices=["auto", "cuda", "cpu"], default="auto")
    p.add_argument("--scale", type=float, default=1.0, help="picture size factor (e.g. 0.25 for a quick run)")
    p.add_argument("--thumbnails", metavar="DIR", help="also write README-sized copies there (Pillow)")
    p.add_argument("--only", choices=["ct", "scan", "lidar"], action="append",
                   help="run only these parts (repeatable)")
    args = p.parse_args(argv)
    del here
    os.makedirs(args.out, exist_ok=True)
    start = time.perf_counter()
    log("octoray demo: backend %s requested, CUDA %s; pictures in %s" % (
        args.backend, "usable" if octoray.vtkOctreeVolumeMapper.IsCudaAvailable() else "not usable here",
        args.out))
    timings, pictures = [], []
    parts = args.only or ["ct", "scan", "lidar"]
    if "ct" in parts:
        head_ct(args, timings, pictures)
    if "scan" in parts:
        laser_scan(args, timings, pictures)
    if "lidar" in parts:
        thesis_lidar(args, timings, pictures)
    total = time.perf_counter() - start
    log()
    log("%-34s %-12s %8s" % ("what", "step", "seconds"))
    for what, step, seconds in timings:
        log("%-34s %-12s %8.2f" % (what, step, seconds))
    log("%-34s %-12s %8.2f" % ("demo", "total", total))
    if args.thumbnails:
        thumbnails(pictures, args.thumbnails)
    return 0


if __name__ == "__main__":
    sys.exit(main())
