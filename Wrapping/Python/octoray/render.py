"""Render point data with the octree volume mapper from the command line.

    python3 -m octoray.render INPUT -o out.png [--backend auto|cuda|cpu]
        [--size 1920x1080] [--mode surface|phong|depthcue|composite|mip|minip|average|additive]
        [--azimuth DEG] [--elevation DEG] [--zoom F] [--parallel] [--depth N]
        [--background LO HI] [--image] [--no-fill]

INPUT is a particle text file (.particles, .txt, .xyz, .gz, ...), a PCL point
cloud (.pcd: ascii, binary or binary_compressed), a folder of
image slices or DICOM files, or a printf pattern of slice names
("ct_%03d.png", with --range FIRST LAST). A slice stack is drawn as the
reader's particles, or with --image as the stack's volume (the reader's
output 1, a vtkImageData; voxels above --background's HI are points); either
way the space between slices is filled with interpolated points (--no-fill:
not), so the stack draws as a closed volume. Reading and building show a
progress bar on stderr; the backend, the number of points, the leaf size and
the load, build and render times are printed on stdout.
"""
import argparse
import os
import sys
import time

import vtk

import octoray

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


class ProgressBar:
    """A text progress bar on stderr, fed by an algorithm's ProgressEvent."""

    def __init__(self, label):
        self.label = label
        self.shown = -1

    def __call__(self, algorithm, event):
        self.show(algorithm.GetProgress())

    def show(self, fraction):
        percent = int(100 * fraction)
        if percent != self.shown:
            self.shown = percent
            bar = "#" * (percent // 4)
            sys.stderr.write("\r%-8s [%-25s] %3d%%" % (self.label, bar, percent))
            if percent >= 100:
                sys.stderr.write("\n")
            sys.stderr.flush()


def make_reader(path, args):
    if os.path.isdir(path) or "%" in path:
        reader = octoray.vtkSliceStackReader()
        if os.path.isdir(path):
            reader.SetDirectoryName(path)
        else:
            reader.SetFilePattern(path)
            reader.SetFileNameRange(*args.range)
        if args.background is not None:
            reader.SetBackgroundRange(*args.background)
        reader.SetFillBetweenSlices(not args.no_fill)
        return reader
    if path.lower().endswith((".pcd", ".pcd.gz")):
        reader = octoray.vtkPCDReader()  # PCL's point cloud files
    else:
        reader = octoray.vtkParticleReader()
    reader.SetFileName(path)
    reader.SetOutputPointsPrecision(vtk.vtkAlgorithm.DOUBLE_PRECISION)
    return reader


def parse_size(text):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError("expected WIDTHxHEIGHT, e.g. 1920x1080, got %r" % text)
    if w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError("the size must be positive, got %r" % text)
    return w, h


def main(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m octoray.render", description=__doc__.splitlines()[0])
    p.add_argument("input")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--backend", choices=["auto", "cuda", "cpu"], default="auto")
    p.add_argument("--size", type=parse_size, default=(1920, 1080))
    p.add_argument("--mode", choices=sorted(MODES), default="surface")
    p.add_argument("--azimuth", type=float, default=0.0)
    p.add_argument("--elevation", type=float, default=0.0)
    p.add_argument("--zoom", type=float, default=1.0)
    p.add_argument("--depth", type=int, default=0, help="octree leaf level (0: automatic)")
    p.add_argument("--range", type=int, nargs=2, default=(0, 0), metavar=("FIRST", "LAST"))
    p.add_argument("--background", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                   help="slice intensities that are background")
    p.add_argument("--parallel", action="store_true", help="parallel projection")
    p.add_argument("--image", action="store_true",
                   help="slice stacks: draw the stack's volume (a vtkImageData) instead of its particles")
    p.add_argument("--no-fill", action="store_true",
                   help="slice stacks: no points between slices (leaves as large as the slice spacing)")
    args = p.parse_args(argv)

    if not (os.path.exists(args.input) or "%" in args.input):
        p.error("no such file or folder: %s" % args.input)

    # ---- Load.
    start = time.perf_counter()
    reader = make_reader(args.input, args)
    reader.AddObserver("ProgressEvent", ProgressBar("reading"))
    reader.Update()
    cloud = reader.GetOutput()
    load = time.perf_counter() - start
    if cloud is None or cloud.GetNumberOfPoints() == 0:
        print("error: no points read from %s" % args.input, file=sys.stderr)
        return 1
    if args.image and not isinstance(reader, octoray.vtkSliceStackReader):
        p.error("--image needs a slice stack (a folder or a pattern of slices)")
    data = reader.GetImageOutput() if args.image else cloud

    # ---- Mapper and scene.
    mapper = {"auto": octoray.vtkOctreeVolumeMapper,
              "cuda": octoray.vtkCudaOctreeVolumeMapper,
              "cpu": octoray.vtkCPUOctreeVolumeMapper}[args.backend]()
    mapper.SetInputData(data)
    mapper.SetLeafDepth(args.depth)
    mapper.SetFillBetweenSlices(not args.no_fill)
    if args.image and args.background is not None:
        mapper.SetImageBackground(args.background[1])
    mapper.AddObserver("ProgressEvent", ProgressBar("building"))
    blend, shade = MODES[args.mode]
    {"surface": mapper.SetBlendModeToSurface,
     "composite": mapper.SetBlendModeToComposite,
     "mip": mapper.SetBlendModeToMaximumIntensity,
     "minip": mapper.SetBlendModeToMinimumIntensity,
     "average": mapper.SetBlendModeToAverageIntensity,
     "additive": mapper.SetBlendModeToAdditive}[blend]()
    if args.mode == "depthcue":
        mapper.SetDepthCue(0.7)
    prop = vtk.vtkVolumeProperty()
    prop.SetShade(shade)
    scalars = data.GetPointData().GetScalars()
    if scalars is not None and scalars.GetNumberOfComponents() in (3, 4):
        prop.IndependentComponentsOff()  # RGB(A) point colours
    elif scalars is not None:
        lo, hi = scalars.GetRange()
        if args.image and args.background is not None:
            lo = max(lo, args.background[1])  # the transfer function over the points' values
        ctf = vtk.vtkColorTransferFunction()
        ctf.AddRGBPoint(lo, 0.2, 0.2, 0.9)
        ctf.AddRGBPoint(0.5 * (lo + hi), 0.9, 0.8, 0.3)
        ctf.AddRGBPoint(hi, 1.0, 1.0, 1.0)
        opacity = vtk.vtkPiecewiseFunction()
        opacity.AddPoint(lo, 0.0 if blend != "surface" else 1.0)
        opacity.AddPoint(hi, 1.0)
        prop.SetColor(ctf)
        prop.SetScalarOpacity(opacity)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*args.size)
    window.AddRenderer(ren)
    ren.ResetCamera()
    cam = ren.GetActiveCamera()
    cam.Azimuth(args.azimuth)
    cam.Elevation(args.elevation)
    cam.OrthogonalizeViewUp()
    cam.SetParallelProjection(args.parallel)
    cam.Zoom(args.zoom)
    ren.ResetCameraClippingRange()

    # ---- Build and render: the first render builds the octree.
    start = time.perf_counter()
    window.Render()
    first = time.perf_counter() - start
    build = mapper.GetLastBuildSeconds()
    if mapper.GetLastUsedBackend() < 0:
        print("error: nothing was drawn (see the messages above)", file=sys.stderr)
        return 1
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(args.output)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()

    print("backend: %s (%s)" % (mapper.GetLastUsedBackendName(), mapper.GetBackendDescription()))
    print("points: %d%s" % (mapper.GetNumberOfOctreePoints(), " (of the image)" if args.image else ""))
    print("leaf: %.6g" % mapper.GetLeafSize())
    print("load: %.3f s" % load)
    print("build: %.3f s" % build)
    print("render: %.3f s (trace %.3f s, first frame with build %.3f s) at %dx%d"
          % (mapper.GetLastTraceSeconds() + mapper.GetLastDepthReadSeconds() + mapper.GetLastUploadSeconds()
             + mapper.GetLastDrawSeconds(), mapper.GetLastTraceSeconds(), first, args.size[0], args.size[1]))
    print("wrote %s" % args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
