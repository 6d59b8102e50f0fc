"""Readers: octoray's particle text and slice-stack readers against what a
VTK or Python user reaches for today, same files, same run."""
import os

from make_report import Section
from section_build import fresh, load_records, machine_text, record_machine, count
import scenes

TITLE = "Readers"

# The documented full run (ctest bench.readers, `make bench`) reads a 1 GiB
# particle file; the report reads a smaller one so the section fits its time
# budget. Throughput (MB/s) is what is compared, and it does not depend on
# the file's size once the file is well past the page size and the thread
# start-up (tens of MB).
PARTICLE_MB = 128
VTK_MB = 16          # vtkDelimitedTextReader runs at a few MB/s: a prefix of the same file
SLICES, SLICE_SIZE = 100, 512
REPEATS = 3


def produce(ctx):
    record_machine(ctx, "readers", "start")
    ctx.run("readers", ["/usr/bin/python3", os.path.join(ctx.root, "Benchmarks", "Python", "bench_readers.py"),
                        "--json", fresh(ctx.work_path("readers.json")), "--workdir", ctx.work_path("readers"),
                        "--mb", PARTICLE_MB, "--vtk-mb", VTK_MB, "--slices", SLICES, "--size", SLICE_SIZE,
                        "--repeats", REPEATS], env=scenes.python_env(ctx))
    record_machine(ctx, "readers", "end")


def _who(backend):
    names = {
        "octoray-1thread": "octoray vtkParticleReader, 1 thread",
        "vtkDelimitedTextReader+vtkTableToPolyData": "vtkDelimitedTextReader + vtkTableToPolyData",
        "octoray-vtkSliceStackReader": "octoray vtkSliceStackReader",
        "vtkPNGReader+vtkThreshold": "vtkPNGReader + vtkThreshold",
        "vtkPNGReader+vtkThresholdPoints": "vtkPNGReader + vtkThresholdPoints",
        "pandas-pyarrow": "pandas read_csv (pyarrow engine)",
    }
    if backend in names:
        return names[backend]
    if backend.startswith("octoray-") and backend.endswith("threads"):
        return "octoray vtkParticleReader, %s threads" % backend[len("octoray-"):-len("threads")]
    if backend.startswith("pandas-") and backend.endswith("-c"):
        return "pandas %s read_csv (C engine)" % backend.split("-")[1]
    return backend


def render(ctx):
    records = load_records(ctx.work_path("readers.json"))
    text_rows, slice_rows, csv_rows, plot = [], [], [], []
    summary = []
    octo = next((r for r in records if r["name"] == "reader/particle_text" and r["backend"].endswith("threads")
                 and r["backend"].startswith("octoray-")), None)
    for r in records:
        if r["name"] == "reader/particle_text":
            if r.get("mb_per_s") is None:
                text_rows.append([_who(r["backend"]) + ": not measured, " + r.get("note", ""), "–", "–", "–", "–",
                                  "–", "–"])
                continue
            speedup = octo["mb_per_s"] / r["mb_per_s"] if octo else None
            text_rows.append([_who(r["backend"]), "%.0f" % (r["bytes"] / 1e6), count(r["n"]),
                              "%.2f s" % r["seconds"], "%d" % r.get("runs", 1), "%.1f" % r["mb_per_s"],
                              ("%.1f×" % speedup) if r is not octo else "–"])
            plot.append((_who(r["backend"]), r["mb_per_s"]))
            csv_rows.append([r["name"], r["backend"], r["n"], r["bytes"], r["seconds"], r.get("min_seconds"),
                             r.get("runs"), r["mb_per_s"]])
            if r["backend"].startswith("pandas-") and r["backend"].endswith("-c") and octo:
                summary.append(("particle text reader (%s threads)" % octo["backend"][8:-7],
                                "%.0f MB/s" % octo["mb_per_s"], "pandas read_csv %.0f MB/s" % r["mb_per_s"],
                                "%.1f×" % speedup))
        elif r["name"] == "reader/slice_stack":
            slice_rows.append([_who(r["backend"]), count(r["voxels"]), count(r["n"]), "%.3f s" % r["seconds"],
                               "%d" % r.get("runs", 1),
                               ("%.1f×" % r["octoray_speedup"]) if "octoray_speedup" in r else "–"])
            csv_rows.append([r["name"], r["backend"], r["n"], r.get("voxels"), r["seconds"], r.get("min_seconds"),
                             r.get("runs"), ""])
    csv = ctx.write_csv("readers", ["benchmark", "reader", "points_or_cells", "bytes_or_voxels", "median_s", "min_s",
                                    "runs", "mb_per_s"], csv_rows)
    png, link = ctx.figure_path("readers")
    if plot:
        _plot(png, plot)
    text = """
{machine}

Command (the report's sizes; `make bench` runs the same script as ctest `bench.readers` on a 1 GiB particle file, a
64 MB prefix for VTK and 200 slices of 512²):

    {cmd}

**Particle text.** A generated file in the thesis format (`x y z r g b reflectivity refraction`, {mb} MB, blocks of
distinct random lines in random order), in the page cache before every reader. octoray's vtkParticleReader
(multi-threaded parser, all cores and one), pandas `read_csv` (C engine; the pyarrow engine where pyarrow is
importable) and vtkDelimitedTextReader + vtkTableToPolyData, what a VTK user has for such a file. VTK's reader runs
at a few MB/s, so it reads the first {vtk_mb} MB of the same file (header line dropped: VTK 9.2's reader has no
comment character) and throughputs are compared. Time: median of {repeats} runs for octoray on all threads, 1 run for
the others, octoray's one-thread run among them (seconds each). Speed-up = octoray (all threads) MB/s / the reader's MB/s.

{text_table}

**Slice stack.** A generated 16-bit PNG stack ({slices} slices of {size}², a noisy ball in a zero background, like a
CT phantom) to points above the background: octoray's vtkSliceStackReader (OpenImageIO, threshold while reading)
against vtkPNGReader + vtkThreshold (what a VTK user does today: voxels as hexahedral cells of an unstructured grid)
and vtkPNGReader + vtkThresholdPoints (the point-wise equivalent). Median of {repeats}. Speed-up = the pipeline's
time / octoray's.

{slice_table}

[CSV]({csv}) · ![reader throughput]({link})
""".format(machine=machine_text(ctx, "readers"), cmd=scenes.with_python_path(ctx.command("readers")), mb=PARTICLE_MB, vtk_mb=VTK_MB,
           repeats=REPEATS, slices=SLICES, size=SLICE_SIZE, csv=csv, link=link,
           text_table=ctx.table(["reader", "MB read", "points", "time", "runs", "MB/s", "octoray speed-up"],
                                text_rows, "lrrrrrr") if text_rows else "No particle-text records.",
           slice_table=ctx.table(["pipeline", "voxels", "points / cells out", "time", "runs", "octoray speed-up"],
                                 slice_rows, "lrrrrr") if slice_rows else "No slice-stack records.")
    return Section(text, summary)


def _plot(png, plot):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 1.2 + 0.45 * len(plot)))
    names = [p[0] for p in plot]
    ax.barh(range(len(plot)), [p[1] for p in plot], color=["#1f77b4" if n.startswith("octoray") else "#999999"
                                                            for n in names])
    ax.set_yticks(range(len(plot)))
    ax.set_yticklabels(names, fontsize=8)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("MB/s (log)")
    ax.set_title("Particle text file to points, same file, same run")
    ax.grid(axis="x", which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
