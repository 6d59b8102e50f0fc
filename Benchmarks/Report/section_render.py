"""Render throughput per shading and blend mode (CPU here; CUDA from the GPU
run). Error against time per quality knob is the quality section's."""
import os
import re

from make_report import Section
from section_build import (NOT_ON_GPU, count, fresh, gpu_records, gpu_source, load_records, machine_text,
                           record_machine)

TITLE = "Render throughput"

# Small enough that the 20 (scene, mode) pairs with a warm-up and 5 timed
# frames each fit the section's budget on 2 cores; Mrays/s is per ray, so it
# compares with the GPU run's 1920x1080 figures.
SIZE = "960x540"
REPEATS = 5
GPU_RENDER_FILE = "bench-render-cuda.json"  # octoray_bench_render --backend cuda on the GPU machine

# The traversal's last change and its last try, each measured in its own
# calls beside the engine before it (Benchmarks/gpu/variants-mirror-table.txt,
# variants-paused-planes.txt).
TRAVERSAL_CHANGES = (
    "\n\nSince ae8927f the device reads a child mask with its octant bits flipped by the ray's direction signs "
    "(MirrorOctants) from a 2 kB table of every mask for each of the eight signs, where it swapped the bits: ncu's "
    "count of each machine instruction of the depth-16 frame had the traversal's loop at 228 warp instructions a "
    "step (216 since), near half of them on the integer pipe (its busiest, at 75 % of its peak), and the swaps at "
    "about 14 of them. Built beside the engine before it and run in turn, three rounds on one H100: primary rays "
    "at depth 10 2736–2809 Mrays/s against 2583–2634, at depth 16 1049–1071 against 991–1007 (issue 16's goal "
    "1,000), Phong with shadows and a bounce 1842–1892 against 1783–1809; in ncu the depth-16 frame took "
    "1.90–1.93 ms with 1477 M warp instructions against 2.04 ms and 1559 M "
    "([gpu/variants-mirror-table.txt](gpu/variants-mirror-table.txt), its summary lines by "
    "scripts/gpu/render-rates.py). Not kept: the comparisons of the children's test as PTX set masks (ptxas made "
    "each a compare and a select: 6 % slower), the swaps without branches, the first-children word read beside "
    "the masks, and the register caps of 5 and 7 blocks a multiprocessor (no faster). Nor a paused node's nine "
    "crossings and corner kept beside it on the stack, so that going back up reads them where it computes them "
    "again: the step fell to 184 warp instructions, but 48 more bytes a level for 768 threads a multiprocessor "
    "outgrew the L1 cache, and every frame ran 2–6 times slower (the depth-16 frame 11.9 ms in ncu against 1.90, "
    "94 % of its stalls waiting on local memory; "
    "[gpu/variants-paused-planes.txt](gpu/variants-paused-planes.txt)).")


def produce(ctx):
    record_machine(ctx, "render", "start")
    ctx.run("render-modes", [os.path.join(ctx.bin, "octoray_bench_render"), "--size", SIZE, "--repeats", REPEATS,
                             "--backend", "cpu", "--parts", "modes",
                             "--json", fresh(ctx.work_path("render-modes.json"))])
    ctx.run("render-traversal", [os.path.join(ctx.bin, "octoray_bench_render"), "--size", "1920x1080",
                                 "--repeats", 3, "--backend", "cpu", "--parts", "traversal",
                                 "--json", fresh(ctx.work_path("render-traversal.json"))])
    record_machine(ctx, "render", "end")


def _mrays(r):
    return (r["primary_rays"] + r["secondary_rays"]) / r["seconds"] / 1e6


def _by_scene(records):
    out = {}
    for r in records:
        _, scene, mode = r["name"].split(".", 2)
        out.setdefault(scene, []).append((mode, r))
    return out


def render(ctx):
    records = [r for r in load_records(ctx.work_path("render-modes.json")) if "primary_rays" in r]
    cpu = _by_scene(records)
    gpu_modes = gpu_records(ctx, GPU_RENDER_FILE)
    gpu = _by_scene([r for r in gpu_modes or [] if "primary_rays" in r])
    cpu_name = records[0]["backend"].split("-", 1)[1] if records else "CPU"

    parts, csv_rows, plot = [], [], []
    for scene, rows in cpu.items():
        table = []
        first = rows[0][1]
        g_by = dict(gpu.get(scene, []))
        for mode, r in rows:
            g = g_by.get(mode)
            g_cell = ("%.0f" % _mrays(g)) if g else NOT_ON_GPU
            ratio = ("%.0f×" % (_mrays(g) / _mrays(r))) if g else "–"
            table.append([mode, "%.1f" % (r["seconds"] * 1e3), "%.2f" % _mrays(r),
                          "%.2f" % (r["primary_rays"] / r["seconds"] / 1e6),
                          "%.2f" % (r["secondary_rays"] / r["primary_rays"]), g_cell, ratio])
            csv_rows.append([scene, mode, r["n"], r["depth"], r["seconds"], r["min_seconds"], r["primary_rays"],
                             r["secondary_rays"], _mrays(r), g["seconds"] if g else "", _mrays(g) if g else ""])
            plot.append((scene, mode, _mrays(r), _mrays(g) if g else None))
        parts.append("**%s**: %s points, depth %d, %s nodes\n\n" % (
            scene, count(first["points"]), first["depth"], count(first["nodes"])) + ctx.table(
            ["mode", "ms / frame", "Mrays/s (all rays)", "Mrays/s (primary)", "secondary rays / pixel",
             "CUDA Mrays/s (all rays)", "CUDA / CPU"], table))
    csv = ctx.write_csv("render-modes", ["scene", "mode", "pixels", "depth", "cpu_s", "cpu_min_s", "primary_rays",
                                         "secondary_rays", "cpu_mrays_s", "cuda_s", "cuda_mrays_s"], csv_rows)
    png, link = ctx.figure_path("render-modes")
    if plot:
        _plot(png, plot, cpu_name)

    gpu_line = ("The CUDA column is from %s (`octoray_bench_render --backend cuda --size 1920x1080`, the same "
                "scenes and modes; wall time of the `Render` call with the picture copied to the host, as on the CPU)." %
                gpu_source(ctx, GPU_RENDER_FILE)) if gpu_modes else (
        "CUDA column: %s; on the GPU machine `build-gpu/bin/octoray_bench_render --backend cuda --size 1920x1080 "
        "--parts modes --json OUTDIR/%s` fills it." % (NOT_ON_GPU, GPU_RENDER_FILE))

    cuda_text, summary = _cuda_cloud(ctx)
    traversal_text, traversal_summary = _one_core(ctx)
    summary = traversal_summary + summary
    text = """
{machine}

Command:

    {cmd}

Scenes: `lidar` = Data/Particles/lidar_simple.particles (the thesis format with reflectivity; automatic depth);
`spheres` = 48 spheres, 1 M points on their surfaces, radial normals, reflectivity 0.4, depth 8. Camera: the
command-line tool's orbit camera (azimuth −60, elevation 30, zoom 1.3, 30°). Modes without "reflections" run with
bounces 0; "reflections" = Phong + shadows + 2 bounces; shadows use one directional light. Mrays/s counts primary +
secondary (shadow and mirror) rays; time is the median of {repeats} frames after one warm-up frame, {size}, engine
{engine}.

{tables}

[CSV]({csv}) · ![render throughput per mode]({link})

{gpu_line}

Reading these tables:

- Volume modes that see every voxel along the ray (MIP, MinIP, average, additive) cost more than the first-hit modes
  on the sphere field: they cannot stop at the first hit; composite stops at alpha 0.995 and costs about a first hit
  on opaque-ish spheres.
- Shadows and reflections add secondary rays (the last column); Mrays/s counts them, so those rows are not slower
  per ray, only per frame.
- The CPU backend traces each frame's primary rays eight at a time (the packets of the one-core section below) and
  the first hits' shadow rays eight at a time too, one packet per light; mirror rays, and the shadow rays of what they
  hit, go one at a time, so those secondary rays cost more per ray than the primary ones.
- How level of detail and the bounce limit trade error for time is in the quality section.

### One core: packets of rays, Traverse and the plain slab-test traversal

{traversal}

### CUDA, 10 M points at 1920×1080 (GPU run)

{cuda}
""".format(machine=machine_text(ctx, "render"), cmd=ctx.command("render-modes"), repeats=REPEATS, size=SIZE,
           engine=cpu_name, tables="\n\n".join(parts) or "No render records.", csv=csv, link=link, gpu_line=gpu_line,
           cuda=cuda_text, traversal=traversal_text)
    return Section(text, summary)


def _plot(png, plot, cpu_name):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    scenes = list(dict.fromkeys(p[0] for p in plot))
    fig, axes = plt.subplots(1, len(scenes), figsize=(5 * len(scenes), 4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        rows = [p for p in plot if p[0] == scene]
        y = np.arange(len(rows))
        with_gpu = any(p[3] for p in rows)
        h = 0.4 if with_gpu else 0.8
        ax.barh(y - (h / 2 if with_gpu else 0), [p[2] for p in rows], height=h, color="#1f77b4", label=cpu_name)
        if with_gpu:
            ax.barh(y + h / 2, [p[3] or np.nan for p in rows], height=h, color="#d62728", label="CUDA")
            ax.set_xscale("log")
        ax.set_yticks(y)
        ax.set_yticklabels([p[1] for p in rows])
        ax.invert_yaxis()
        ax.set_xlabel("Mrays/s (primary + secondary)")
        ax.set_title("scene: " + scene)
        ax.grid(axis="x", alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def _one_core(ctx):
    """Primary rays on one core through packets of eight rays, through
    Traverse and through the reference slab-test traversal, timed in the same
    run (`--parts traversal`)."""
    records = [r for r in load_records(ctx.work_path("render-traversal.json")) if r["name"].startswith("traversal.")]
    rows, scenes = [], []
    for r in records:
        rays = r["n"]
        packets, fast, reference = (rays / r[k] / 1e6 for k in ("packet_seconds", "seconds", "peer_seconds"))
        scenes.append((r["name"].split(".", 1)[1], packets, reference))
        rows.append([scenes[-1][0], r["depth"], count(r["nodes"]), "%.2f" % packets, "%.2f" % fast,
                     "%.2f" % reference, "%.2f×" % (packets / fast), "%.2f×" % (fast / reference),
                     "yes" if r["same_first_hits"] else "NO"])
    if not rows:
        return "No traversal records.", []
    names = " / ".join(s[0] for s in scenes)
    summary = [("CPU render, one core, primary rays 1920×1080 (%s), packets of 8 rays" % names,
                " / ".join("%.1f Mrays/s" % s[1] for s in scenes),
                "plain slab-test traversal " + " / ".join("%.1f" % s[2] for s in scenes),
                " / ".join("%.2f×" % (s[1] / s[2]) for s in scenes))]
    text = ("Command:\n\n    %s\n\nEach pixel's primary ray to its first voxel in a plain loop on one core (no "
            "shading, no picture), 1920×1080, best of 3 after a warm-up, three ways:\n\n"
            "- *packets*: eight neighbouring pixels of a row at once (PacketTraversal.h), as the CPU engine traces "
            "every primary ray, of surfaces and of the volume blend modes alike (shadow and mirror rays go one "
            "by one). One walk of the octree serves the packet; each step's arithmetic runs in SIMD lanes, one "
            "ray per lane (AVX2 where the processor has it, chosen at run time; SSE2 otherwise). Each lane keeps "
            "the set of children that `Traverse` keeps for its ray, so its pixel sees the voxels `Traverse` "
            "shows it, bit for bit and in the same order: the two walks look at a child, go down into it and "
            "climb back through the same code (Traversal.h's `WalkNode`). A lane whose direction lies in another "
            "octant than the packet's, or runs parallel to an axis, is traced alone by `Traverse`.\n"
            "- *Traverse* (Traversal.h), one ray at a time: each child's span picked from its parent's near, mid "
            "and far plane crossings; only the children the ray meets stepped to, and of those only the ones "
            "whose own children it meets gone down into; the way back up one step to the deepest node with "
            "children left, whose crossings are computed again; one 64-bit word on the stack per such node.\n"
            "- *reference*, `ReferenceTraverse` (ReferenceTraversal.h): a slab test of every child's box, each "
            "node's box decoded from its Morton key, a stack entry per child met. This is what the engine traced "
            "with before.\n\n"
            "\"Same first hits\" compares the sums of the hit voxels' indices over the frame, for all three. The "
            "engine tests compare the packets with `Traverse` lane by lane, and `Traverse` with the reference "
            "visit by visit.\n\n" % ctx.command("render-traversal") +
            ctx.table(["scene", "depth", "nodes", "Mrays/s, packets", "Mrays/s, Traverse", "Mrays/s, reference",
                       "packets / Traverse", "Traverse / reference", "same first hits"], rows))
    return text, summary


# Issue 16's goals for the frames of octoray_bench_cuda, in Mrays/s counting
# every ray, by (depth, primary rays alone).
RENDER_GOALS = {(10, True): 2000, (16, True): 1000, (10, False): 1000}


def _all_rays_per_second(ctx):
    """Mrays/s counting shadow and mirror rays, by (depth, primary), from the
    render lines octoray_bench_cuda printed in the same run (summary.txt)."""
    path = ctx.gpu_file("summary.txt")
    if not path:
        return {}
    found = {}
    for depth, kind, rate in re.findall(r"^render depth (\d+), (primary|Phong \+ shadows \+ 1 bounce):.*?"
                                        r"(\d+) Mrays/s", open(path).read(), re.M):
        found[(int(depth), kind == "primary")] = float(rate)
    return found


def _cuda_cloud(ctx):
    name = "bench-results-cuda.json"
    records = gpu_records(ctx, name)
    if records is None:
        return NOT_ON_GPU + ".", []
    rows, csv_rows, summary = [], [], []
    pixels = 1920 * 1080
    all_rays = _all_rays_per_second(ctx)
    for r in records:
        if not r["name"].startswith("render "):
            continue
        mode = "surface, primary rays" if "primary" in r["name"] else "Phong, 1 light, shadows, 1 bounce"
        primary = "primary" in r["name"]
        rays = all_rays.get((r["depth"], primary))
        goal = RENDER_GOALS.get((r["depth"], primary))
        rows.append([r["depth"], mode, "%.2f ms" % (r["seconds"] * 1e3), "%.0f" % (pixels / r["seconds"] / 1e6),
                     "%.0f" % rays if rays else "–", "%.0f" % (1 / r["seconds"]),
                     "%d (%.2f×)" % (goal, rays / goal) if goal and rays else "–"])
        csv_rows.append([r["n"], r["depth"], mode, r["seconds"], pixels / r["seconds"] / 1e6])
        if goal and rays:
            summary.append(("CUDA render 1920×1080, %s, 10 M points, depth %d (GPU run)" % (mode, r["depth"]),
                            "%.0f Mrays/s" % rays, "issue 16's goal %s Mrays/s" % count(goal),
                            "%.2f×" % (rays / goal)))
    csv = ctx.write_csv("render-cuda", ["points", "depth", "mode", "device_s", "mpixels_s"], csv_rows)
    text = ("From %s: the octoray_bench_cuda cloud (Gaussian clusters with colour and reflectivity), camera outside "
            "the cube; device time of the frame from `RenderStats.seconds` with the picture left on the device (as "
            "the VTK mapper draws it); median of 9. Mpixels/s = 1920·1080 / time; Mrays/s counts the shadow and "
            "mirror rays too (the benchmark's own line in [gpu/summary.txt](gpu/summary.txt), same run); the goal "
            "column is issue 16's, with the ratio reached.\n\n" % gpu_source(ctx, name) +
            ctx.table(["depth", "mode", "device time", "Mpixels/s", "Mrays/s", "frames/s", "goal, Mrays/s"], rows) +
            "\n\n[CSV](%s)\n\nEach frame runs the kernel instantiated for its feature set, one "
            "thread per pixel, through the traversal of the section above. At depth 16 the clustered points are "
            "sparse and most rays cross the whole cube without a hit." % csv)
    if ctx.gpu_file("variants-mirror-table.txt"):
        text += TRAVERSAL_CHANGES
    profile = ctx.gpu_file("profile.txt")
    if profile:
        text += ("\n\nNsight Compute on the render kernel, one depth-10 frame of each kind above and one "
                 "depth-16 primary frame (gpu-check.sh's "
                 "`profile` part, `ncu --clock-control none`, [gpu/profile.txt](gpu/profile.txt); the kernel is "
                 "built with the register cap OCTORAY_RENDER_MIN_BLOCKS, Rendering/Engine/CMakeLists.txt):\n\n"
                 "```\n%s```\n" % open(profile).read())
    before = ctx.gpu_file("profile-9b98c7c.txt")
    if before:
        text += ("\nThe same profile before the traversal stepped only to the children the ray meets and came "
                 "back up in one step (9b98c7c, [gpu/profile-9b98c7c.txt](gpu/profile-9b98c7c.txt); that call's "
                 "ncu did not yet report instructions and pipes):\n\n```\n%s```\n" % open(before).read())
    return text, summary
