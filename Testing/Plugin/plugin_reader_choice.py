"""Which reader ParaView offers for particle text named .txt, .csv or .xyz.

usage: plugin_reader_choice.py PLUGIN DATA_DIR WORK_DIR

ParaView's reader factory takes every reader whose ReaderFactory hint names
the file's extension and asks each one's CanReadFile. The particle reader
claims .txt, .csv and .xyz (and .gz of each) and says yes only to particle
text (vtkParticleTextReader::CanReadFile, which parses the first lines with
the reader's own format code). Checked here, on files written to WORK_DIR:

- File > Open's list (vtkSMReaderFactory::GetReaders) holds
  OctorayParticleReader for the thesis example as .txt, .txt.gz, .csv (with a
  header line) and .xyz (x y z), beside ParaView's own readers of those
  extensions, and not for a CSV table with text columns, a note in .txt, a
  CSV of 5 unnamed numeric columns, an XYZ molecule file or an empty .txt;
- what pvpython's OpenDataFile picks (the first reader that can read the
  file, in the order of the proxies' XML names): CSVReader for .txt, .txt.gz
  and .csv (ParaView's GUI asks the user instead), OctorayParticleReader for
  a particle .xyz (before P3DReader and xyzreader);
- the reader reads the .txt: the LiDAR tile's 1065 points with Colors;
- the bundled LiDAR scan as .xyzrgbi (x y z r g b intensity, Data/README.md)
  opens with OpenDataFile, through the particle reader alone.
"""
import gzip
import os
import shutil
import sys

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

plugin, data, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
LoadPlugin(plugin, remote=False, ns=globals())
factory = servermanager.vtkSMProxyManager.GetProxyManager().GetReaderFactory()
session = servermanager.ActiveConnection.Session

failures = []


def check(what, got, expected):
    print(f"{what}: {got} (expected {expected})")
    if got != expected:
        failures.append(what)


def readers_for(path):
    found = factory.GetReaders(path, session)
    return [found.GetString(i) for i in range(1, found.GetLength(), 3)]


def write(name, text):
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write(text)
    return path


thesis = os.path.join(data, "Particles", "lidar_simple.particles")
with open(thesis) as f:
    lines = f.read().splitlines()
rows = [line.split() for line in lines if line and not line.startswith("#")]
txt = os.path.join(work, "lidar_simple.txt")
shutil.copyfile(thesis, txt)
txtgz = os.path.join(work, "lidar_simple.txt.gz")
with open(thesis, "rb") as src, gzip.open(txtgz, "wb") as dst:
    dst.write(src.read())
files = {
    # name: (path, particle text?)
    "thesis .txt": (txt, True),
    "thesis .txt.gz": (txtgz, True),
    "thesis .csv with a header": (write("lidar_simple.csv", "x,y,z,r,g,b,reflectivity,refraction\n" +
                                        "".join(",".join(r) + "\n" for r in rows)), True),
    "x y z .xyz": (write("lidar_simple.xyz", "".join(" ".join(r[:3]) + "\n" for r in rows)), True),
    "CSV table with text columns": (write("table.csv", "name,value,unit\nfoo,1,m\nbar,2,s\n"), False),
    "note in .txt": (write("note.txt", "hello world\nthis is a note\n"), False),
    "5 unnamed numeric columns .csv": (write("five.csv", "1,2,3,4,5\n6,7,8,9,10\n"), False),
    "XYZ molecule file": (write("water.xyz", "3\nwater\nO 0.0 0.0 0.0\nH 0.757 0.586 0.0\n"
                                             "H -0.757 0.586 0.0\n"), False),
    "empty .txt": (write("empty.txt", ""), False),
}
for what, (path, particles) in files.items():
    offered = readers_for(path)
    print(f"  {os.path.basename(path)}: {offered}")
    check(f"{what}: File > Open offers OctorayParticleReader",
          "OctorayParticleReader" in offered, particles)
# ParaView's own readers stay offered beside it.
check("thesis .txt: CSVReader offered too", "CSVReader" in readers_for(txt), True)
check("x y z .xyz: XYZ molecule reader offered too",
      "xyzreader" in readers_for(files["x y z .xyz"][0]), True)

# pvpython's choice.
check("OpenDataFile(.txt)", OpenDataFile(txt).GetXMLName(), "CSVReader")
check("OpenDataFile(.csv)", OpenDataFile(files["thesis .csv with a header"][0]).GetXMLName(),
      "CSVReader")
check("OpenDataFile(x y z .xyz)", OpenDataFile(files["x y z .xyz"][0]).GetXMLName(),
      "OctorayParticleReader")
# The factory matches every tail of the name's extensions (gz, txt.gz, txt),
# so the CSV reader claims .txt.gz as well, and comes first.
check("OpenDataFile(.txt.gz)", OpenDataFile(txtgz).GetXMLName(), "CSVReader")

# The particle reader on the .txt.
r = OctorayParticleReader(FileNames=[txt])
r.UpdatePipeline()
check(".txt read: points", r.GetDataInformation().GetNumberOfPoints(), 1065)
check(".txt read: Colors", "Colors" in r.PointData.keys(), True)

# The bundled scan's own extension, which no ParaView reader claims.
scan = os.path.join(data, "PointClouds", "simple_las.xyzrgbi")
check(".xyzrgbi: File > Open offers", readers_for(scan), ["OctorayParticleReader"])
opened = OpenDataFile(scan)
check("OpenDataFile(.xyzrgbi)", opened.GetXMLName() if opened else None, "OctorayParticleReader")
if opened:
    opened.UpdatePipeline()
    check(".xyzrgbi read: points", opened.GetDataInformation().GetNumberOfPoints(), 1065)
    check(".xyzrgbi read: intensity", "intensity" in opened.PointData.keys(), True)

if failures:
    print("FAILED:", ", ".join(failures))
    sys.exit(1)
print("OK")
