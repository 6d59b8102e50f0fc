#!/usr/bin/python3
"""Scenes that the report's programs share, written from the bundled data by
the project's own VTK readers and writers (so the engine-only benchmarks,
which cannot link VTK, read them as particle files).

    Benchmarks/Report/scenes.py ct5n OUT.particles   # needs the build's octoray package on PYTHONPATH

From a section: `ct_particles(ctx)` writes build/report/scenes/ct5n.particles
once per report run and returns its path.
"""
import glob
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CT5N = os.path.join(ROOT, "Data", "DICOM", "CT5N")
# Air is below about -900 HU, fat about -100, soft tissue 20 to 80, bone
# above 300: everything above -500 is tissue (these five 16x16 slices hold
# fat and soft tissue, no bone).
CT_AIR_BELOW_HU = -500.0


def scenes_dir(ctx):
    return ctx.work_path("scenes")


def python_dir(build):
    """The build tree's `octoray` Python package folder."""
    for candidate in sorted(glob.glob(os.path.join(build, "lib", "python3*", "*-packages"))):
        if os.path.isdir(os.path.join(candidate, "octoray")):
            return candidate
    raise RuntimeError(f"no octoray Python package under {build}/lib (build the project first)")


def python_env(ctx):
    """The environment in which /usr/bin/python3 finds the build tree's `octoray` package."""
    return {"PYTHONPATH": python_dir(ctx.build), "VTK_LOGGING_LEVEL": "ERROR"}


def with_python_path(command):
    """A command run in python_env as RESULTS.md shows it, from the
    repository's root (make's build folder)."""
    return "PYTHONPATH=build/lib/python3/dist-packages " + command


def ct_particles(ctx):
    """build/report/scenes/ct5n.particles: the CT series as points (x y z
    HU), air removed. Written by this file run as a program, through
    ctx.run, so the report records the command."""
    out = os.path.join(scenes_dir(ctx), "ct5n.particles")
    if not os.path.exists(out) or "scene-ct5n" not in ctx.commands:
        ctx.run("scene-ct5n", [sys.executable, os.path.abspath(__file__), "ct5n", out], env=python_env(ctx))
    return out


def write_ct5n(out):
    import octoray
    reader = octoray.vtkSliceStackReader()
    reader.SetDirectoryName(CT5N)
    reader.SetBackgroundRange(-1e9, CT_AIR_BELOW_HU)  # intensity in this range: no particle
    # The scene is the voxels themselves (as RESULTS.md and the GPU run's
    # copy of this file have it), not the planes the reader fills between
    # slices by default.
    reader.SetFillBetweenSlices(False)
    reader.Update()
    if reader.GetErrorCode() or reader.GetOutput().GetNumberOfPoints() == 0:
        raise RuntimeError(f"{CT5N}: {reader.GetErrorMessage() or 'no points'}")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    writer = octoray.vtkParticleTextWriter()
    writer.SetInputData(reader.GetOutput())
    writer.SetFileName(out)
    writer.WriteAllArraysOff()  # x y z and the intensity (HU): what the engine's loader reads
    if writer.Write() != 1:
        raise RuntimeError(f"{out}: could not be written")
    print(f"{out}: {reader.GetOutput().GetNumberOfPoints()} points (HU > {CT_AIR_BELOW_HU:g}) "
          f"from {reader.GetNumberOfSlices()} slices of {CT5N}")


def main(argv):
    if len(argv) != 3 or argv[1] != "ct5n":
        print(__doc__, file=sys.stderr)
        return 2
    write_ct5n(argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
