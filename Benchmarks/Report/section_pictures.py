"""Report section: the picture. The octree mapper against what a VTK user
would do today with the same points (vtkPointInterpolator or
vtkGaussianSplatter into an image drawn by vtkSmartVolumeMapper;
vtkPointGaussianMapper), and the mapper's own cost in a VTK render window.

produce: Benchmarks/Python/bench_pictures.py (JSON + the first frame of every
method as PNG under work/pictures/) and Benchmarks/Python/bench_mapper.py
(its printed table, in work/pictures-mapper.log), both under an X display.
render: one table and one montage per scene, a CSV, the mapper's table.
"""
import os
import re
import shutil

from scenes import with_python_path

TITLE = "Pictures: the mapper against vtkPointInterpolator, vtkGaussianSplatter and vtkPointGaussianMapper"

PYTHON = "/usr/bin/python3"  # Debian's python3: ParaView 5.11's VTK
MAPPER_ARGS = ["--frames", "5", "--points", "200000", "--size", "960x540"]

# Panel order of the montages and the tables' wording.
NAMES = {
    "octoray": "octoray vtkOctreeVolumeMapper",
    "interp": "vtkPointInterpolator + vtkSmartVolumeMapper",
    "splat": "vtkGaussianSplatter + vtkSmartVolumeMapper",
    "pointgauss": "vtkPointGaussianMapper",
    "stack": "CT image + vtkSmartVolumeMapper",
}
ORDER = ["octoray", "interp", "splat", "pointgauss", "stack"]


def _env(ctx):
    return {
        "PYTHONPATH": os.path.join(ctx.build, "lib", "python3", "dist-packages"),
        "OCTORAY_DATA": os.path.join(ctx.root, "Data"),
        "VTK_LOGGING_LEVEL": "ERROR",
        "PYTHONDONTWRITEBYTECODE": "1",
    }


def produce(ctx):
    package = os.path.join(ctx.build, "lib", "python3", "dist-packages", "octoray", "__init__.py")
    if not os.path.exists(package):
        raise RuntimeError("report: pictures: no octoray Python package in %s (build the project first)" % package)
    images = ctx.work_path("pictures")
    shutil.rmtree(images, ignore_errors=True)
    for stale in ("pictures.json", "pictures-mapper.json"):
        if os.path.exists(ctx.work_path(stale)):
            os.remove(ctx.work_path(stale))
    rendering = os.path.join(ctx.root, "Benchmarks", "Python")
    ctx.run("pictures", [PYTHON, os.path.join(rendering, "bench_pictures.py"),
                         "--json", ctx.work_path("pictures.json"), "--images", images],
            env=_env(ctx), display=True, timeout=600)
    ctx.run("pictures-mapper", [PYTHON, os.path.join(rendering, "bench_mapper.py"),
                                "--json", ctx.work_path("pictures-mapper.json")] + MAPPER_ARGS,
            env=_env(ctx), display=True, timeout=300)


# ------------------------------------------------------------------ helpers

def _ms(s):
    if s is None:
        return "–"
    return "%.2f s" % s if s >= 1.0 else "%.0f ms" % (s * 1e3) if s >= 0.01 else "%.1f ms" % (s * 1e3)


def _tag(r):
    return r["method"] if r.get("grid") is None else "%s-%d" % (r["method"], r["grid"])


def _method_cell(r):
    name = NAMES[r["method"]]
    if r.get("dims"):
        name += " (%s)" % "×".join(str(d) for d in r["dims"])
    return name


def _ratio(a, b):
    """How many times b is a (a the peer, b octoray): '3.2× faster' style."""
    if not a or not b:
        return "–"
    return "%.1f× less" % (a / b) if a >= b else "%.1f× more" % (b / a)


def _faster(peer, ours):
    return "%.1f× faster" % (peer / ours) if peer >= ours else "%.1f× slower" % (ours / peer)


def _records(data, scene):
    rows = [r for r in data["records"] if r["scene"] == scene]
    return sorted(rows, key=lambda r: (ORDER.index(r["method"]), r.get("grid") or 0))


def _scene_table(data, scene):
    rows = _records(data, scene)
    octo = next((r for r in rows if r["method"] == "octoray"), None)
    out = []
    for r in rows:
        prepare = r.get("prepare_s")
        render_first = r["first_s"] - (prepare or 0.0)
        out.append([
            _method_cell(r),
            _ms(prepare) if prepare is not None else
            ("(octree build %s, in the first render)" % _ms(r["build_s"]) if "build_s" in r else "–"),
            _ms(render_first),
            _ms(r["first_s"]),
            _ms(r["frame_s"]),
            "%.0f MB" % r["peak_mb"] if r.get("peak_mb") is not None else "–",
            "1" if r is octo else _ratio(r["first_s"], octo["first_s"]) if octo else "–",
            "1" if r is octo else _ratio(r["frame_s"], octo["frame_s"]) if octo else "–",
        ])
    header = ["method (splat grid, voxels)", "splat / interpolate", "first render", "time to first picture",
              "median frame", "peak memory added", "octoray's first picture: time", "octoray's frame: time"]
    return header, out


def _montage(ctx, data, scene, images):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    grids = data["grids"]
    chosen = []
    for r in _records(data, scene["name"]):
        # The four methods (and the CT's own image) at the first grid size.
        if r.get("grid") not in (None, grids[0]):
            continue
        path = os.path.join(images, r["image"])
        if os.path.exists(path):
            chosen.append((r, path))
    if not chosen:
        return None
    fig, axes = plt.subplots(1, len(chosen), figsize=(3.6 * len(chosen), 3.4))
    axes = axes if len(chosen) > 1 else [axes]
    for ax, (r, path) in zip(axes, chosen):
        ax.imshow(mpimg.imread(path))
        ax.set_axis_off()
        label = NAMES[r["method"]].replace(" + ", "\n+ ")
        if r.get("grid"):
            label += " (%d)" % r["grid"]
        ax.set_title("%s\nfirst picture %s, frame %s" % (label, _ms(r["first_s"]), _ms(r["frame_s"])), fontsize=8)
    fig.suptitle("%s: %s points, %d×%d window, one camera" % (scene["title"], format(scene["points"], ","),
                                                             *data["size"]), fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.9))
    path, link = ctx.figure_path("pictures_" + scene["name"])
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return link


def _mapper_tables(ctx):
    """The table bench_mapper.py prints, per scene."""
    log = ctx.work_path("pictures-mapper.log")
    if not os.path.exists(log):
        return None
    with open(log) as f:
        text = f.read()
    scenes = []
    head = re.compile(r"^(\w+): (\d+) points, backend (.*), build ([\d.]+) ms, (\d+)x(\d+), median of (\d+) orbiting frames$")
    step = re.compile(r"^\| (.+?) \| ([\d.]+) \|$")
    layer = re.compile(r"^VTK layer .* = ([\d.]+)% of the engine's trace; ([\d.]+) frames/s$")
    current = None
    for line in text.splitlines():
        m = head.match(line)
        if m:
            current = dict(name=m.group(1), points=int(m.group(2)), backend=m.group(3), build_ms=float(m.group(4)),
                           size=(int(m.group(5)), int(m.group(6))), frames=int(m.group(7)), steps={})
            scenes.append(current)
            continue
        m = step.match(line)
        if m and current is not None:
            current["steps"][m.group(1)] = float(m.group(2))
            continue
        m = layer.match(line)
        if m and current is not None:
            current["layer_pct"], current["fps"] = float(m.group(1)), float(m.group(2))
    return scenes


def render(ctx):
    from make_report import Section

    path = ctx.work_path("pictures.json")
    if not os.path.exists(path):
        return Section("Not produced yet: run `make report` (or `--only pictures`).")
    data = ctx.load_json(path)
    images = ctx.work_path("pictures")
    w, h = data["size"]
    cmd = with_python_path(ctx.command("pictures"))
    md = []
    md.append(
        "Command (under an X display; `xvfb-run -a` without one):\n\n"
        "    %s\n\n"
        "The same points, in one run, drawn by four methods into an offscreen %d×%d window from one "
        "camera (VTK's ResetCamera of the points' bounds, raised by an elevation per scene), which then "
        "orbits the data in %d steps:\n\n"
        "- **octoray**: `vtkOctreeVolumeMapper` with a `vtkVolumeProperty` (shading on; the point colours "
        "or the scene's colour map); `New()` picks the CPU backend here (no GPU). First-hit surface of the "
        "octree's leaf voxels at the automatic leaf depth: cubes, lit by the renderer's headlight.\n"
        "- **vtkPointInterpolator** with a `vtkGaussianKernel` (sharpness 2; radius per scene below, at "
        "least one voxel) onto a `vtkImageData` with 128 and 256 voxels along the longest side and equal "
        "spacing on every axis (what one sets up for a volume mapper; the CT scene only 128, already 8 "
        "times finer than its 16×16×5 samples), drawn by `vtkSmartVolumeMapper`. "
        "The volume is RGBA: the interpolated colours (or the interpolated scalar through the same colour "
        "map) with the interpolator's valid-point mask as alpha; the colour of empty voxels beside a filled "
        "one is copied from it, because the ray caster interpolates colour and alpha separately and the "
        "empty voxels' black would otherwise darken every blob. Unshaded: with dependent RGBA components "
        "VTK 9.2's ray caster lit samples with the ambient term only (checked on a solid ball), so shading "
        "would only darken it. The time includes this numpy glue.\n"
        "- **vtkGaussianSplatter** onto the same grid (same radius, exponent factor −5, no scalar "
        "warping), drawn by `vtkSmartVolumeMapper` with shading and an opacity ramp over the density "
        "0.02–0.2. The splatter makes a density, not colours: its pictures have one colour.\n"
        "- **vtkPointGaussianMapper** as an actor, splat radius = the scene's radius, with ParaView's "
        "\"Sphere\" splat shader (opaque lit discs; the default Gaussian blur is translucent); point "
        "colours directly or the same colour map.\n\n"
        "Threads: ParaView 5.11's VTK on Debian defaults to the Sequential vtkSMPTools backend (one "
        "thread). vtkPointInterpolator runs with the %s backend (%s threads), the same 2 cores as "
        "octoray's CPU backend; vtkGaussianSplatter keeps Sequential, because with STDThread it took 65 s "
        "instead of 0.8 s for the 200 k-point sphere field here (its threaded splat contends): each VTK "
        "filter runs at its faster setting.\n\n"
        "*Time to first picture* starts with the points in memory and ends when the first frame is "
        "drawn (`Render()` + `WaitForCompletion()`): octree build and trace, or interpolation/splatting, "
        "texture upload, shader compilation and ray casting. *splat / interpolate* is the part before "
        "the first `Render()` (for octoray: the octree build reported by the mapper, inside its first "
        "render). *Median frame* is the median over the orbit. *Peak memory added* is the process's peak "
        "resident memory (VmHWM, reset through /proc/self/clear_refs before each method) less its "
        "resident memory before it: it includes Mesa's copies of the textures. The columns at the right "
        "say how octoray's time compares (\"3.0× less\": octoray takes a third of the peer's time).\n\n"
        "**This machine has no GPU**: VTK draws through Mesa's llvmpipe under Xvfb, so "
        "`vtkSmartVolumeMapper`'s GPU ray caster (its render mode was \"%s\" in every run) and "
        "`vtkPointGaussianMapper` run in software on the same 2 CPU cores as octoray's CPU backend: a "
        "fair same-machine comparison of CPU against CPU, not a statement about GPUs. On a workstation "
        "GPU the VTK methods' frames would be much faster, and octoray would use its CUDA backend. "
        "On the GPU machine, with VTK built for EGL on the NVIDIA driver, the CUDA mapper and VTK's GPU "
        "mappers are timed against each other in one window: *The CUDA mapper in VTK windows* below."
        % (cmd, w, h, data["frames"], data.get("smp_backend", "?"), data.get("smp_threads", "?"),
           _render_modes(data)))

    csv_rows = []
    for scene in data["scenes"]:
        header, rows = _scene_table(data, scene["name"])
        octo = next((r for r in data["records"] if r["scene"] == scene["name"] and r["method"] == "octoray"), {})
        md.append("### %s\n\n%s points, %s; splat radius %g (data units); octoray's leaf voxel: %.3g; "
                  "grids: %s.\n\n%s" % (
                      scene["title"], format(scene["points"], ","),
                      "point colours (RGB)" if scene["colouring"] == "rgb" else "CT values through one colour map",
                      scene["radius"], octo.get("leaf_size", float("nan")),
                      ", ".join("×".join(str(d) for d in r["dims"]) for r in _records(data, scene["name"])
                                if r["method"] == "interp"),
                      ctx.table(header, rows, "l" + "r" * (len(header) - 1))))
        link = _montage(ctx, data, scene, images)
        if link:
            md.append("![%s](%s)" % (scene["title"], link))
        for r in _records(data, scene["name"]):
            csv_rows.append([scene["name"], _tag(r), r["label"], scene["points"], r.get("grid") or "",
                             "x".join(str(d) for d in r.get("dims", [])), "%.6f" % r["first_s"],
                             "" if r.get("prepare_s") is None else "%.6f" % r["prepare_s"],
                             "%.6f" % r["frame_s"], r["frames"],
                             "" if r.get("peak_mb") is None else "%.1f" % r["peak_mb"],
                             r.get("backend") or r.get("render_mode", "")])
    link = ctx.write_csv("pictures", ["scene", "method", "label", "points", "grid", "dims", "first_picture_s",
                                      "splat_s", "frame_median_s", "frames", "peak_mb", "backend"], csv_rows)
    md.append(
        "All figures: [%s](%s).\n\n"
        "How the pictures differ, and why. They show the same object from the same camera. octoray draws "
        "the leaf voxels as cubes: on the sparse LiDAR tile (one point per ~100 m) they tile the ground as "
        "a mosaic, on the CT points the five slices (2.5 mm apart, pixels 0.49 mm) stay five sheets of "
        "voxels, on the spheres the shells are one voxel thick and lit per face. Its voxels are lit with the "
        "volume property's defaults (ambient 0.1, diffuse 0.7, specular 0.2) and their faces are seen "
        "obliquely, so they look darker than the point Gaussians' spheres, which face the camera with the "
        "actor's full diffuse light. The interpolated volumes "
        "are blobs of the kernel's radius, unshaded (see above), smoother at 256 voxels. The splatter's "
        "pictures are single-coloured densities with shading from the density gradient. The point "
        "Gaussians are lit spheres of the chosen radius, so they look fuller than the voxels of the same "
        "points. For the CT, the stack's own image (vtkSliceStackReader's second output, 16×16×5 "
        "samples) drawn by `vtkSmartVolumeMapper` is what a VTK user would draw instead of points: it "
        "interpolates between the slices, so it is a solid block."
        % (link, link))

    mapper = _mapper_tables(ctx)
    md.append(_mapper_section(ctx, mapper))

    gpu = ctx.gpu_file("pictures.json")
    if gpu:
        md.append("A pictures run on a GPU machine was committed (%s); it is not shown here because this "
                  "section's GPU rows need VTK on that machine." % ctx.relative(gpu))

    summary = []
    sph = {(_tag(r)): r for r in data["records"] if r["scene"] == "spheres"}
    octo, peer = sph.get("octoray"), sph.get("interp-%d" % data["grids"][0])
    if octo and peer:
        points = next(s["points"] for s in data["scenes"] if s["name"] == "spheres")
        what = "%s-point sphere field, %d×%d, CPU (VTK in llvmpipe)" % (format(points, ","), w, h)
        summary.append(("time to first picture, " + what, _ms(octo["first_s"]),
                        "%s (vtkPointInterpolator %d + vtkSmartVolumeMapper)" % (_ms(peer["first_s"]), peer["grid"]),
                        _faster(peer["first_s"], octo["first_s"])))
        summary.append(("median orbit frame, " + what, _ms(octo["frame_s"]),
                        "%s (vtkSmartVolumeMapper, %d grid)" % (_ms(peer["frame_s"]), peer["grid"]),
                        _faster(peer["frame_s"], octo["frame_s"])))
    return Section("\n\n".join(md), summary)


def _render_modes(data):
    modes = sorted({r["render_mode"] for r in data["records"] if r.get("render_mode")})
    return ", ".join(modes) or "unknown"


def _mapper_section(ctx, scenes):
    cmd = with_python_path(ctx.command("pictures-mapper"))
    if not scenes:
        return "### Mapper in a VTK render window, CPU\n\nNot produced yet."
    s0 = scenes[0]
    rows = []
    for s in scenes:
        st = s["steps"]
        title = "LiDAR tile, %d points" % s["points"] if s["name"] == "lidar" else \
            "48 spheres, %s points" % format(s["points"], ",")
        rows.append([title, "%.1f ms" % s["build_ms"], "%.1f ms" % st["trace"], "%.1f ms" % st["depth read"],
                     "%.2f ms" % st["upload"], "%.2f ms" % st["draw"], "%.1f%%" % s.get("layer_pct", float("nan")),
                     "%.1f ms" % st["whole Render()"], "%.2f" % s.get("fps", float("nan"))])
    table = ctx.table(["scene", "octree build", "engine trace", "depth read-back", "upload", "composite draw",
                       "VTK layer / trace", "whole Render()", "frames/s"], rows)
    return (
        "### Mapper in a VTK render window, CPU\n\n"
        "What the mapper itself adds to a frame beside the engine's trace. Command (`make bench` runs "
        "the same as bench.mapper at 1920×1080 with 10 frames and 1 M points; here smaller, to fit the "
        "report's time):\n\n"
        "    %s\n\n"
        "Offscreen %d×%d window under Xvfb (Mesa's software OpenGL), an opaque sphere actor plus the "
        "cloud (so the depth read-back has something to read), camera orbiting; median of %d frames; "
        "backend: %s.\n\n%s\n\n"
        "Per frame the mapper reads back the depth of what VTK drew (so rays stop at opaque actors), "
        "uploads the traced picture as a texture and draws it as a full-viewport quad writing "
        "`gl_FragDepth`. The depth read-back through Mesa is most of the VTK layer's cost. The parts "
        "of the CUDA mapper's frame, measured on the GPU machine (the picture handed to OpenGL on the "
        "device or through host memory), are in *The CUDA mapper in VTK windows* below; that orbit "
        "draws the cloud alone, so the mapper skips the depth read there."
        % (cmd, s0["size"][0], s0["size"][1], s0["frames"], s0["backend"], table))
