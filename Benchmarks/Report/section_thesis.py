"""The 2015 thesis's table 2 and its two-sphere scene, with this engine's
figures beside them: CPU measured here, CUDA from the committed GPU run."""
import os

from make_report import Section
from section_build import (NOT_ON_GPU, count, fresh, gpu_records, gpu_source, load_records, machine_text,
                           record_machine, human_bytes)

TITLE = "The thesis's figures again"

REPEATS = 5
GPU_THESIS_FILE = "bench-thesis-cuda.json"  # octoray_bench_thesis --backend cuda on the GPU machine
NOT_IN_NOTES = "figure not in our notes"

# The thesis's table 2 (2015, GTX Titan), as our notes have it: one range for
# all five point counts, not a figure per row.
THESIS_BUILD = "0.02–6.1 s"
THESIS_TRACE = "24–45 ms"
THESIS_TRACE_FASTEST_S = 0.024
THESIS_MEMORY = "2.4–2.5 GB"


def produce(ctx):
    record_machine(ctx, "thesis", "start")
    ctx.run("thesis", [os.path.join(ctx.bin, "octoray_bench_thesis"), "--backend", "cpu", "--repeats", REPEATS,
                       "--json", fresh(ctx.work_path("thesis.json"))])
    record_machine(ctx, "thesis", "end")


def _get(records, name, n=None):
    for r in records or []:
        if r["name"] == name and (n is None or r["n"] == n):
            return r
    return None


def _ms(r):
    return ("%.2f ms" % (r["seconds"] * 1e3)) if r else None


def render(ctx):
    cpu = load_records(ctx.work_path("thesis.json"))
    gpu = gpu_records(ctx, GPU_THESIS_FILE)
    # Before octoray_bench_thesis ran on a GPU, octoray_bench_cuda timed the
    # same table 2 scenes (same generator, camera and settings); its records
    # have no memory figure.
    cuda_bench = gpu_records(ctx, "bench-results-cuda.json")
    legacy = {}
    for r in cuda_bench or []:
        if r["name"] == "thesis table 2 build":
            legacy.setdefault(r["n"], {})["build"] = r
        elif r["name"] == "thesis table 2 trace 800x600":
            legacy.setdefault(r["n"], {})["trace"] = r
    gpu_from = gpu_source(ctx, GPU_THESIS_FILE) if gpu else (
        gpu_source(ctx, "bench-results-cuda.json") + " (octoray_bench_cuda's table 2 rows)" if legacy else None)

    rows, csv_rows, plot = [], [], []
    slowest_gpu_trace = 0.0
    for build in (r for r in cpu if r["name"] == "thesis/table2/build"):
        n = build["n"]
        trace = _get(cpu, "thesis/table2/trace_800x600", n)
        gb = _get(gpu, "thesis/table2/build", n)
        gt = _get(gpu, "thesis/table2/trace_800x600", n)
        if gb is None and n in legacy:
            gb, gt = legacy[n].get("build"), legacy[n].get("trace")
        if gt:
            slowest_gpu_trace = max(slowest_gpu_trace, gt["seconds"])
        rows.append([count(n), _ms(build), _ms(trace), human_bytes(build["bytes"]),
                     _ms(gb) or NOT_ON_GPU, _ms(gt) or NOT_ON_GPU,
                     human_bytes(gb["bytes"]) if gb and "bytes" in gb else ("not recorded" if gb else NOT_ON_GPU)])
        csv_rows.append([n, build["seconds"], trace["seconds"] if trace else "", build["bytes"],
                         gb["seconds"] if gb else "", gt["seconds"] if gt else "",
                         gb.get("bytes", "") if gb else ""])
        plot.append((n, build["seconds"], trace["seconds"] if trace else None, gb["seconds"] if gb else None,
                     gt["seconds"] if gt else None))
    rows.append(["thesis (GTX Titan, 2015), all five", "–", "–", "–", THESIS_BUILD, THESIS_TRACE, THESIS_MEMORY])
    csv = ctx.write_csv("thesis-table2", ["points", "cpu_build_s", "cpu_trace_s", "cpu_bytes", "gpu_build_s",
                                          "gpu_trace_s", "gpu_bytes"], csv_rows)
    png, link = ctx.figure_path("thesis-table2")
    if plot:
        _plot(png, plot)

    spheres = [("build (whole call)", "thesis/two_spheres/build"),
               ("Phong, 800×600, per image", "thesis/two_spheres/phong_800x600"),
               ("Phong + shadows + 1 bounce, 800×600, per image", "thesis/two_spheres/shadows_bounce_800x600")]
    srows = []
    sbuild = _get(cpu, "thesis/two_spheres/build")
    for label, name in spheres:
        c, g = _get(cpu, name), _get(gpu, name)
        srows.append([label, NOT_IN_NOTES, NOT_IN_NOTES, _ms(c) or "–", _ms(g) or NOT_ON_GPU])
    if sbuild:
        srows.append(["engine memory", NOT_IN_NOTES, NOT_IN_NOTES, human_bytes(sbuild["bytes"]),
                      human_bytes(_get(gpu, "thesis/two_spheres/build")["bytes"]) if gpu and _get(
                          gpu, "thesis/two_spheres/build") else NOT_ON_GPU])

    summary = []
    if slowest_gpu_trace:
        summary.append(("thesis table 2: ray tracing 800×600 per image (GPU run)",
                        "≤ %.2f ms" % (slowest_gpu_trace * 1e3), "thesis %s (GTX Titan)" % THESIS_TRACE,
                        "≥ %.0f×" % (THESIS_TRACE_FASTEST_S / slowest_gpu_trace)))

    text = """
{machine}

Command (CPU rows):

    {cmd}

The thesis ("Motor de renderizado volumétrico con arquitectura en paralelo", UNAM, 2015) built its octree on a GTX
Titan with 32-bit Morton keys and a dense array of node pointers, and traced 800×600 rays. Its table 2: clouds like a
thresholded slice stack, point counts 30 641 to 3 283 639, depth 7, Phong; for all five sizes build 0.02–6.1 s
(almost all of it allocation), ray tracing 24–45 ms per image, memory 2.4–2.5 GB. Our notes keep those ranges, not
the figure of each row, so the thesis row gives the ranges (the project's design notes add
one: 1.94 s to build the 3.28 M-point cloud).

Ours: the same kind of scene from one generator shared by the CPU and CUDA programs
(`ThesisSliceStack` in Benchmarks/Engine/BenchScenes.h: grid points inside an ellipsoid with semi-axes 1, 0.8,
0.6, slice by slice, the first n kept, so the counts are the thesis's exactly), depth 7, 800×600, Phong with a
headlight, the fixed camera of the CUDA benchmark (`CubeCamera`). Build: whole `Engine::Build` call, median of
{repeats} after a warm-up on one engine (buffers reused, as the thesis rebuilt per frame). Trace:
`RenderStats.seconds`, the frame up to the picture in the backend's memory (on CUDA left on the device), median of
{repeats} after a warm-up frame. Memory: `Engine::Memory().Total()` (on the GPU: device memory). GPU columns: {gpu_from}.

{table}

[CSV]({csv}) · ![thesis table 2 again]({link})

The thesis's build time was allocation of the dense pointer skeleton (18 MB at depth 7, more than 1 GB past
depth 9); ours is the sort of the keys and the unique keys per level, linear in points, and memory is linear in
occupied nodes. The CPU rows are this 2-core machine's, beside a 2015 GPU: they show where the time goes, not a
like-for-like race.

**Two spheres.** The thesis also timed a scene of two spheres on the CPU and the GPU; those figures are not in our
notes, so the thesis columns say so rather than guess. Ours: `TwoSpheres` (BenchScenes.h), two solid spheres of radius
0.5 as grid points ({spheres_n} points), a red diffuse one and a grey mirror (reflectivity 0.6), depth 7, 800×600, the
same camera; Phong with the headlight, then Phong with one directional light, shadows and one bounce. Fresh engine;
times as above.

{spheres}
""".format(machine=machine_text(ctx, "thesis"), cmd=ctx.command("thesis"), repeats=REPEATS,
           gpu_from=gpu_from or (NOT_ON_GPU + "; on the GPU machine `build-gpu/bin/octoray_bench_thesis --backend cuda "
                                 "--json OUTDIR/%s` fills them" % GPU_THESIS_FILE),
           table=ctx.table(["points", "CPU build", "CPU trace / image", "CPU memory", "GPU build", "GPU trace / image",
                            "GPU memory"], rows),
           csv=csv, link=link, spheres_n=count(sbuild["n"]) if sbuild else "?",
           spheres=ctx.table(["two spheres, depth 7", "thesis CPU", "thesis GPU", "octoray CPU (here)",
                              "octoray CUDA (GPU run)"], srows, "lrrrr"))
    return Section(text, summary)


def _plot(png, plot):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.2))
    n = [p[0] for p in plot]
    ax.loglog(n, [p[1] for p in plot], "-o", color="#1f77b4", label="octoray CPU build")
    ax.loglog(n, [p[2] for p in plot], "--o", color="#1f77b4", label="octoray CPU trace / image")
    if any(p[3] for p in plot):
        ax.loglog(n, [p[3] for p in plot], "-s", color="#d62728", label="octoray CUDA build")
        ax.loglog(n, [p[4] for p in plot], "--s", color="#d62728", label="octoray CUDA trace / image")
    ax.axhspan(0.02, 6.1, color="#999999", alpha=0.15, label="thesis build, all five (0.02–6.1 s)")
    ax.axhspan(0.024, 0.045, color="#ff7f0e", alpha=0.3, label="thesis trace, all five (24–45 ms)")
    ax.set_xlabel("points")
    ax.set_ylabel("seconds (log)")
    ax.set_title("Thesis table 2 scenes: depth 7, 800×600, Phong")
    ax.legend(fontsize=7)
    ax.grid(which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
