"""Per-frame cost of the VTK layer beside the engine's own trace.

An offscreen 1920x1080 window orbits the camera around a cloud drawn by
vtkOctreeVolumeMapper; per frame the mapper reports the engine's trace and
its own steps (depth read-back, upload of the picture, composite draw), and
the whole vtkRenderWindow::Render is timed. Prints a table and merges JSON
records {name, backend, n, depth, seconds, peer, peer_seconds} into
bench-results.json.

    PYTHONPATH=build/lib/python3/dist-packages xvfb-run -a python3 \\
        Benchmarks/Python/bench_mapper.py --json build/bench-results.json
"""
import argparse
import os
import statistics
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support

import octoray

HERE = os.path.dirname(os.path.abspath(__file__))
# The JSON merge shared by the Python benchmarks.
sys.path.insert(0, os.path.join(HERE, "..", "Python"))
from bench_readers import merge  # noqa: E402
DATA = os.environ.get("OCTORAY_DATA", os.path.join(HERE, "..", "..", "Data"))


def lidar():
    r = octoray.vtkParticleReader()
    r.SetFileName(os.path.join(DATA, "Particles", "lidar_simple.particles"))
    r.SetOutputPointsPrecision(vtk.vtkAlgorithm.DOUBLE_PRECISION)
    r.Update()
    return r.GetOutput()


def sphere_field(n, seed=1):
    """n points on the surfaces of 48 spheres, with RGB colours."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1, 1, (48, 3))
    radii = rng.uniform(0.05, 0.2, 48)
    k = rng.integers(0, 48, n)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    xyz = (centres[k] + radii[k, None] * d).astype(np.float32)
    rgb = (rng.uniform(60, 255, (48, 3))[k]).astype(np.uint8)
    poly = vtk.vtkPolyData()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_support.numpy_to_vtk(xyz, deep=True))
    poly.SetPoints(pts)
    colors = numpy_support.numpy_to_vtk(rgb, deep=True)
    colors.SetName("Colors")
    poly.GetPointData().SetScalars(colors)
    return poly


def run(name, data, frames, size, backend):
    mapper = octoray.vtkCPUOctreeVolumeMapper() if backend == "cpu" else octoray.vtkOctreeVolumeMapper()
    mapper.SetInputData(data)
    prop = vtk.vtkVolumeProperty()
    prop.IndependentComponentsOff()
    prop.ShadeOn()
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    # An opaque actor, so that the depth read-back has something to read.
    sphere = vtk.vtkSphereSource()
    b = data.GetBounds()
    sphere.SetCenter((b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2)
    sphere.SetRadius(0.2 * max(b[1] - b[0], b[3] - b[2], b[5] - b[4]))
    actor = vtk.vtkActor()
    sm = vtk.vtkPolyDataMapper()
    sm.SetInputConnection(sphere.GetOutputPort())
    actor.SetMapper(sm)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    ren.AddActor(actor)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(*size)
    win.AddRenderer(ren)
    ren.ResetCamera()
    ren.GetActiveCamera().Elevation(30)
    win.Render()  # build and warm up
    build = mapper.GetLastBuildSeconds()
    steps = {"frame": [], "trace": [], "depth read": [], "upload": [], "draw": []}
    for _ in range(frames):
        ren.GetActiveCamera().Azimuth(360.0 / frames)
        t0 = time.perf_counter()
        win.Render()
        win.WaitForCompletion()
        steps["frame"].append(time.perf_counter() - t0)
        steps["trace"].append(mapper.GetLastTraceSeconds())
        steps["depth read"].append(mapper.GetLastDepthReadSeconds())
        steps["upload"].append(mapper.GetLastUploadSeconds())
        steps["draw"].append(mapper.GetLastDrawSeconds())
    med = {k: statistics.median(v) for k, v in steps.items()}
    layer = med["depth read"] + med["upload"] + med["draw"]
    print("%s: %d points, backend %s, build %.1f ms, %dx%d, median of %d orbiting frames" % (
        name, data.GetNumberOfPoints(), mapper.GetBackendDescription(), build * 1e3, size[0], size[1], frames))
    print("| step | ms / frame |\n| --- | ---: |")
    for k in ("trace", "depth read", "upload", "draw", "frame"):
        print("| %s | %.2f |" % (k if k != "frame" else "whole Render()", med[k] * 1e3))
    print("VTK layer (depth read + upload + draw) = %.2f ms = %.1f%% of the engine's trace; %.2f frames/s\n" % (
        layer * 1e3, 100 * layer / med["trace"], 1 / med["frame"]))
    n = data.GetNumberOfPoints()
    backend_name = mapper.GetLastUsedBackendName()
    return [
        dict(name="mapper vtk layer %dx%d/%s" % (size[0], size[1], name), backend=backend_name, n=n, depth=0,
             seconds=layer, peer="engine trace", peer_seconds=med["trace"]),
        dict(name="mapper frame %dx%d/%s" % (size[0], size[1], name), backend=backend_name, n=n, depth=0,
             seconds=med["frame"], peer="", peer_seconds=0.0),
    ]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--json", default="bench-results.json")
    p.add_argument("--frames", type=int, default=10)
    p.add_argument("--size", default="1920x1080")
    p.add_argument("--backend", default="auto", choices=["auto", "cpu"])
    p.add_argument("--points", type=int, default=1000000)
    args = p.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    records = run("lidar", lidar(), args.frames, size, args.backend)
    records += run("spheres", sphere_field(args.points), args.frames, size, args.backend)
    merge(args.json, records)
    print("%d records merged into %s" % (len(records), args.json))
    return 0


if __name__ == "__main__":
    sys.exit(main())
