"""Render point data with the octree volume mapper from the command line.

    python3 -m octoray.render INPUT -o out.png [--backend auto|cuda|cpu]
        [--size 1920x1080] [--mode surface|phong|depthcue|composite|mip|minip|average|additive]
        [--shadows] [--preset ct-bone|ct-skin|ct-muscle] [--threshold V]
        [--color-by auto|colors|intensity|z|none|ARRAY] [--normals auto|pcl|voxels|none]
        [--azimuth DEG] [--elevation DEG] [--zoom F] [--parallel] [--depth N]
        [--background LO HI] [--particles] [--no-fill]
        [--clip OX OY OZ NX NY NZ]... [--crop X0 X1 Y0 Y1 Z0 Z1]

INPUT is a particle text file (.particles, .txt, .xyz, .gz, ...), a PCL point
cloud (.pcd: ascii, binary or binary_compressed), a folder of image slices or
DICOM files, or a printf pattern of slice names ("ct_%03d.png"; --range FIRST
LAST, by default every number it names a file for). Slice stacks are drawn from the reader's image output (its
volume, a vtkImageData; --particles: its particles): voxels above
--threshold (default: the preset's, else 0) become the octree, with
interpolated points between slices (--no-fill: not), so the stack draws as a
closed volume, shaded by the CT's gradient. Reading, normals and building
show a progress bar on stderr; the backend, the octree's points, depth and
leaf size and the load, normals, build and render times are printed on
stdout.

Defaults: --preset applies a CT transfer function (Hounsfield units) and its
threshold; points without RGB colours are coloured by their Intensity array,
else by elevation z, through viridis over the 1st to 99th percentile;
--mode phong lights points that have no normals by normals fitted to the
octree's voxels (the mapper's EstimateNormals; a slice stack's particles
carry the reader's gradient normals; --normals pcl estimates them with PCL
instead, none lights the voxels by their occupancy); the
camera faces a DICOM head from the front (patient anterior, head up) and a
PCD scan from its sensor, --azimuth and --elevation turn it from there; a
key light above-left of the camera casts the shadows (--shadows) and a
headlight fills them.
"""
import argparse
import math
import os
import sys

import vtk

import octoray
from octoray import scene

MODES = {
    "surface": ("surface", False),
    "phong": ("surface", True),
    "depthcue": ("surface", False),
    "composite": ("composite", False),
    "mip": ("mip", False),
    "minip": ("minip", False),
    "average": ("average", False),
    "additive": ("additive", False),
}

# Kept for scripts that imported it from here.
ProgressBar = scene.ProgressBar


MAX_SIDE = 16384


def parse_size(text):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError("expected WIDTHxHEIGHT, e.g. 1920x1080, got %r" % text)
    if w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError("the size must be positive, got %r" % text)
    if max(w, h) > MAX_SIDE:
        # Past it OpenGL refused the window's textures, with a flood of its
        # errors and a crash.
        raise argparse.ArgumentTypeError("at most %d pixels a side (OpenGL's usual limit), got %r" % (MAX_SIDE, text))
    return w, h


def finite(text):
    """A finite number (NaN made the camera's matrices singular)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("expected a number, got %r" % text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError("expected a finite number, got %r" % text)
    return value


def positive(text):
    """A finite number above 0 (--zoom 0 and -1 were ignored)."""
    value = finite(text)
    if value <= 0:
        raise argparse.ArgumentTypeError("expected a number above 0, got %r" % text)
    return value


def parser():
    p = argparse.ArgumentParser(prog="python3 -m octoray.render", description=__doc__.splitlines()[0],
                                epilog=__doc__.split("\n\n", 2)[2], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("input")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--backend", choices=["auto", "cuda", "cpu"], default="auto")
    p.add_argument("--size", type=parse_size, default=(1920, 1080))
    p.add_argument("--mode", choices=sorted(MODES), default="surface")
    p.add_argument("--shadows", action="store_true", help="shadow rays towards the lights (phong)")
    p.add_argument("--preset", metavar="NAME",
                   help="CT transfer function: %s" % ", ".join(octoray.preset_names()))
    p.add_argument("--threshold", type=float, default=None, metavar="V",
                   help="slice stacks: voxels at or below V are empty (default: the preset's, else 0)")
    p.add_argument("--color-by", default="auto", metavar="WHAT",
                   help="points: colors, intensity, z, none or an array name, by its magnitude where it has "
                        "several components (auto: colors when the points have them, else Intensity, else z)")
    p.add_argument("--normals", choices=["auto", "pcl", "voxels", "none"], default="auto",
                   help="auto: for points without normals, fitted to the octree's voxels (the mapper's "
                        "EstimateNormals), for a slice stack's particles the reader's gradient; voxels: "
                        "fitted to the voxels; pcl: PCL's, 16 neighbours; none: the voxels' occupancy")
    p.add_argument("--azimuth", type=finite, default=0.0)
    p.add_argument("--elevation", type=finite, default=0.0)
    p.add_argument("--zoom", type=positive, default=1.0)
    p.add_argument("--depth", type=int, default=0, help="octree leaf level (0: automatic)")
    p.add_argument("--range", type=int, nargs=2, default=None, metavar=("FIRST", "LAST"),
                   help="the slice numbers a pattern of slice names reads (default: every number it names "
                        "a file for, from the lowest to the highest)")
    p.add_argument("--background", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                   help="slice intensities that are background: as --threshold HI (--particles: the "
                        "reader's BackgroundRange)")
    p.add_argument("--parallel", action="store_true", help="parallel projection")
    p.add_argument("--image", action="store_true",
                   help="slice stacks: draw the stack's volume (a vtkImageData; the default)")
    p.add_argument("--particles", action="store_true",
                   help="slice stacks: draw the reader's particles instead of its volume")
    p.add_argument("--no-fill", action="store_true",
                   help="slice stacks: no points between slices (leaves as large as the slice spacing)")
    p.add_argument("--clip", type=float, nargs=6, action="append", default=[],
                   metavar=("OX", "OY", "OZ", "NX", "NY", "NZ"),
                   help="a clipping plane through (OX, OY, OZ) in the data's coordinates, keeping the side "
                        "its normal points to (the mapper's AddClippingPlane); repeatable")
    p.add_argument("--crop", type=float, nargs=6, default=None, metavar=("X0", "X1", "Y0", "Y1", "Z0", "Z1"),
                   help="keep the box between these fractions (0..1) of the drawn bounds along x, y and z "
                        "(the mapper's cropping to the sub-volume), e.g. 0 1 0.5 1 0 1 for the half of larger y")
    return p


def check_output(p, path):
    """-o names a PNG file in a folder that exists, said before anything is
    read or drawn (a folder got VTK's "Ran out of disk space", a .jpg name
    PNG bytes)."""
    if os.path.isdir(path):
        p.error("-o names a folder, %s; give the PNG file to write" % path)
    if not path.lower().endswith(".png"):
        p.error("-o writes a PNG picture; name the file .png, got %s" % path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        p.error("-o: no folder %s to write %s into" % (folder, os.path.basename(path)))


def check_cuts(p, args):
    """--clip needs a finite plane with a normal, --crop fractions that
    leave a box: an error naming the option otherwise."""
    for plane in args.clip:
        if not all(map(math.isfinite, plane)) or not any(plane[3:]):
            p.error("--clip needs a finite origin and a non-zero normal, got %s" % " ".join("%g" % v for v in plane))
    if args.crop is not None:
        box = args.crop
        if not all(0.0 <= box[2 * a] < box[2 * a + 1] <= 1.0 for a in range(3)):
            p.error("--crop needs fractions 0 <= low < high <= 1 on each axis, got %s"
                    % " ".join("%g" % v for v in box))


def add_cuts(mapper, args, bounds):
    """The clipping planes and the cropping box of --clip and --crop; the
    box in fractions of `bounds`, what the camera frames."""
    for plane in args.clip:
        cut = vtk.vtkPlane()
        cut.SetOrigin(*plane[:3])
        cut.SetNormal(*plane[3:])
        mapper.AddClippingPlane(cut)
    if args.crop is not None:
        box = [bounds[2 * a] + f * (bounds[2 * a + 1] - bounds[2 * a])
               for a in range(3) for f in args.crop[2 * a:2 * a + 2]]
        mapper.SetCropping(1)
        mapper.SetCroppingRegionFlagsToSubVolume()
        mapper.SetCroppingRegionPlanes(*box)


def main(argv=None):
    p = parser()
    args = p.parse_args(argv)

    if not (os.path.exists(args.input) or "%" in args.input):
        p.error("no such file or folder: %s" % args.input)
    check_output(p, args.output)
    if args.preset is not None and not octoray.vtkOctreeVolumePresets.HasPreset(args.preset):
        p.error("unknown preset %r; known presets: %s"
                % (args.preset, octoray.vtkOctreeVolumePresets.GetNamesAsString()))
    if not 0 <= args.depth <= 21:
        p.error("--depth must be 0 (automatic) or 1..21, got %d" % args.depth)
    check_cuts(p, args)
    blend, shade = MODES[args.mode]

    # ---- Load.
    kind = scene.input_kind(args.input)
    if (args.image or args.particles or args.no_fill) and kind != "slices":
        p.error("--image, --particles and --no-fill need a slice stack (a folder or a pattern of slices)")
    if args.image and args.particles:
        p.error("--image and --particles exclude each other")
    threshold = args.threshold
    if args.background is not None and threshold is None:
        threshold = args.background[1]
    if args.preset is not None and threshold is None and blend == "surface":
        threshold = octoray.vtkOctreeVolumePresets.GetSurfaceThreshold(args.preset)

    def configure(reader):
        if kind != "slices":
            return
        reader.SetFillBetweenSlices(not args.no_fill)
        reader.SetGradientNormals(args.particles and shade and args.normals == "auto")
        if args.particles and args.background is not None:
            reader.SetBackgroundRange(*args.background)
        elif args.particles and threshold is not None:
            reader.SetBackgroundRange(-1e300, threshold)

    reader, data, load = scene.read(args.input, args.range, configure=configure, particles=args.particles)
    if data is None or data.GetNumberOfPoints() == 0:
        why = reader.GetErrorMessage() if hasattr(reader, "GetErrorMessage") else ""
        print("error: %s" % (why or "nothing read from %s" % args.input), file=sys.stderr)
        return 1
    image = isinstance(data, vtk.vtkImageData)

    # ---- Normals: PCL's where asked for; else the mapper fits them to the
    # voxels where shading needs them and the points have none.
    normals_seconds = None
    if not image and args.normals == "pcl":
        data, normals_seconds, invalid = scene.estimate_normals(data)

    # ---- Mapper, colours and scene.
    mapper = {"auto": octoray.vtkOctreeVolumeMapper,
              "cuda": octoray.vtkCudaOctreeVolumeMapper,
              "cpu": octoray.vtkCPUOctreeVolumeMapper}[args.backend]()
    mapper.SetLeafDepth(args.depth)
    mapper.SetEstimateNormals(args.normals != "none")
    mapper.AddObserver("ProgressEvent", scene.ProgressBar("building"))
    {"surface": mapper.SetBlendModeToSurface,
     "composite": mapper.SetBlendModeToComposite,
     "mip": mapper.SetBlendModeToMaximumIntensity,
     "minip": mapper.SetBlendModeToMinimumIntensity,
     "average": mapper.SetBlendModeToAverageIntensity,
     "additive": mapper.SetBlendModeToAdditive}[blend]()
    if args.mode == "depthcue":
        mapper.SetDepthCue(0.7)
    mapper.SetShadows(args.shadows and shade)
    mapper.SetFillBetweenSlices(not args.no_fill)
    prop = vtk.vtkVolumeProperty()
    colouring = None
    if args.preset is not None:
        scalars = data.GetPointData().GetScalars()
        if scalars is None or scalars.GetNumberOfComponents() != 1:
            print("error: --preset needs one-component scalars (a CT's Hounsfield units); %s has %s"
                  % (args.input, "none" if scalars is None else "%d components" % scalars.GetNumberOfComponents()),
                  file=sys.stderr)
            return 1
        octoray.apply_preset(args.preset, prop)
        colouring = "preset %s" % args.preset
    else:
        try:
            data, colouring = scene.color_by(data, mapper, prop, scene.choose_color_by(data, args.color_by))
        except ValueError as e:
            print("error: --color-by: %s" % e, file=sys.stderr)
            return 1
        scalars = data.GetPointData().GetScalars()
        if kind == "slices" and scalars is not None and scalars.GetNumberOfComponents() == 1:
            lo, hi = scalars.GetRange()
            if image and threshold is not None:
                lo = max(lo, min(threshold, hi))  # the transfer function over the drawn values
            ctf = vtk.vtkColorTransferFunction()
            ctf.AddRGBPoint(lo, 0.2, 0.2, 0.9)
            ctf.AddRGBPoint(0.5 * (lo + hi), 0.9, 0.8, 0.3)
            ctf.AddRGBPoint(hi, 1.0, 1.0, 1.0)
            opacity = vtk.vtkPiecewiseFunction()
            opacity.AddPoint(lo, 0.0 if blend != "surface" else 1.0)
            opacity.AddPoint(hi, 1.0)
            prop.SetColor(ctf)
            prop.SetScalarOpacity(opacity)
    if shade:
        prop.ShadeOn()
        if args.preset is None:
            prop.SetAmbient(0.15)
            prop.SetDiffuse(0.85)
            prop.SetSpecular(0.15)
            prop.SetSpecularPower(20)
    if image:
        mapper.SetImageBackground(threshold if threshold is not None else 0.0)
    mapper.SetInputData(data)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    if shade:
        scene.add_lights(ren, key=0.85 if image else 0.55, fill=0.35 if image else 0.6)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*args.size)
    window.AddRenderer(ren)
    front, up = scene.default_view(data, kind, reader)
    # Points: the voxels' bounds, which reach past the points by up to a
    # leaf (points all at one place fill a leaf with a corner at them).
    bounds = [0.0] * 6
    if image:
        bounds = scene.visible_bounds(data, mapper.GetImageBackground())
    else:
        mapper.GetVoxelBounds(bounds)
    scene.look_at(ren, bounds, front, up, args.azimuth, args.elevation, args.zoom)
    add_cuts(mapper, args, bounds)
    ren.GetActiveCamera().SetParallelProjection(args.parallel)

    # ---- Build and render: the first render builds the octree.
    with scene.Timer() as first:
        window.Render()
    build = mapper.GetLastBuildSeconds()
    fitted = mapper.GetLastNormalEstimateSeconds()  # normals fitted to the voxels, in the first frame
    if mapper.GetLastUsedBackend() < 0:
        print("error: nothing was drawn (see the messages above)", file=sys.stderr)
        return 1
    try:
        scene.write_png(scene.grab(window), args.output)
    except OSError as e:
        print("error: %s" % e, file=sys.stderr)
        return 1

    no_cuda = args.backend == "auto" and not mapper.IsCudaAvailable()
    print("backend: %s%s" % (mapper.GetBackendDescription(), ", no usable CUDA device" if no_cuda else ""))
    if image:
        d = data.GetDimensions()
        print("input: %d voxels (%d x %d x %d)" % (data.GetNumberOfPoints(), d[0], d[1], d[2]))
        print("threshold: %g (voxels at or below are empty)" % mapper.GetImageBackground())
    else:
        print("input: %d point%s" % (data.GetNumberOfPoints(), "" if data.GetNumberOfPoints() == 1 else "s"))
    print("points: %d (in the octree%s)" % (mapper.GetNumberOfOctreePoints(), ", of the image" if image else ""))
    print("depth: %d%s" % (mapper.GetOctreeDepth(), " (automatic)" if args.depth == 0 else ""))
    print("leaf: %.6g" % mapper.GetLeafSize())
    if colouring:
        print("colour: %s" % colouring)
    if args.clip or args.crop:
        print("cut: %d clipping plane%s%s" % (len(args.clip), "" if len(args.clip) == 1 else "s",
                                             ", cropped to a box" if args.crop else ""))
    print("load: %.3f s" % load)
    if normals_seconds is not None:
        print("normals: %.3f s (PCL, 16 neighbours)" % normals_seconds)
    if fitted > 0:
        print("normals: %.3f s (fitted to the voxels, in the first frame)" % fitted)
    print("build: %.3f s" % build)
    print("render: %.3f s (trace %.3f s, first frame with build %.3f s) at %dx%d"
          % (mapper.GetLastTraceSeconds() + mapper.GetLastDepthReadSeconds() + mapper.GetLastUploadSeconds()
             + mapper.GetLastDrawSeconds(), mapper.GetLastTraceSeconds(), first.seconds, args.size[0], args.size[1]))
    print("wrote %s" % args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
