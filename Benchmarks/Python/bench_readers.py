#!/usr/bin/python3
"""Reader benchmarks (ctest label bench): octoray's readers against VTK's own
and pandas, in one run, on the same cores.

1. Particle text: a generated file in the thesis format (default 1 GiB,
   OCTORAY_BENCH_MB) read by vtkParticleTextReader (all threads and one
   thread), pandas.read_csv (C engine, and the pyarrow engine when pyarrow is
   importable), and vtkDelimitedTextReader + vtkTableToPolyData. VTK's reader
   runs on the first OCTORAY_BENCH_VTK_MB (default 64) MB of the same file:
   at its ~2-3 MB/s the whole file would take minutes; throughputs (MB/s)
   are compared.
2. Slice stack: a generated 16-bit PNG stack read by vtkSliceStackReader, and
   by vtkPNGReader + vtkThreshold (and + vtkThresholdPoints, the point-wise
   equivalent).

Records are merged into bench-results.json (a list; a record replaces one with
the same name, backend and n).

    python3 bench_readers.py --json build/bench-results.json --workdir build/bench
"""
import argparse
import json
import os
import sys
import time

import numpy as np
import vtk
import octoray
from vtk.util.numpy_support import numpy_to_vtk


class Timing:
    def __init__(self, times):
        self.median = float(np.median(times))
        self.min = min(times)
        self.runs = len(times)

    def fields(self):
        return dict(seconds=self.median, min_seconds=self.min, runs=self.runs)


def timed(fn, repeats):
    """Runs fn `repeats` times: (Timing, result). Records give the median, not
    the best run: on a shared machine one lucky or unlucky run must not be the
    figure; the fastest is kept beside it."""
    times = []
    result = None
    for _ in range(repeats):
        t = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t)
    return Timing(times), result


def make_particle_file(path, target_bytes):
    """Thesis-format lines; blocks of distinct random lines in random order."""
    if os.path.exists(path) and os.path.getsize(path) >= target_bytes:
        return
    rng = np.random.default_rng(42)
    blocks = []
    for _ in range(8):
        n = 100000
        cols = np.column_stack([
            rng.uniform(-1000, 1000, (n, 3)), rng.integers(0, 256, (n, 3)),
            rng.uniform(0, 1, n), rng.choice([0, 1.33, 1.5], n)])
        text = "\n".join("%.4f %.4f %.4f %d %d %d %.3f %.2f" % tuple(r) for r in cols) + "\n"
        blocks.append(text.encode())
    written = 0
    with open(path + ".part", "wb") as f:
        f.write(b"# x y z r g b reflectivity refraction\n")
        while written < target_bytes:
            b = blocks[rng.integers(0, len(blocks))]
            f.write(b)
            written += len(b)
    os.replace(path + ".part", path)


def prefix_file(path, prefix_path, nbytes):
    with open(path, "rb") as f:
        data = f.read(nbytes)
    data = data[: data.rfind(b"\n") + 1]
    # vtkDelimitedTextReader (VTK 9.2) has no comment character: drop the header.
    if data.startswith(b"#"):
        data = data[data.find(b"\n") + 1:]
    with open(prefix_path, "wb") as f:
        f.write(data)
    return len(data)


def bench_particles(workdir, mb, vtk_mb, repeats):
    path = os.path.join(workdir, "particles_%dMB.txt" % mb)
    t = time.perf_counter()
    make_particle_file(path, mb << 20)
    size = os.path.getsize(path)
    print("particle file: %s, %.0f MB (generated in %.1f s)" % (path, size / 1e6, time.perf_counter() - t))
    # Warm the page cache so every reader starts from memory.
    with open(path, "rb") as f:
        while f.read(64 << 20):
            pass
    cores = os.cpu_count()
    records = []

    def octo(threads):
        r = octoray.vtkParticleReader()
        r.SetFileName(path)
        r.SetNumberOfThreads(threads)
        r.Update()
        return r.GetOutput().GetNumberOfPoints()

    t, n = timed(lambda: octo(0), repeats)
    records.append(dict(name="reader/particle_text", backend="octoray-%dthreads" % cores, n=n,
                        bytes=size, mb_per_s=size / 1e6 / t.median, **t.fields()))
    octo_all = records[-1]
    t1, _ = timed(lambda: octo(1), 1)
    records.append(dict(name="reader/particle_text", backend="octoray-1thread", n=n, bytes=size,
                        mb_per_s=size / 1e6 / t1.median, **t1.fields()))

    import pandas as pd

    def pandas_read(engine):
        # One header line; the pyarrow engine has no comment option.
        df = pd.read_csv(path, sep=" ", skiprows=1, header=None, engine=engine)
        return len(df)

    t, m = timed(lambda: pandas_read("c"), 1)
    assert m == n, (m, n)
    records.append(dict(name="reader/particle_text", backend="pandas-%s-c" % pd.__version__, n=n,
                        bytes=size, mb_per_s=size / 1e6 / t.median, **t.fields()))
    try:
        import pyarrow  # noqa: F401
        import pyarrow.csv as pacsv
        t, m = timed(lambda: pandas_read("pyarrow"), 1)
        assert m == n, (m, n)
        records.append(dict(name="reader/particle_text",
                            backend="pandas-%s-pyarrow-%s" % (pd.__version__, pyarrow.__version__),
                            n=n, bytes=size, mb_per_s=size / 1e6 / t.median, **t.fields()))

        def arrow_read():
            return pacsv.read_csv(path, read_options=pacsv.ReadOptions(
                skip_rows=1, autogenerate_column_names=True),
                parse_options=pacsv.ParseOptions(delimiter=" ")).num_rows

        t, m = timed(arrow_read, repeats)
        assert m == n, (m, n)
        records.append(dict(name="reader/particle_text",
                            backend="pyarrow-%s-csv" % pyarrow.__version__,
                            n=n, bytes=size, mb_per_s=size / 1e6 / t.median, **t.fields()))
    except ImportError:
        records.append(dict(name="reader/particle_text", backend="pandas-pyarrow", n=n,
                            bytes=size, seconds=None, mb_per_s=None,
                            note="pyarrow is not importable (Debian 12 does not package it)"))

    prefix = os.path.join(workdir, "particles_prefix.txt")
    psize = prefix_file(path, prefix, vtk_mb << 20)

    def vtk_read():
        r = vtk.vtkDelimitedTextReader()
        r.SetFileName(prefix)
        r.SetFieldDelimiterCharacters(" ")
        r.SetHaveHeaders(False)
        r.SetDetectNumericColumns(True)
        r.SetMergeConsecutiveDelimiters(True)
        t2p = vtk.vtkTableToPolyData()
        t2p.SetInputConnection(r.GetOutputPort())
        t2p.SetXColumn("Field 0")
        t2p.SetYColumn("Field 1")
        t2p.SetZColumn("Field 2")
        t2p.Update()
        return t2p.GetOutput().GetNumberOfPoints()

    t, m = timed(vtk_read, 1)
    records.append(dict(name="reader/particle_text",
                        backend="vtkDelimitedTextReader+vtkTableToPolyData", n=m, bytes=psize,
                        mb_per_s=psize / 1e6 / t.median, **t.fields(),
                        note="first %d MB of the same file" % vtk_mb))
    for r in records:
        if r is not octo_all and r.get("mb_per_s"):
            r["peer"] = octo_all["backend"]
            r["peer_mb_per_s"] = octo_all["mb_per_s"]
            r["octoray_speedup"] = octo_all["mb_per_s"] / r["mb_per_s"]
    return records


def bench_slices(workdir, slices, size, repeats):
    folder = os.path.join(workdir, "stack_%d_%d" % (slices, size))
    pattern = os.path.join(folder, "slice_%04d.png")
    if not os.path.exists(pattern % (slices - 1)):
        os.makedirs(folder, exist_ok=True)
        rng = np.random.default_rng(1)
        yy, xx = np.mgrid[0:size, 0:size]
        for k in range(slices):
            # A noisy ball in a zero background: a CT-like phantom.
            r2 = (xx - size / 2) ** 2 + (yy - size / 2) ** 2 + ((k - slices / 2) * size / slices) ** 2
            img = np.where(r2 < (0.4 * size) ** 2, 1000 + rng.integers(0, 3000, (size, size)), 0)
            im = vtk.vtkImageData()
            im.SetDimensions(size, size, 1)
            im.GetPointData().SetScalars(numpy_to_vtk(img.astype(np.uint16).ravel(), deep=1))
            w = vtk.vtkPNGWriter()
            w.SetInputData(im)
            w.SetFileName(pattern % k)
            w.Write()
    files = [pattern % k for k in range(slices)]
    records = []

    def octo():
        r = octoray.vtkSliceStackReader()
        r.SetFilePattern(pattern)
        r.SetFileNameRange(0, slices - 1)
        r.GradientNormalsOff()  # as the peers: points and values, no normals
        r.Update()
        return r.GetOutput().GetNumberOfPoints()

    t, n = timed(octo, repeats)
    octo_rec = dict(name="reader/slice_stack", backend="octoray-vtkSliceStackReader", n=n,
                    voxels=slices * size * size, **t.fields())
    records.append(octo_rec)

    # The names and the reader must outlive the pipeline's Update: with only
    # the connection holding it, VTK 9.2 crashes in vtkPNGReader here.
    names = vtk.vtkStringArray()
    for f in files:
        names.InsertNextValue(f)

    def png_reader():
        r = vtk.vtkPNGReader()
        r.SetFileNames(names)
        return r

    def vtk_threshold():
        t = vtk.vtkThreshold()
        reader = png_reader()
        t.SetInputConnection(reader.GetOutputPort())
        t.SetInputArrayToProcess(0, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, "PNGImage")
        t.SetLowerThreshold(1)
        t.SetUpperThreshold(65535)
        t.SetThresholdFunction(vtk.vtkThreshold.THRESHOLD_BETWEEN)
        t.Update()
        return t.GetOutput().GetNumberOfCells()

    def vtk_threshold_points():
        t = vtk.vtkThresholdPoints()
        reader = png_reader()
        t.SetInputConnection(reader.GetOutputPort())
        t.SetInputArrayToProcess(0, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, "PNGImage")
        t.ThresholdByUpper(1)
        t.Update()
        return t.GetOutput().GetNumberOfPoints()

    for label, fn in (("vtkPNGReader+vtkThreshold", vtk_threshold),
                      ("vtkPNGReader+vtkThresholdPoints", vtk_threshold_points)):
        t, m = timed(fn, repeats)
        records.append(dict(name="reader/slice_stack", backend=label, n=m,
                            voxels=slices * size * size,
                            peer=octo_rec["backend"], peer_seconds=octo_rec["seconds"],
                            octoray_speedup=t.median / octo_rec["seconds"], **t.fields()))
    return records


def merge(path, records):
    existing = []
    if path and os.path.exists(path):
        try:
            with open(path) as f:
                existing = json.load(f)
        except ValueError:
            existing = []
    key = lambda r: (r.get("name"), r.get("backend"), r.get("n"))  # noqa: E731
    new = {key(r) for r in records}
    merged = [r for r in existing if key(r) not in new] + records
    with open(path, "w") as f:
        f.write("[\n" + ",\n".join("  " + json.dumps(r) for r in merged) + "\n]\n")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--json", default="bench-results.json")
    p.add_argument("--workdir", default=".")
    p.add_argument("--mb", type=int, default=int(os.environ.get("OCTORAY_BENCH_MB", 1024)))
    p.add_argument("--vtk-mb", type=int, default=int(os.environ.get("OCTORAY_BENCH_VTK_MB", 64)))
    p.add_argument("--slices", type=int, default=200)
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    records = bench_particles(args.workdir, args.mb, args.vtk_mb, args.repeats)
    records += bench_slices(args.workdir, args.slices, args.size, args.repeats)
    for r in records:
        print(json.dumps(r))
    merge(args.json, records)
    print("%d records merged into %s" % (len(records), args.json))
    return 0


if __name__ == "__main__":
    sys.exit(main())
