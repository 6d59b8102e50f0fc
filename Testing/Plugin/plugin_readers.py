"""LoadPlugin + the plugin's readers (run by pvpython and by pvbatch).

usage: plugin_readers.py PLUGIN DATA_DIR
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

plugin, data = sys.argv[1], sys.argv[2]
LoadPlugin(plugin, remote=False, ns=globals())

failures = []


def check(what, got, expected):
    print(f"{what}: {got} (expected {expected})")
    if got != expected:
        failures.append(what)


# The particle reader by name and through File > Open's reader factory.
particles = os.path.join(data, "Particles", "lidar_simple.particles")
r = OctorayParticleReader(FileNames=[particles])
r.UpdatePipeline()
check("particles: points", r.GetDataInformation().GetNumberOfPoints(), 1065)
check("particles: Colors array", "Colors" in r.PointData.keys(), True)
factory = servermanager.vtkSMProxyManager.GetProxyManager().GetReaderFactory()
session = servermanager.ActiveConnection.Session


def readers_for(path):
    """The reader proxies File > Open offers for path."""
    found = factory.GetReaders(path, session)
    return [found.GetString(i) for i in range(1, found.GetLength(), 3)]


check("particles: File > Open offers the reader",
      "OctorayParticleReader" in readers_for(particles), True)
o = OpenDataFile(particles)
check("OpenDataFile(.particles)", o.GetXMLName(), "OctorayParticleReader")

# A PCD file (written here: the real scans come with `make data`) through
# the reader factory: OpenDataFile picks the PCD reader.
import tempfile  # noqa: E402

pcd = os.path.join(tempfile.mkdtemp(), "cloud.pcd")
with open(pcd, "w") as f:
    f.write("VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
            "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
            "0 0 0 1\n1 0 0 2\n0 1 0 3\n")
check("PCD: File > Open offers the reader", "OctorayPCDReader" in readers_for(pcd), True)
p = OpenDataFile(pcd)
check("OpenDataFile(.pcd)", p.GetXMLName(), "OctorayPCDReader")
p.UpdatePipeline()
check("PCD: points", p.GetDataInformation().GetNumberOfPoints(), 3)
check("PCD: Intensity array", "Intensity" in p.PointData.keys(), True)

# A DICOM folder: the folder reader, then the same files as a series.
folder = os.path.join(data, "DICOM", "CT5N")
d = OctoraySliceFolderReader(DirectoryName=folder)
d.UpdatePipeline()
dicom_points = d.GetDataInformation(0).GetNumberOfPoints()
check("DICOM folder: particles > 0", dicom_points > 0, True)
volume = d.GetDataInformation(1)
check("DICOM folder: volume slices", volume.GetExtent()[5] - volume.GetExtent()[4] + 1, 5)
check("DICOM folder: File > Open offers the folder reader",
      "OctoraySliceFolderReader" in readers_for(folder), True)
files = sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".dcm"))
s = OctoraySliceStackReader(FileNames=files, BackgroundRange=[0, 0])
s.UpdatePipeline()
check("DICOM series: same points as the folder", s.GetDataInformation(0).GetNumberOfPoints(),
      dicom_points)
check("DICOM .dcm: File > Open offers the series reader",
      "OctoraySliceStackReader" in readers_for(files[0]), True)
# Both slice readers take their options from one definition
# (OctoraySliceReaderBase): the same list, each documented, and each reader
# offered only for what it reads.
options = ["Spacing", "Origin", "UseMetadata", "BackgroundRange", "RegionOfInterest", "Stride",
           "FillBetweenSlices", "GenerateVertices"]
for name, proxy in (("folder", d), ("series", s)):
    check(f"{name} reader: its options", [o for o in options if proxy.GetProperty(o)], options)
    check(f"{name} reader: each documented",
          [o for o in options if not proxy.GetProperty(o).GetDocumentation().GetDescription()], [])
    check(f"{name} reader: two outputs", proxy.GetNumberOfOutputPorts(), 2)
check("DICOM .dcm: not offered the folder reader", "OctoraySliceFolderReader" in readers_for(files[0]), False)
check("DICOM folder: not offered the series reader", "OctoraySliceStackReader" in readers_for(folder), False)
strided = OctoraySliceStackReader(FileNames=files, Stride=[2, 2, 1])
strided.UpdatePipeline()
check("DICOM series: a stride of 2 thins the particles",
      0 < strided.GetDataInformation(0).GetNumberOfPoints() < dicom_points, True)

# A numbered series of particle files (and of PCD files), as File > Open
# groups them: one reader, each file a time step (a list of files was
# refused: "This property requires 1 values").
series = tempfile.mkdtemp()
names = []
for k in range(3):
    names.append(os.path.join(series, "p_%03d.particles" % k))
    with open(names[-1], "w") as f:
        f.write("".join("%d %d 0\n" % (i, k) for i in range(10 + k)))
t = OpenDataFile(names)
check("particle series: the reader", t.GetXMLName(), "OctorayParticleReader")
check("particle series: its time steps", list(t.TimestepValues), [0.0, 1.0, 2.0])
check("particle series: each step's points",
      [(t.UpdatePipeline(time), t.GetDataInformation().GetNumberOfPoints())[1] for time in (0.0, 1.0, 2.0)],
      [10, 11, 12])
pcds = []
for k in range(2):
    pcds.append(os.path.join(series, "c_%d.pcd" % k))
    with open(pcds[-1], "w") as f:
        f.write("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH %d\nHEIGHT 1\n"
                "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA ascii\n" % (3 + k, 3 + k))
        f.write("".join("%d 0 0\n" % i for i in range(3 + k)))
c = OctorayPCDReader(FileNames=pcds)
check("PCD series: each step's points",
      [(c.UpdatePipeline(time), c.GetDataInformation().GetNumberOfPoints())[1] for time in c.TimestepValues], [3, 4])

# A folder without slices: the reader says so once, and nothing else (in one
# update ParaView asks for the information and then the data: the error was
# said twice, and VTK added that the volume output had no whole extent).
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow  # noqa: E402
empty = tempfile.mkdtemp()
paraview_window, said = vtkOutputWindow.GetInstance(), vtkStringOutputWindow()
vtkOutputWindow.SetInstance(said)
OctoraySliceFolderReader(DirectoryName=empty).UpdatePipeline()
vtkOutputWindow.SetInstance(paraview_window)
check("empty folder: the reader's error, said once",
      said.GetOutput().count("the directory '%s' has no image or DICOM files" % empty), 1)
check("empty folder: no word of a whole extent", "whole extent" in said.GetOutput(), False)

if failures:
    print("FAILED:", ", ".join(failures))
    sys.exit(1)
print("OK")
