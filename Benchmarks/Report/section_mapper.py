"""The CUDA mapper inside VTK windows on the GPU (issue 13): the mapper tests
on both backends, compute-sanitizer over the CUDA ones, and the orbit against
VTK's own GPU mappers.

Nothing is measured here: the files come from scripts/gpu/gpu-check.sh on a
GPU machine (VTK with EGL on the NVIDIA driver), committed in
Benchmarks/gpu/ with COMMAND.md."""
import os
import re
import xml.etree.ElementTree as ET

from make_report import Section, gpu_summaries, gpu_summary_link

TITLE = "The CUDA mapper in VTK windows (from the GPU run)"

# The mapper tests run three ways; the prefix of a CTest name says which.
VARIANTS = [
    ("CUDA-host-", "CUDA, picture through host memory (the fallback)"),
    ("CUDA-", "CUDA, picture to OpenGL device to device (the default)"),
    ("", "CPU backend (the reference), OpenGL on the NVIDIA driver through EGL"),
]
METHODS = {
    "octoray": "octoray (CUDA, interop)",
    "octoray-host": "octoray (CUDA, host path)",
    "pointgauss": "vtkPointGaussianMapper",
    "points": "vtkPolyDataMapper points",
}


def produce(ctx):
    pass  # measured on the GPU machine only


def mapper_test_counts(path):
    """{variant label: (passed, failed, skipped, total, [failed names])} from CTest's JUnit file."""
    counts = {label: [0, 0, 0, 0, []] for _, label in VARIANTS}
    for case in ET.parse(path).getroot().iter("testcase"):
        name = case.get("name", "").split("Cxx-", 1)[-1]
        label = next(l for prefix, l in VARIANTS if name.startswith(prefix))
        status = case.get("status")
        c = counts[label]
        c[3] += 1
        if status == "run":
            c[0] += 1
        elif status == "notrun" or case.find("skipped") is not None:
            c[2] += 1
        else:
            c[1] += 1
            c[4].append(name)
    return counts


def method_title(method):
    if method.startswith("smart-"):
        return f"vtkPointInterpolator {method[6:]}³ + vtkSmartVolumeMapper"
    return METHODS.get(method, method)


def orbit_rows(records):
    """Rows per (scene, points, size, method), in the order of the run."""
    rows = []
    for r in records:
        _, scene, size, method = r["name"].split(" ", 3)
        rows.append(dict(scene=scene, n=r["n"], size=size, method=method, median=r["seconds"],
                         p95=r["p95_frame_s"], first=r["first_picture_s"], prepare=r["prepare_s"],
                         frames=int(r["frames"]), gpu=r["gpu_bytes"], trace=r.get("trace_s"),
                         depth=r.get("depth_read_s"), transfer=r.get("transfer_s"), draw=r.get("draw_s")))
    return rows


def ratios(rows):
    """Per (scene, n, size): octoray's median frame, the fastest VTK frame and
    its method, the ratio; octoray's first picture against the fastest
    vtkSmartVolumeMapper first picture."""
    groups = {}
    for r in rows:
        groups.setdefault((r["scene"], r["n"], r["size"]), []).append(r)
    out = []
    for key, group in groups.items():
        ours = next((r for r in group if r["method"] == "octoray"), None)
        peers = [r for r in group if not r["method"].startswith("octoray")]
        smart = [r for r in peers if r["method"].startswith("smart-")]
        if not ours or not peers:
            continue
        fastest = min(peers, key=lambda r: r["median"])
        first = min(smart, key=lambda r: r["first"]) if smart else None
        out.append((key, ours, fastest, first))
    return out


def ms(seconds):
    return "–" if seconds is None else f"{1e3 * seconds:.2f}"


def render(ctx):
    summary_path = ctx.gpu_file("summary.txt")
    xml = ctx.gpu_file("mapper-tests.xml")
    orbit = ctx.gpu_file("orbit.json")
    if not (summary_path and xml):
        return Section("Not run on a GPU yet: `scripts/gpu/gpu-check.sh OUTDIR` on a GPU machine writes the "
                       "files this section reads.")
    device = open(ctx.gpu_file("gpu.txt")).read().strip() if ctx.gpu_file("gpu.txt") else "the GPU machine"
    counts = mapper_test_counts(xml)
    test_rows = [(label, f"{c[0]} passed, {c[1]} failed, {c[2]} skipped of {c[3]}"
                  + (f" (failed: {', '.join(c[4])})" if c[4] else "")) for label, c in counts.items()]
    for name, text in gpu_summaries(os.path.dirname(summary_path)):
        memcheck = re.search(r"^memcheck-mapper:\s+(\d+) =+ ERROR SUMMARY: (.*)$", text, re.M)
        if memcheck:
            test_rows.append(("compute-sanitizer memcheck over every CUDA mapper test",
                              f"{memcheck.group(1)} runs, each: {memcheck.group(2)}"
                              + gpu_summary_link(name)))
            break
    text = [
        f"Device: {device}. Command: `{ctx.gpu_command() or 'scripts/gpu/gpu-check.sh OUTDIR'}` "
        "(it builds VTK 9.2 with EGL from ParaView 5.11's sources, or unpacks the build "
        "`scripts/gpu/fetch-vtk.sh --prebuilt` made here, then the whole project with CUDA against it).",
        "",
        "The mapper tests (Rendering/Volume/Testing/Cxx) run in offscreen EGL windows on the NVIDIA "
        "driver, each on the CPU backend and on the CUDA backend, against the same baselines and "
        "tolerances; each CUDA test asserts that CUDA drew the picture and that it took the path asked "
        "for. Among them: the octree and an OpenGL sphere hiding each other (with and without 8× "
        "multisampling), an animation equal to rebuilds frame by frame, the fall back to the CPU after a "
        "CUDA failure in mid-session, two windows, a 4096² window, ImageSampleDistance 2 against the "
        "half-size picture, and a window resized between frames.",
        "",
        ctx.table(["mapper tests", "result"], test_rows, "ll"),
    ]
    summary_rows = [(f"mapper tests in VTK windows on {device.split(',')[0]}",
                     "; ".join(f"{c[0]}/{c[3]}" for c in counts.values()), "CPU and CUDA backends",
                     f"{sum(c[1] for c in counts.values())} failed")]
    if orbit:
        text += orbit_text(ctx, orbit_rows(ctx.load_json(orbit)), summary_rows)
    return Section("\n".join(text), summary_rows)


# The orbit runs in a call of its own (COMMAND.md).
ORBIT_SUMMARY = "summary-orbit.txt"


def orbit_text(ctx, rows, summary_rows):
    table = [(r["scene"], f"{r['n']:,}", r["size"], method_title(r["method"]), ms(r["median"]), ms(r["p95"]),
              r["frames"], ms(r["first"]), ms(r["prepare"]) if r["prepare"] else "–", f"{r['gpu'] / 1e6:.0f}")
             for r in rows]
    link = ctx.write_csv("mapper-orbit", ["scene", "points", "size", "method", "median_ms", "p95_ms", "frames",
                                          "first_picture_ms", "prepare_ms", "gpu_mb"], table)
    where = [(r["scene"], f"{r['n']:,}", r["size"], method_title(r["method"]), ms(r["trace"]), ms(r["depth"]),
              ms(r["transfer"]), ms(r["draw"]), ms(r["median"])) for r in rows if r["trace"] is not None]
    ratio_rows = []
    for (scene, n, size), ours, fastest, first in ratios(rows):
        ratio_rows.append((scene, f"{n:,}", size, ms(ours["median"]), f"{method_title(fastest['method'])} "
                           f"{ms(fastest['median'])}", f"{fastest['median'] / ours['median']:.1f}×",
                           f"{ours['first'] / first['first']:.3f}" if first else "not run"))
    big = [(key, ours, fastest) for key, ours, fastest, _ in ratios(rows) if key[2] == "3840x2160"]
    if big:
        key, ours, fastest = max(big, key=lambda t: t[0][1])
        summary_rows.append((f"orbit frame, {key[1]:,} points, 3840×2160, CUDA mapper in a VTK window (GPU run)",
                             f"{ms(ours['median'])} ms", f"{method_title(fastest['method'])} {ms(fastest['median'])} ms",
                             f"{fastest['median'] / ours['median']:.1f}× faster"))
    return [
        "",
        "**Orbit against VTK's GPU mappers** (`octoray_bench_orbit`, Benchmarks/Orbit): the same points, "
        "the same camera orbit (the frame count and time limit are in the command; a method whose frame is "
        "slow draws fewer frames, at least 3) and the same offscreen window, each frame ended by glFinish. "
        "Scenes: 64 Gaussian clusters (fixed seed) coloured by position, and the largest real cloud in "
        "Data/, the LMS400 laser scan of a table (`make data`; 460,400 points, coloured by intensity "
        "between its 1st and 99th percentiles). octoray and vtkPointGaussianMapper are lit, the points "
        "and the resampled volumes are not. A resampling estimated to take longer than `--max-prepare` "
        "is skipped, and says so. First picture: from points in memory to the first frame (octree "
        "build, or resampling onto an image, plus the first render); making the points is not counted. "
        "GPU memory: what the device's use grew by (cudaMemGetInfo: CUDA and OpenGL together). "
        f"From a call of its own ({ctx.gpu_call(ORBIT_SUMMARY) or 'gpu/COMMAND.md'}), not the tests' call "
        f"above. Table as CSV: [{link}]({link}).",
        "",
        ctx.table(["scene", "points", "window", "method", "median frame ms", "p95 ms", "frames",
                   "first picture ms", "of which resampling ms", "GPU MB"], table, "lrlrrrrrrr"),
        "",
        "The issue's ratios (octoray's median frame against the fastest VTK path in the same window; "
        "octoray's first picture as a fraction of vtkSmartVolumeMapper's, resampling included):",
        "",
        ctx.table(["scene", "points", "window", "octoray ms", "fastest VTK path ms", "frames faster",
                   "first picture / vtkSmartVolumeMapper's"], ratio_rows, "lrlrrrr"),
        "",
        "Where octoray's frame goes (medians over the orbit; the rest of the frame is VTK's own: clearing, "
        "the render passes, glFinish):",
        "",
        ctx.table(["scene", "points", "window", "path", "trace ms", "depth read ms", "picture to OpenGL ms",
                   "composite draw ms", "frame ms"], where, "llllrrrrr"),
    ]
