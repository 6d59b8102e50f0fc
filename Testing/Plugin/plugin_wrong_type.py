""""Octree Volume" on data it cannot draw says so, once.

usage: plugin_wrong_type.py LAUNCHER... -- PLUGIN DATA_DIR WORK_DIR

Runs this file again as the ParaView script under LAUNCHER (e.g. `pvbatch`
or `mpiexec -np 2 pvbatch`), collects what it prints (stdout and stderr,
where ParaView's output window writes), and checks the warnings of
vtkOctreeVolumeRepresentation:

- a vtkMultiBlockDataSet (Group Datasets of the Wavelet image and a
  sphere) shown as "Octree Volume", then rendered five times with camera and
  property changes (the blend mode makes the representation run its
  RequestData again): the warning naming vtkMultiBlockDataSet and the image
  block exactly once;
- a vtkTable (ParaView's CSV reader on a particle file named .csv) given to
  the representation directly, rendered three times: the warning naming
  vtkTable, with the Table To Points hint, exactly once;
- in both, what the representation can draw (vtkPointSet, vtkImageData);
- a Group Datasets of two particle files, one with a column "extra" that
  the other lacks, rendered three times: drawn, with the warning that
  "extra" is not in every block, so not drawn, exactly once (on several
  ranks, the blocks are read on the first);
- on several ranks, still one of each (the first rank speaks for all), and
  no warning about blending the ranks' pictures in order for data that is
  not drawn (the multiblock's composite blend mode);
- no pipeline error about the representation's input ("Can not execute
  simple algorithm ... without output ports", which ParaView printed for
  composite data before), and the script ran to its end.
"""
import os
import subprocess
import sys

DRAWS = ("it draws point sets (vtkPointSet: vtkPolyData, vtkUnstructuredGrid, vtkStructuredGrid, "
         "...), images (vtkImageData) and composite data of point sets; nothing is drawn.")
MULTIBLOCK = ("Octree Volume cannot draw a vtkMultiBlockDataSet holding a vtkImageData: " + DRAWS +
              " To draw this data, apply Merge Blocks first to make one unstructured grid of its "
              "blocks.")
DROPPED = ("Octree Volume draws the blocks of this vtkMultiBlockDataSet as one point set with the point "
           "arrays every block has, as Merge Blocks makes it: 'extra' is not in every block, so not drawn.")
TABLE = ("Octree Volume cannot draw a vtkTable: " + DRAWS + " To draw this data, apply Table To "
         "Points first (or open a particle text file with the Octoray Particle Reader).")


def child(plugin, data, workdir):
    from paraview.simple import (LoadPlugin, GroupDatasets, Sphere, Wavelet, Show, Render,
                                 GetActiveViewOrCreate, CSVReader)
    from paraview import servermanager
    LoadPlugin(plugin, remote=False, ns=globals())
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = [200, 150]

    # An image among the blocks: composite data of point sets alone is drawn
    # (plugin_composite.py).
    group = GroupDatasets(Input=[Wavelet(), Sphere()])
    display = Show(group, view)
    display.SetRepresentationType("Octree Volume")
    for frame in range(5):
        view.GetActiveCamera().Azimuth(10)
        if frame == 3:
            display.OctreeBlendMode = "Composite"
        Render(view)
    display.Visibility = 0

    # Blocks of point sets whose arrays differ: drawn, the array that some
    # lack said once.
    readers = []
    for name, header in (("with_extra", "# x y z value extra"), ("without_extra", "# x y z value")):
        path = os.path.join(workdir, name + ".particles")
        with open(path, "w") as f:
            f.write(header + "\n")
            for i in range(20):
                f.write("%d 0 %d 1%s\n" % (i, len(readers), " 2" if "extra" in header else ""))
        readers.append(OctorayParticleReader(FileNames=[path]))
    blocks = GroupDatasets(Input=readers)
    display = Show(blocks, view)
    display.SetRepresentationType("Octree Volume")
    for _ in range(3):
        view.GetActiveCamera().Azimuth(10)
        Render(view)
    display.Visibility = 0

    # A particle file named .csv through ParaView's CSV reader: a vtkTable.
    csv = os.path.join(workdir, "particles.csv")
    with open(os.path.join(data, "Particles", "lidar_simple.particles")) as src, \
            open(csv, "w") as dst:
        dst.write("x,y,z,r,g,b,reflectivity,refraction\n")
        for line in src:
            if not line.startswith("#"):
                dst.write(",".join(line.split()) + "\n")
    table = CSVReader(FileName=[csv])
    table.UpdatePipeline()
    print("CSV reader output:", table.GetDataInformation().GetDataSetTypeAsString())
    rep = servermanager.rendering.OctreeVolumeRepresentation(Input=table)
    view.Representations.append(rep)
    for _ in range(3):
        view.GetActiveCamera().Elevation(5)
        Render(view)
    print("SCRIPT-END")


def main():
    argv = sys.argv[1:]
    split = argv.index("--")
    launcher, (plugin, data, workdir) = argv[:split], argv[split + 1:]
    workdir = os.path.abspath(workdir)
    os.makedirs(workdir, exist_ok=True)
    run = subprocess.run(launcher + [os.path.abspath(__file__), "--child", plugin, data, workdir],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         timeout=240)
    out = run.stdout
    print(out)
    failures = []

    def check(what, got, expected):
        print(f"{what}: {got} (expected {expected})")
        if got != expected:
            failures.append(what)

    check("exit status", run.returncode, 0)
    check("script ran to its end", "SCRIPT-END" in out, True)
    check("CSV reader gives a vtkTable", "CSV reader output: vtkTable" in out, True)
    check("warnings naming vtkMultiBlockDataSet", out.count(MULTIBLOCK), 1)
    check("warnings naming vtkTable", out.count(TABLE), 1)
    check("warnings naming the array some blocks lack", out.count(DROPPED), 1)
    check("'Octree Volume cannot draw' in all", out.count("Octree Volume cannot draw"), 2)
    check("blend-order warnings for data not drawn",
          out.count("blend each rank's picture without ordering") +
          out.count("ranks the points are redistributed into disjoint pieces"), 0)
    check("pipeline errors about the representation's input",
          out.count("Can not execute simple algorithm vtkOctreeVolumeRepresentation") +
          out.count("vtkOctreeVolumeRepresentation) is of type"), 0)
    if failures:
        print("FAILED:", ", ".join(failures))
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        # No sys.exit in pvbatch: it crashes ParaView 5.11's teardown (SIGSEGV
        # in vtkXOpenGLRenderWindow::MakeCurrent while the view is deleted).
        child(*sys.argv[2:5])
    else:
        sys.exit(main())
