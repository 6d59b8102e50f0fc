"""Report section: image error against render time for each quality knob
(leaf depth, level of detail, bounce limit, shadows, image size), one table
per scene, a Pareto plot per backend. Measured by octoray_bench_quality
(Benchmarks/Engine/BenchQuality.cpp; metrics in ImageMetrics.h)."""
import math
import os

from make_report import Section
import scenes

TITLE = "Rendering quality: image error against render time"

CPU_JSON = "quality-cpu.json"
GPU_JSON = "quality-cuda.json"
SCENES = [
    ("ct5n", "CT series (Data/DICOM/CT5N as points, air removed)"),
    ("lidar", "LiDAR tile (Data/Particles/lidar_simple.particles)"),
    ("spheres", "synthetic sphere field (48 spheres, points on their surfaces)"),
]
# What a reader needs to know of each scene to read its table.
SCENE_NOTES = {
    "ct5n": "The CT points carry HU only (coloured through a transfer function: fat yellow, soft tissue "
            "red), no reflectivity: no mirror rays are traced, so the bounce rows show the same picture "
            "as the reference. The five slices are 2.5 mm apart and 0.49 mm pixels across, so at the "
            "chosen depth each slice is a separate sheet of voxels.",
    "lidar": "RGB points with reflectivity from the return intensity (0 to 1), so mirror rays bounce; "
             "1065 points over the tile make voxels many pixels wide, which is why small LOD k changes "
             "nothing.",
    "spheres": "Points on sphere surfaces with radial normals and reflectivity 0.4; the generator is "
               "Benchmarks/Engine/BenchScenes.h (shared with octoray_bench_render).",
}
KNOBS = ["depth", "lod", "bounces", "shadows", "size"]
KNOB_TEXT = {"depth": "leaf depth", "lod": "LOD k (pixels)", "bounces": "bounces", "shadows": "shadows",
             "size": "image size (× W, H)"}
COLOURS = {"depth": "tab:blue", "lod": "tab:orange", "bounces": "tab:green", "shadows": "tab:red",
           "size": "tab:purple"}
# 1 - SSIM of identical pictures is 0, which a log axis cannot show: drawn here.
ERROR_FLOOR = 1e-6


def produce(ctx):
    ct = scenes.ct_particles(ctx)
    ctx.run("quality-cpu", [os.path.join(ctx.bin, "octoray_bench_quality"), "--backend", "cpu",
                            "--scenes", os.path.dirname(ct), "--json", ctx.work_path(CPU_JSON)])


def load(ctx):
    runs = {}
    cpu = ctx.work_path(CPU_JSON)
    if os.path.exists(cpu):
        runs["cpu"] = ctx.load_json(cpu)
    gpu = ctx.gpu_file(GPU_JSON)
    if gpu:
        runs["cuda"] = ctx.load_json(gpu)
    return runs


def rows_of(records, scene, knob=None):
    return [r for r in records if r["scene"] == scene and (knob is None or r["knob"] == knob)]


def reference_seconds(records, scene, knob):
    for r in rows_of(records, scene, knob):
        if r["is_reference"]:
            return r["seconds"]
    return None


def fmt_psnr(r):
    return "∞" if r["psnr"] is None else f"{r['psnr']:.1f}"


def fmt_ms(seconds):
    ms = seconds * 1e3
    return f"{ms:.1f}" if ms >= 10 else f"{ms:.2f}"


def scene_table(ctx, runs, scene):
    cpu = runs.get("cpu", [])
    gpu = runs.get("cuda")
    header = ["knob", "value", "RMSE", "PSNR (dB)", "SSIM", "CPU ms", "CPU × ref"]
    header += ["CUDA ms", "CUDA × ref", "CUDA SSIM"] if gpu else ["CUDA ms"]
    rows = []
    for knob in KNOBS:
        ref_cpu = reference_seconds(cpu, scene, knob)
        ref_gpu = reference_seconds(gpu, scene, knob) if gpu else None
        for r in rows_of(cpu, scene, knob):
            value = r["value"] + (" (reference)" if r["is_reference"] else "")
            row = [KNOB_TEXT[knob], value, f"{r['rmse']:.4f}", fmt_psnr(r), f"{r['ssim']:.4f}",
                   fmt_ms(r["seconds"]), f"{r['seconds'] / ref_cpu:.2f}" if ref_cpu else "—"]
            if gpu:
                g = [x for x in rows_of(gpu, scene, knob) if x["value"] == r["value"]]
                if g:
                    g = g[0]
                    row += [fmt_ms(g["seconds"]), f"{g['seconds'] / ref_gpu:.2f}" if ref_gpu else "—",
                            f"{g['ssim']:.4f}"]
                else:
                    row += ["not in the GPU run", "", ""]
            else:
                row += ["not run on a GPU yet"]
            rows.append(row)
    return ctx.table(header, rows, "ll" + "r" * (len(header) - 2))


def reference_checks(records, scene):
    return {r["value"].split(":")[0]: r for r in rows_of(records, scene, "reference-check")}


def pareto_front(points):
    """points: (seconds, error); the ones no other point beats on both."""
    front, best = [], math.inf
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def pareto_plot(ctx, records, backend):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    present = [s for s, _ in SCENES if rows_of(records, s)]
    fig, axes = plt.subplots(1, len(present), figsize=(5.2 * len(present), 4.6), squeeze=False)
    device = records[0]["device"] if records else backend
    for ax, scene in zip(axes[0], present):
        points = []
        for knob in KNOBS:
            rs = rows_of(records, scene, knob)
            xs = [r["seconds"] * 1e3 for r in rs]
            ys = [max(1 - r["ssim"], ERROR_FLOOR) for r in rs]
            # Image size is measured against its own (supersampled)
            # reference: drawn hollow, and not part of the frontier.
            own = knob == "size"
            ax.scatter(xs, ys, s=30, alpha=0.9, marker="s" if own else "o",
                       facecolors="none" if own else COLOURS[knob], edgecolors=COLOURS[knob])
            for r, x, y in zip(rs, xs, ys):
                if not r["is_reference"]:
                    ax.annotate(r["value"].split(" ")[0], (x, y), fontsize=6, xytext=(3, 2),
                                textcoords="offset points", color=COLOURS[knob])
            if not own:
                points += list(zip(xs, ys))
        front = pareto_front(points)
        ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="black", lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.axhline(ERROR_FLOOR, color="grey", lw=0.5, ls=":")
        ax.set_title(scene, fontsize=10)
        ax.set_xlabel("frame time (ms, log)")
        ax.set_ylabel("1 − SSIM (log)")
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
    handles = [Line2D([], [], ls="", marker="o", color=COLOURS[k], label=KNOB_TEXT[k]) for k in KNOBS[:-1]]
    handles.append(Line2D([], [], ls="", marker="s", markerfacecolor="none", color=COLOURS["size"],
                          label=KNOB_TEXT["size"] + ", against 2×2 supersampling"))
    handles.append(Line2D([], [], color="black", lw=1, label="Pareto frontier (filled points)"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    fig.suptitle(f"Image error against frame time, {backend.upper()}: {device} "
                 f"(identical pictures drawn at 1 − SSIM = {ERROR_FLOOR:g})", fontsize=11)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    path, link = ctx.figure_path(f"quality-pareto-{backend}")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return link


def fastest_good(records, scene, ssim_at_least=0.95):
    """The fastest setting of `scene` with SSIM >= the bound against the
    common reference, and that reference's time (image size, which has its
    own reference, left out)."""
    ref = reference_seconds(records, scene, "lod")
    good = [r for r in records if r["scene"] == scene and r["knob"] in KNOBS[:-1] and not r["is_reference"]
            and r["ssim"] >= ssim_at_least]
    if not good or not ref:
        return None
    return min(good, key=lambda r: r["seconds"]), ref


def render(ctx):
    runs = load(ctx)
    if "cpu" not in runs:
        return Section("Not produced yet: run `make report` (or `--only quality`).")
    cpu = runs["cpu"]
    gpu = runs.get("cuda")
    md = []
    first = cpu[0]
    md.append(
        f"What each quality knob costs in picture and buys in time. For every scene one knob at a time "
        f"moves away from the reference setting (the others stay there) and each picture is compared with "
        f"the reference picture of the same scene, rendered by the same backend. Pictures are "
        f"{first['width']}×{first['height']} (W×H), Phong-shaded with one directional light.\n")
    md.append(f"CPU rows: `{ctx.command('quality-cpu')}` (CT scene written first by "
              f"`{scenes.with_python_path(ctx.command('scene-ct5n'))}`), on {first['device']}.")
    if gpu:
        md.append(f"CUDA rows: `build-gpu/bin/octoray_bench_quality --backend cuda --scenes DIR --json "
                  f"quality-cuda.json` (scripts/gpu/gpu-check.sh; DIR holds the ct5n.particles written here), "
                  f"on {gpu[0]['device']}, from [gpu/{GPU_JSON}](gpu/{GPU_JSON}).")
    else:
        md.append("CUDA rows: not run on a GPU yet (scripts/gpu/gpu-check.sh writes "
                  f"`{GPU_JSON}`, to be committed in Benchmarks/gpu/).")
    md.append("""
**The references, and why they can be trusted.**

- *Level of detail, bounces, shadows, leaf depth*: the reference picture is the scene at the depth the
  engine chooses from the data (the shallowest level at which the median leaf holds one point), level of
  detail off (k = 0: every ray descends to the leaves, nothing finer exists), 8 bounces and shadows on, at
  W×H. It is converged in each knob's own direction: k = 0 is the finest the octree holds; mirror weights
  multiply along a path (0.4 per bounce on the spheres), and the row *reference-check, bounces: 8 against 16*
  below measures what 8 more bounces would change; shadows on is the full light model.
- *Leaf depth* has no converged limit: deeper leaves shrink each point's box until rays pass between the
  points, so the picture does not approach anything as the depth grows. The reference is the depth the
  engine picks, and the rows say how much a shallower tree (larger, averaged boxes) or a deeper one
  (smaller boxes, gaps) changes the picture, and what that costs.
- *Image size*: rendered at s·W×s·H (s = ¼, ½, 1), each pixel repeated to W×H (nearest, as a viewer
  stretching a smaller picture shows it), against a reference rendered at 2W×2H and box-filtered to W×H
  (2×2 supersampling: 4 rays a pixel). The row *reference-check, size: 2x2 against 4x4* compares that
  reference with 4×4 supersampling (16 rays a pixel): errors of that order are within the reference's own
  aliasing.
- The tracer that makes every picture is tested against brute-force references in `make test`
  (Testing/Engine, on each backend): `RenderTest.SurfaceMatchesBruteForceVoxelHits` (first hit and depth
  against a double-precision intersection of the ray with every leaf box),
  `RenderTest.MaximumIntensityMatchesBruteForce`, `SceneTest.VolumeBlendModesMatchABruteForceRayMarcher`,
  `SceneTest.LevelOfDetailDrawsTheCoarserOctree` (LOD draws exactly the coarser level),
  `SceneTest.MirrorPlaneShowsTheVoxelsMirrorImage`, `SceneTest.BlockCastsItsShadowOnTheFloor`,
  `RenderTest.FullPlaneHasNoCracksAtAnyAngle`, and `RenderCUDA.ImagesEqualTheCpuBackend` (the CUDA
  picture equals the CPU one), so a reference is the engine's exact answer at its setting, not an
  approximation of it.

**Metrics** (Benchmarks/Engine/ImageMetrics.h): on the premultiplied RGB (the picture over black),
each channel clamped to [0, 1], data range 1. RMSE over all channels and pixels; PSNR = 10 log10(1/MSE)
(∞: identical); SSIM after Wang et al. 2004: 11×11 Gaussian window, σ = 1.5, population statistics,
K1 = 0.01, K2 = 0.03, over the pixels whose window lies inside the picture, per RGB channel and the three
averaged. `python.bench_quality_metrics` (Testing/Python/test_bench_quality_metrics.py, `make test`)
checks all three against scikit-image's `structural_similarity(..., channel_axis=-1,
gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=1)` and
`peak_signal_noise_ratio` on pictures the program renders of all three scenes.

**Time**: median of the repeats (after a warm-up frame) of the engine's own frame time
(`RenderStats::seconds`): on the CPU the whole frame; on CUDA the host clock around the kernel launch and
the device synchronise, the picture left in device memory (its copy to the host, needed only for the
comparison, is not timed). "× ref" is the time over the reference's time in the same run (for image size,
the 2W×2H render). This machine is shared, so differences of a few per cent are noise.
""")

    for scene, text in SCENES:
        rs = rows_of(cpu, scene)
        if not rs:
            md.append(f"### {scene}: {text}\n\nNot in this run.\n")
            continue
        r0 = rs[0]
        md.append(f"### {scene}: {text}\n")
        md.append(f"{r0['points']} points; reference: {r0['reference']}.\n")
        md.append(SCENE_NOTES[scene] + "\n")
        md.append(scene_table(ctx, runs, scene))
        found = fastest_good(cpu, scene)
        if found and found[0]["seconds"] <= 0.9 * found[1]:
            best, ref = found
            md.append(f"\nFastest CPU setting within SSIM 0.95 of the reference (image size aside): "
                      f"{KNOB_TEXT[best['knob']]} {best['value']}, SSIM {best['ssim']:.3f} in "
                      f"{best['seconds'] / ref:.2f}× the reference's time.")
        else:
            md.append("\nNo CPU setting within SSIM 0.95 of the reference (image size aside) saves 10% "
                      "of its time or more.")
        checks = reference_checks(cpu, scene)
        notes = []
        for key, label in (("size", "2×2 against 4×4 supersampling"), ("bounces", "8 bounces against 16")):
            c = checks.get(key)
            if c:
                notes.append(f"{label}: RMSE {c['rmse']:.4f}, PSNR {fmt_psnr(c)} dB, SSIM {c['ssim']:.4f}")
        if notes:
            md.append("\nReference check (CPU): " + "; ".join(notes) + ".\n")

    header = ["scene", "backend", "device", "knob", "value", "seconds", "rmse", "psnr", "ssim", "reference",
              "is_reference", "width", "height", "depth", "points", "repeats"]
    csv_rows = [[r.get(h) for h in header] for backend in ("cpu", "cuda") for r in runs.get(backend, [])]
    csv_link = ctx.write_csv("quality", header, csv_rows)

    plots = [f"![CPU: error against time]({pareto_plot(ctx, cpu, 'cpu')})"]
    if gpu:
        plots.append(f"![CUDA: error against time]({pareto_plot(ctx, gpu, 'cuda')})")
    md.append("\n### Pareto plots\n")
    md.append("1 − SSIM (log) against frame time (log), one panel per scene, points coloured by knob and "
              "labelled with the knob's value. The black line is the Pareto frontier of the knobs that "
              "share the common reference (no other of those settings is both faster and closer to it); "
              "image size, measured against the supersampled picture, is drawn hollow and left off the "
              f"frontier. Settings whose picture equals the reference sit on the bottom line (error 0, "
              f"drawn at {ERROR_FLOOR:g}).\n")
    md += plots
    if not gpu:
        md.append("\nCUDA plot: not run on a GPU yet.")
    md.append(f"\nAll records (both backends): [{csv_link}]({csv_link}).")

    summary = []
    for backend, records in (("cpu", cpu), ("cuda", gpu)):
        if records is None:
            summary.append(("Quality: fastest single-knob setting with SSIM ≥ 0.95, sphere field (CUDA)",
                            "not run on a GPU yet", "", ""))
            continue
        found = fastest_good(records, "spheres")
        if found and found[0]["seconds"] <= 0.9 * found[1]:
            best, ref = found
            summary.append((f"Quality: fastest single-knob setting with SSIM ≥ 0.95, sphere field "
                            f"({backend.upper()}): {KNOB_TEXT[best['knob']]} {best['value']}",
                            f"{fmt_ms(best['seconds'])} ms, SSIM {best['ssim']:.3f}",
                            f"{fmt_ms(ref)} ms (reference)", f"{ref / best['seconds']:.1f}× faster"))
    return Section("\n".join(md), summary)
