"""The "Octree Volume" representation as users run it: a reader, Show,
"Octree Volume", SaveScreenshot; on one rank or under `mpiexec -np N
pvbatch` with no RedistributeDataSet (the reader's data stays where it was
read: rank 0 holds every point, the other ranks an empty piece).

usage: plugin_parallel.py PLUGIN DATA_FILE READER OUTPUT.png
           [--ranks N] [--reference ONE_RANK.png] [--tolerance F]
           [--expect-reader NAME] [--expect-array NAME]... [--shade]
           [--blend MODE --leaf-depth D --unit-distance U --centre]

READER: the proxy to read DATA_FILE with, by its XML name (e.g.
OctorayParticleReader); "open" takes what OpenDataFile picks (File > Open),
which --expect-reader checks; "Wavelet" (DATA_FILE "-") is ParaView's
source, an image that it splits over the ranks by extent, drawn with
--image-background as its background. A missing DATA_FILE fails the test and
says that `make data` fetches it.

1. The user's script, as written: Show, SetRepresentationType, SaveScreenshot
   with ParaView's defaults. It must not fail on any rank (it crashed rank 1
   with SIGSEGV: "vtkPVLODVolume: You must give me a mapper!"). Its picture is
   not compared: paraview.simple's SaveScreenshot does not reset the camera,
   so it shows the view's default camera, not the data, on any rank count.
2. The same display with a camera on the data (and, with --blend, a
   translucent blend mode coloured and made transparent through the
   Reflectivity array), saved as OUTPUT.png:
   - on one rank (no --reference): the octree must cover at least 5 % of the
     picture (it draws);
   - with --reference (the one-rank picture of step 2): at most F (default
     0.0001, i.e. 0.01 %, 12 pixels) of the pixels may differ from it by more
     than 8/255 in any channel. Opaque surface mode with every point on rank
     0: the other ranks add background at far depth, so IceT's depth
     composite is the one-rank picture (here to the bit; the margin is for
     other OpenGL implementations). The translucent modes are given a wider
     tolerance by the test list (see CMakeLists.txt).
   FXAA is off in both (see below).
"""
import argparse
import os
import sys

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

parser = argparse.ArgumentParser()
parser.add_argument("plugin")
parser.add_argument("data")
parser.add_argument("reader")
parser.add_argument("output")
parser.add_argument("--ranks", type=int, default=1)
parser.add_argument("--reference")
parser.add_argument("--blend")
parser.add_argument("--tolerance", type=float, default=0.0001)
parser.add_argument("--expect-reader", help="the reader OpenDataFile must pick")
parser.add_argument("--expect-array", action="append", default=[],
                    help="a point array the reader's output must have")
parser.add_argument("--shade", action="store_true", help="Phong shading (normals)")
parser.add_argument("--leaf-depth", type=int, default=6)
parser.add_argument("--unit-distance", type=float)
parser.add_argument("--image-background", type=float, help="the Octree Volume's ImageBackground")
parser.add_argument("--centre", action="store_true",
                    help="translate the data's centre to the origin (Transform filter)")
args = parser.parse_args()

if args.reader != "Wavelet" and not os.path.isfile(args.data):
    print(f"FAILED: the test data {args.data} is missing; `make data` fetches it "
          "(Data/External: from Debian packages, not committed)")
    sys.exit(1)
ranks = servermanager.ActiveConnection.GetNumberOfDataPartitions()
print(f"ranks: {ranks} (expected {args.ranks})")
if ranks != args.ranks:
    print("FAILED: not run on the expected number of ranks")
    sys.exit(1)

# --- 1. The user's script -------------------------------------------------
LoadPlugin(args.plugin, remote=False, ns=globals())
if args.reader == "open":
    r = OpenDataFile(args.data)
elif args.reader == "Wavelet":
    r = Wavelet()
else:
    r = getattr(servermanager.sources, args.reader)(FileNames=[args.data])
print("reader:", r.GetXMLName())
if args.expect_reader and r.GetXMLName() != args.expect_reader:
    print(f"FAILED: the reader is {r.GetXMLName()}, expected {args.expect_reader}")
    sys.exit(1)
r.UpdatePipeline()
for name in args.expect_array:
    if name not in r.PointData.keys():
        print(f"FAILED: no point array {name} in {r.PointData.keys()}")
        sys.exit(1)
if args.centre:
    # ParaView 5.11's k-d tree for ordered compositing (DIY, in 32-bit
    # floats) does not split data far from the origin: the LiDAR tile's UTM
    # coordinates all land on one rank. Near the origin the points are
    # really shared out, and the blend over ranks is what is tested.
    b = r.GetDataInformation().GetBounds()
    r = Transform(Input=r)
    r.Transform.Translate = [-0.5 * (b[0] + b[1]), -0.5 * (b[2] + b[3]), -0.5 * (b[4] + b[5])]
d = Show(r)
d.SetRepresentationType("Octree Volume")
if args.image_background is not None:
    ColorBy(d, ("POINTS", "RTData"))
    d.ImageBackground = args.image_background
    d.LeafDepth = args.leaf_depth
plain = os.path.splitext(args.output)[0] + "_default_camera.png"
SaveScreenshot(plain)
if not os.path.isfile(plain):
    print("FAILED: the user's script saved no picture")
    sys.exit(1)
points = r.GetDataInformation().GetNumberOfPoints()
print(f"points: {points}; representation: {d.Representation}")

# --- 2. A camera on the data ------------------------------------------------
view = GetActiveView()
view.ViewSize = [400, 300]
view.OrientationAxesVisibility = 0
view.Background = [0.1, 0.1, 0.15]
view.UseColorPaletteForBackground = 0
# ParaView's FXAA (on in its default settings) runs before the volumes on one
# rank but over the composited picture on several (vtkSynchronizedRenderers),
# so with it every voxel edge of the parallel picture is antialiased and the
# two cannot be compared pixel for pixel.
view.UseFXAA = 0
if args.shade:
    d.OctreeShade = 1
if args.blend:
    # Translucent: coloured and made transparent by one scalar, at a fixed
    # leaf depth (the view redistributes the points over the ranks, and the
    # automatic depth would be chosen from each rank's share).
    ColorBy(d, ("POINTS", "Reflectivity"))
    d.RescaleTransferFunctionToDataRange(True, False)
    opacity = GetOpacityTransferFunction("Reflectivity")
    lo, hi = r.PointData["Reflectivity"].GetRange()
    print(f"Reflectivity {lo:g}..{hi:g}")
    opacity.Points = [lo, 0.2, 0.5, 0.0, hi, 0.8, 0.5, 0.0]
    d.ScalarOpacityFunction = opacity
    d.OctreeBlendMode = args.blend
    d.LeafDepth = args.leaf_depth
    if args.unit_distance:
        d.ScalarOpacityUnitDistance = args.unit_distance
view.ResetCamera()
camera = view.GetActiveCamera()
camera.Elevation(35)
camera.Azimuth(20)
view.ResetCamera()
SaveScreenshot(args.output, view, ImageResolution=[400, 300])
print("saved", args.output)

from vtkmodules.vtkIOImage import vtkPNGReader  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
import numpy as np  # noqa: E402


def load(path):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    img = reader.GetOutput()
    return img.GetDimensions(), vtk_to_numpy(img.GetPointData().GetScalars()).astype(int)[:, :3]


dims, got = load(args.output)
background = np.array([round(0.1 * 255), round(0.1 * 255), round(0.15 * 255)])
drawn = (np.abs(got - background).max(axis=1) > 8).mean()
print(f"octree covers {100 * drawn:.1f} % of the picture")
if args.reference is None:
    if drawn < 0.05:
        print("FAILED: the octree covers less than 5 % of the one-rank picture")
        sys.exit(1)
else:
    rdims, want = load(args.reference)
    if dims != rdims:
        print(f"FAILED: size {dims} differs from the one-rank picture's {rdims}")
        sys.exit(1)
    diff = np.abs(got - want).max(axis=1)
    bad = (diff > 8).mean()
    print(f"pixels differing from the one-rank picture by > 8/255: {100 * bad:.3f} % "
          f"(tolerance {100 * args.tolerance:.3f} %); largest difference {diff.max()}")
    if bad > args.tolerance:
        print("FAILED: the composited picture differs from the one-rank picture")
        sys.exit(1)
print("OK")
