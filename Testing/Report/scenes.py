#!/usr/bin/python3
"""Scenes the report's sections share, written once under build/report/scenes/.

    ct_particles(ctx)  the bundled CT stack (Data/DICOM/CT5N) as a particle
                       file: vtkSliceStackReader keeps the voxels above -500 HU
                       (tissue and bone; air is background) as points in
                       millimetres with their HU as scalar, and
                       vtkParticleTextWriter writes them as `x y z scalar`
                       lines, which the engine-only programs read with
                       Rendering/Engine/Tools/PointFile.h.

Run as a script it writes one scene (what ct_particles runs, so the command is
in the report's log):

    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 Testing/Report/scenes.py ct OUT.particles
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CT_SERIES = os.path.join(ROOT, "Data", "DICOM", "CT5N")
CT_BACKGROUND_HU = (-10000, -500)  # air and below is background, as in test_slice_stack_reader.py


def python_env(ctx):
    """The environment that finds the build tree's `octoray` package."""
    return {"PYTHONPATH": os.path.join(ctx.build, "lib", "python3", "dist-packages"),
            "VTK_LOGGING_LEVEL": "ERROR"}


def ct_particles(ctx):
    """Path of the CT stack as a particle file; written if missing."""
    path = ctx.work_path("scenes", "ct5n.particles")
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        ctx.run("scene-ct5n", ["/usr/bin/python3", os.path.abspath(__file__), "ct", path], env=python_env(ctx))
    return path


def write_ct(out):
    import octoray  # noqa: F401  (the build tree's package, on PYTHONPATH)
    reader = octoray.vtkSliceStackReader()
    reader.SetDirectoryName(CT_SERIES)
    reader.SetBackgroundRange(*CT_BACKGROUND_HU)
    reader.Update()
    points = reader.GetOutput()
    if points.GetNumberOfPoints() == 0:
        raise SystemExit("scenes.py: no CT voxel above the background")
    writer = octoray.vtkParticleTextWriter()
    writer.SetInputData(points)
    writer.SetWriteAllArrays(False)  # x y z [scalar]: the columns PointFile.h reads
    writer.SetFileName(out + ".part")
    if not writer.Write():
        raise SystemExit("scenes.py: could not write " + out)
    os.replace(out + ".part", out)
    print("%s: %d points from %d slices" % (out, points.GetNumberOfPoints(), reader.GetNumberOfSlices()))


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] != "ct":
        raise SystemExit(__doc__)
    write_ct(sys.argv[2])
