"""Octree build: octoray against PCL's octree and VTK's point locators (same
points, same run), the engine alone (phases, memory), the CUDA backend from
the committed GPU run, and the octree's quantisation error against depth."""
import collections
import json
import os
import re

from make_report import Section, file_parts
import scenes

TITLE = "Octree build"

# The peers comparison: the 10 M uniform case is the headline (issue 2's goal:
# single-threaded >= 5x faster than PCL). vtkOctreePointLocator takes about a
# minute per 10 M build on 2 cores, more than this section's time budget
# allows next to everything else, so it is measured up to 1 M points only.
PEER_CASES = "uniform:1e6,uniform:1e7,clustered:1e6"
OCTREE_LOCATOR_MAX = "5e6"
PEER_REPEATS = 3      # octoray and vtkStaticPointLocator (PCL and vtkOctreePointLocator: 3, their default)
BUILD_POINTS = "1e6,1e7"
BUILD_REPEATS = 3

PCL = "pcl::octree::OctreePointCloudPointVector"
OCTREE_LOCATOR = "vtkOctreePointLocator"
STATIC_LOCATOR = "vtkStaticPointLocator"
NOT_ON_GPU = "not run on a GPU yet"


# ---------------------------------------------------------------- shared helpers
# (the other benchmark sections import these)

def machine_note(ctx):
    """One line on the machine the CPU rows come from, written by produce()
    into work/machine-<section>.json so that render() can say it again."""
    cpu = "?"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        with open("/proc/meminfo") as f:
            mem_gb = int(f.readline().split()[1]) / 1e6
    except (OSError, ValueError, IndexError):
        mem_gb = 0
    return {"nproc": os.cpu_count(), "cpu": cpu, "memory_gb": round(mem_gb, 1),
            "load": os.getloadavg()[0]}


def record_machine(ctx, section, when):
    path = ctx.work_path("machine-%s.json" % section)
    data = {}
    if when != "start" and os.path.exists(path):
        data = ctx.load_json(path)
    note = machine_note(ctx)
    data.setdefault("machine", note)
    data["load_" + when] = note["load"]
    with open(path, "w") as f:
        json.dump(data, f)


def machine_text(ctx, section):
    path = ctx.work_path("machine-%s.json" % section)
    if not os.path.exists(path):
        return "Machine: (not recorded)."
    data = ctx.load_json(path)
    m = data["machine"]
    load = "load average %.1f at the start, %.1f at the end" % (data.get("load_start", 0), data.get("load_end", 0))
    text = ("Machine: %d CPU cores (`nproc`), \"%s\", %.0f GB RAM, no GPU; %s." % (
        m["nproc"], m["cpu"], m["memory_gb"], load))
    if max(data.get("load_start", 0), data.get("load_end", 0)) > m["nproc"]:
        text += (" **Caveat: the load was above the core count, so other work shared the cores with these "
                 "programs.** Times are then longer than on a quiet machine, and a ratio between two programs "
                 "timed at different moments can be off by the load's swings; re-run on a quiet machine before "
                 "quoting a ratio.")
    return text


def load_records(path):
    if not path or not os.path.exists(path):
        return []
    with open(path) as f:
        return json.load(f)


def fresh(path):
    """Raw results are rebuilt from scratch: drop an earlier file so records of
    cases no longer run cannot linger (the programs merge into the file)."""
    if os.path.exists(path):
        os.remove(path)
    return path


def seconds(s):
    """A time in the unit that reads best."""
    if s is None:
        return "–"
    if s >= 1:
        return "%.2f s" % s
    if s >= 1e-3:
        return "%.1f ms" % (s * 1e3) if s >= 0.01 else "%.2f ms" % (s * 1e3)
    return "%.3f ms" % (s * 1e3)


# Issue 16's goals for the CUDA build and the octree's size (its render
# goals: section_render.RENDER_GOALS).
GOAL_OVER_SORT = 2.0  # device phases / the bare CUB sort, at 10 M and 100 M points
GOAL_BUILD_100M = 0.015  # seconds of device phases at 100 M points
GOAL_CALL_OVER_COPY = 1.5  # whole call from host arrays / the pinned copy
GOAL_BYTES_PER_POINT = 24  # every attribute, 100 M points, depth 10
GOAL_BILLION_FRAMES = 60  # frames/s at 1920x1080, a billion points on one GPU


def named_record(records, name):
    """The first record of that name, or None."""
    return next((r for r in records if r["name"] == name), None)


def device_phases(r):
    """A CUDA build record's device phases: keys, sort and levels."""
    return r["key_seconds"] + r["sort_seconds"] + r["level_seconds"]


def call_over_copy(r):
    """A CUDA build record's whole call over the pinned copy of its input:
    the median of the pairs where the run recorded it (since the overlapped
    upload), else the two medians' ratio."""
    return r.get("call_over_pinned_copy") or r["seconds"] / r["pinned_upload_seconds"]


def human_bytes(b):
    for unit in ("B", "KB", "MB", "GB", "TB", "PB"):
        if b < 1000:
            return ("%.2f %s" if b < 10 and unit != "B" else "%.1f %s") % (b, unit)
        b /= 1000.0
    return "%.1f EB" % b


def count(n):
    """1 000 000 -> '1 M'; other counts with thin grouping."""
    if n >= 1e6 and n % 1000000 == 0:
        return "%d M" % (n // 1000000)
    return "{:,}".format(int(n)).replace(",", " ")


# octoray_bench_orbit --tile 1e9 on the GPU machine: a real scan tiled to a
# billion points through the mapper (the second-to-last call of COMMAND.md).
TILED_FILE = "orbit-tiled.json"
TILED_SUMMARY = "summary-tiled.txt"  # its call's closing table


# More rounds of the engine this report's run measured, on other H200
# machines, each (session, variants file, its parts): the fortieth session's
# rounds of "wholebounds" (calls 2 and 3, 42ed685 with the patch that
# a74e097 keeps, on one machine), the forty-first's of "main" (calls 3
# and 4, at 68179e4, beside a variant not kept), the forty-second's
# (calls 1, 3 and 4, at fd87b4a and 42b586b, the benchmark alone), the
# forty-third's (call 1, at 73c5ff4, on a host that copied slowly) and the
# forty-fourth's (call 3, at 0cb9b19, the report's run before this one)
# (COMMAND.md).
ROUNDS_ENGINE = "a74e097"
ROUNDS = (
    ("fortieth", "variants-whole-bounds.txt", ("wholebounds-2", "wholebounds-3")),
    ("forty-first", "variants-hugepages.txt", ("main-3", "main-4")),
    ("forty-second", "bench-build-rounds.txt", ("main", "main-3")),
    ("forty-third", "bench-build-rounds.txt", ("main-4",)),
    ("forty-fourth", "bench-build-rounds.txt", ("main-5",)),
)


def more_rounds(ctx, n):
    """[(session, file, parts, whole call / pinned copy ratios at n points)]
    of those rounds whose files are present."""
    found = []
    for session, name, parts in ROUNDS:
        path = ctx.gpu_file(name)
        if path:
            runs = summary_figures(path)
            found.append((session, name, parts, sum((runs[(p, n)]["call"] for p in parts), [])))
    return found


# The twenty-seventh session's runs on an NVIDIA H200 (COMMAND.md): the
# benchmark; and the variants of that session and later ones, each built
# beside main and run in turn, not kept. Their "summary n=..." lines are
# scripts/gpu/build-ratios.py's, under a line "== source-NAME" for each
# variant of a variants file ("main" the engine it was built beside). Each
# entry: the file, the parts of main's rounds, those of the variant's, and
# what the variant tried.
H200_BENCH_FILE = "bench-h200.txt"
H200_VARIANTS = (
    ("variants-staging-one-stream.txt", ("main",), ("one",),
     "every staging thread's DMA queued on one copy stream, where each thread has its own"),
    ("variants-nested-tiles4.txt", ("main",), ("tiles4",),
     "the nested lists in warp tiles of 4 rounds, where they hold 8"),
    ("variants-staging-pieces.txt", ("main",), ("hook",),
     "the thirtieth session's cube check and sort queued from a thread of their own, where the staging thread "
     "that queued the positions' last piece queues them"),
    ("variants-gather-staged.txt", ("main",), ("gather-staged",),
     "the thirty-first session's records written in sorted order straight from the staged attribute arrays, one "
     "loop an attribute, where they are gathered from the point records (the sort phase with the gather took "
     "0.79–0.80 ms at 10 M points against 0.76–0.77, and 9.65 ms at 100 M against 7.10–7.12)"),
    ("variants-leaf-parents.txt", ("main",), ("leaf-parents",),
     "the thirty-third session's leaves reduced in the loop of the level above them, a thread a parent that "
     "reads its leaves back where it has just written them (in ncu at 10 M points that launch took 376 µs where "
     "the leaves and level 9 took 164 + 101)"),
    ("variants-overlapped-launches.txt", ("main",), ("overlapped",),
     "the thirty-third session's build kernels launched to begin while the kernel before each ends (Hopper's "
     "programmatic dependent launch), each waiting there for that kernel's writes"),
    ("variants-loads-first.txt", ("main",), ("loads-first",),
     "the thirty-third session's leaf and inner loops loading everything before they store anything (in ncu at "
     "10 M points the leaves took 164.4 µs and level 9 104.4, where they took 164.0 and 101.0)"),
    ("variants-landed-records.txt", ("main",), ("landed",),
     "the twenty-ninth session's records stored as each piece of the attributes lands, in the caller's order and "
     "ranked by the sort during the upload, where they are made and gathered in sorted order after the copy (the "
     "staging threads were held up, for a reason not established, and at 100 M points the random writes ran "
     "9–11 ms past the copy)"),
    ("variants-hugepages.txt", ("main-3", "main-4"), ("hugepages-3", "hugepages-4"),
     "the forty-first session's staging buffers in one region of 2 MB pages, registered once, where each is a "
     "page-locked allocation of its own in 4 kB pages (main's two rounds in which the host copied at about half "
     "its speed read 1.79 and 1.89; one of the variant's read 1.98, its host's half and the pinned copy at once "
     "6.83 ms)"),
)


SUMMARY_FIGURES = ("phases", "floor", "ratio", "call")


def summary_figures(path):
    """{(variant, n): {figure: [one a summary line]}} of a GPU record's
    summary lines: "phases" and "floor" in ms, "ratio" (phases / floor) and
    "call" (whole call / pinned copy), by variant (variant_matches); empty
    lists for a variant and size the record lacks."""
    pattern = re.compile(r"summary n=(\d+): phases ([0-9.]+) ms, floor ([0-9.]+) ms, phases / floor ([0-9.]+), "
                         r"call / pinned copy ([0-9.]+)")
    found = collections.defaultdict(lambda: {k: [] for k in SUMMARY_FIGURES})
    for variant, m in variant_matches(path, pattern):
        figures = found[(variant, int(m.group(1)))]
        for k, value in zip(SUMMARY_FIGURES, m.groups()[1:]):
            figures[k].append(float(value))
    return found


def variant_matches(path, pattern):
    """(variant, match) for each line of a GPU record that pattern finds:
    the variant is NAME under a part "== source-NAME", else None."""
    for header, lines in file_parts(path).items():
        variant = header[len("source-"):] if header.startswith("source-") else None
        for m in filter(None, map(pattern.search, lines)):
            yield variant, m


def spread(values, form="%.2f"):
    """min–max of the values, one value where they are one."""
    if not values:
        return "–"
    low, high = form % min(values), form % max(values)
    return low if low == high else low + "–" + high


def _h200(ctx):
    """The earlier H200 calls' rounds and variants, from their files."""
    bench = ctx.gpu_file(H200_BENCH_FILE)
    if not bench:
        return []
    runs = summary_figures(bench)
    ten, hundred = (runs[(None, n)] for n in (10000000, 100000000))
    text = ("**Earlier runs on the H200** (the twenty-seventh session's calls, c6857bf's engine, [gpu/%s](gpu/%s)): "
            "over %d runs of the benchmark the device phases at 10 M points took %s ms and the sort %s, so the build "
            "read %s times the sort (%s at 100 M points); the whole call %s times the pinned copy at 10 M points "
            "and %s at 100 M." % (
                H200_BENCH_FILE, H200_BENCH_FILE, len(ten["ratio"]), spread(ten["phases"], "%.3f"),
                spread(ten["floor"], "%.3f"), spread(ten["ratio"]), spread(hundred["ratio"]), spread(ten["call"]),
                spread(hundred["call"])))
    for name, main_parts, variant_parts, tried in H200_VARIANTS:
        path = ctx.gpu_file(name)
        if not path:
            continue
        rounds = summary_figures(path)
        main, other = ({k: sum((rounds[(p, 10000000)][k] for p in parts), []) for k in SUMMARY_FIGURES}
                       for parts in (main_parts, variant_parts))
        text += (" Built beside main and run in turn there, %s: at 10 M points the device phases %s ms against "
                 "%s, %s times the sort against %s, the whole call %s times the pinned copy against %s; not kept "
                 "([gpu/%s](gpu/%s))." % (
                     tried, spread(other["phases"], "%.3f"), spread(main["phases"], "%.3f"), spread(other["ratio"]),
                     spread(main["ratio"]), spread(other["call"]), spread(main["call"]), name, name))
    return [text, ""]


# The thirty-fourth session's change on the H200 (COMMAND.md): the leaf and
# inner loops of clouds of the lean attributes compiled for those alone,
# built beside the engine before and run in turn ("main" against "before"
# in call 3; "set3" and "set3o8" against "before-call2" in call 2), with
# ncu's steps of a 10 M-point build ("call 3: ncu, main" against call 1's
# "colour-scalar", whose leaves ran the engine before's general loop, and
# "occ8", that general loop at eight blocks).
LEAN_FILE = "variants-lean-loops.txt"
LEAN_STEPS = {"lean": "call 3: ncu, main: steps of the last of two 10 M-point builds",
              "before": "call 1: ncu, colour-scalar: steps of the last of two 10 M-point builds (its leaves: "
                        "ReduceLeaves<63>, the general loop)",
              "occ8": "call 1: ncu, occ8: steps of the last of two 10 M-point builds"}


def _lean_loops(ctx):
    """The lean loops, from their H200 file."""
    path = ctx.gpu_file(LEAN_FILE)
    if not path:
        return []
    rounds = summary_figures(path)
    at = lambda variant, n, figure, form="%.2f": spread(rounds[(variant, n)][figure], form)
    parts = file_parts(path)
    us = {(k, step): t for k, header in LEAN_STEPS.items() for step, t in build_steps(parts.get(header, []))}
    text = ("**The lean loops** (the thirty-fourth session, on the H200, kept in 4881ff3): the leaf loop keeps the sum "
            "of every slot its points may have in registers through its loop, and where every attribute may be "
            "present that is ten doubles and four 64-bit words, 60 registers on sm_90, four blocks a multiprocessor. "
            "The loops of clouds of 8-bit colours, scalars and reflectivity alone (OctreeKernels.h's "
            "kLeanAttributes, most scanned and simulated clouds, the benchmark's among them) are compiled for "
            "those alone (OctreeDriver.h's ReduceNodes) and ask for eight blocks a multiprocessor "
            "(Config.h's Occupying): the leaf loop holds 32 registers so, 12 bytes spilled, the inner one 32. "
            "Built beside fd530d0's engine and run in turn, three rounds, the device phases at 10 M points took %s ms "
            "against %s, %s times the sort against %s, and at 100 M %s against %s times; the whole call %s times the "
            "pinned copy at 10 M points against %s. In ncu at 10 M points the leaves took %.1f µs against %.1f, "
            "level 9 %.1f against %.1f, the device phases by step %.1f against %.1f. At six blocks (39 registers) "
            "the device phases took %s ms, at eight %s, against %s in that call; the general loop forced to eight "
            "blocks spilled 152 bytes a thread and took the leaves to %.1f µs ([gpu/%s](gpu/%s)). Clouds with float "
            "colours, normals or refraction keep the general loops." % (
                at("main", 10000000, "phases", "%.3f"), at("before", 10000000, "phases", "%.3f"),
                at("main", 10000000, "ratio"), at("before", 10000000, "ratio"),
                at("main", 100000000, "ratio"), at("before", 100000000, "ratio"),
                at("main", 10000000, "call"), at("before", 10000000, "call"),
                us["lean", "leaves (level 10)"], us["before", "leaves (level 10)"],
                us["lean", "level 9"], us["before", "level 9"],
                us["lean", "device phases (keys, sort, level sizes, levels)"],
                us["before", "device phases (keys, sort, level sizes, levels)"],
                at("set3", 10000000, "phases", "%.3f"), at("set3o8", 10000000, "phases", "%.3f"),
                at("before-call2", 10000000, "phases", "%.3f"), us["occ8", "leaves (level 10)"], LEAN_FILE, LEAN_FILE))
    return [text, ""]


# The thirty-fifth session's change on the H200 (COMMAND.md): a staged
# build's leaf loop reading the records through the sorted indices
# ("direct") against the gather in sorted order first ("main"), built side
# by side and run in turn, with ncu's steps of a 10 M and a 100 M-point
# build of each.
DIRECT_FILE = "variants-direct-records.txt"
DIRECT_STEPS = "ncu, %s: steps of the last of two %d M-point builds"


def _direct_records(ctx):
    """The staged build's records read through the indices, from their H200
    file."""
    path = ctx.gpu_file(DIRECT_FILE)
    if not path:
        return []
    rounds = summary_figures(path)
    at = lambda variant, n: ", ".join("%.2f" % r for r in rounds[(variant, n)]["call"])
    parts = file_parts(path)
    us = {(v, m, step): t for v in ("main", "direct") for m in (10, 100)
          for step, t in build_steps(parts.get(DIRECT_STEPS % (v, m), []))}
    text = ("**The records read through the indices** (the thirty-fifth session, on the H200, kept in b422446): a "
            "build from host arrays sorts the positions' keys with their indices while the attributes are still on "
            "their way, and after the copy gathered the records in sorted order, a random read a point, for a leaf "
            "loop that read them in order. The leaf loop now reads them through the indices itself "
            "(OctreeKernels.h's SortedKeys), eight blocks a multiprocessor waiting on those reads as the gather's "
            "threads did. In ncu the leaves took %.1f µs at 10 M points where the gather and the leaves took "
            "%.1f + %.1f, and %.2f ms at 100 M where they took %.2f + %.2f. Built beside 607a057's engine and run "
            "in turn, three rounds, the whole call took %s times the pinned copy at 10 M points against %s (the "
            "engine before's first round was the freshly started machine's first build), and %s at 100 M against "
            "%s ([gpu/%s](gpu/%s)). A build from device arrays, whose records travel with the keys, runs as "
            "before." % (
                us["direct", 10, "leaves (level 10)"], us["main", 10, "records gathered in sorted order"],
                us["main", 10, "leaves (level 10)"], us["direct", 100, "leaves (level 10)"] / 1e3,
                us["main", 100, "records gathered in sorted order"] / 1e3, us["main", 100, "leaves (level 10)"] / 1e3,
                at("direct", 10000000), at("main", 10000000), at("direct", 100000000), at("main", 100000000),
                DIRECT_FILE, DIRECT_FILE))
    return [text, ""]


# The thirty-sixth session's measurement on the H200 (COMMAND.md): the build
# benchmark's cloud in spatial order beside its random order, run in turn.
SPATIAL_FILE = "variants-spatial-order.txt"


def _spatial_order(ctx):
    """The whole call and the levels after the copy with the cloud in
    spatial order, from their H200 file."""
    path = ctx.gpu_file(SPATIAL_FILE)
    if not path:
        return []
    rounds = summary_figures(path)
    pattern = re.compile(r"^build n=(\d+) depth=10: .*?\(upload [0-9.]+, keys [0-9.]+, sort [0-9.]+, levels ([0-9.]+) ms;")
    levels = collections.defaultdict(list)
    for variant, m in variant_matches(path, pattern):
        levels[(variant, int(m.group(1)))].append(float(m.group(2)))
    call = lambda variant, n: spread(rounds[(variant, n)]["call"])
    ms = lambda variant, n: spread(levels[(variant, n)]) + " ms"
    text = ("**The cloud's order** (the thirty-sixth session, on the H200): the benchmark's clusters come in random "
            "order, so that a staged build's leaf loop reads each point's record at a random place. The same cloud "
            "put in the order of its points' Morton keys, as a scan that sweeps space arrives, was built beside it "
            "in turn, two rounds: the levels after the copy took %s at 10 M points against %s, and %s at 100 M "
            "against %s; the whole call took %s times the pinned copy at 10 M points against %s, and %s at 100 M "
            "against %s ([gpu/%s](gpu/%s)). The benchmark's random order is the worst case for those reads; what "
            "is left in spatial order is mostly the staged copy itself. Builds from device arrays, whose records "
            "travel with the keys, take the same time in both orders." % (
                ms("spatial", 10000000), ms("main", 10000000), ms("spatial", 100000000), ms("main", 100000000),
                call("spatial", 10000000), call("main", 10000000), call("spatial", 100000000),
                call("main", 100000000), SPATIAL_FILE, SPATIAL_FILE))
    return [text, ""]


# The twenty-eighth session's change on the H200 (COMMAND.md): the keys and
# the sort during the attributes' upload, built beside the engine before and
# run in turn in calls 2 and 3 (variants "main-79d9b9f" and "before-call2",
# "main" and "before"), and the benchmark of the engine kept.
OVERLAP_VARIANTS_FILE = "variants-sort-during-upload.txt"
OVERLAP_BENCH_FILE = "bench-h200-sort-during-upload.txt"


def _sort_during_upload(ctx):
    """The keys and the sort during the upload, from their H200 files."""
    variants, bench = ctx.gpu_file(OVERLAP_VARIANTS_FILE), ctx.gpu_file(OVERLAP_BENCH_FILE)
    if not variants or not bench:
        return []
    rounds = summary_figures(variants)
    at = lambda variants, n, figure: sum((rounds[(v, n)][figure] for v in variants), [])
    kept, before = ("main-79d9b9f", "main"), ("before-call2", "before")
    runs = summary_figures(bench)
    ten, hundred = (runs[(None, n)] for n in (10000000, 100000000))
    text = ("**The keys and the sort during the upload** (the twenty-eighth session, on the H200, kept in 022a550): "
            "where a build's attributes are still on their way once its positions have landed (the staged copy of "
            "host arrays of 1 MB and more, the positions first), the cube's check, the keys, the sort of the "
            "positions with their indices and the levels' run starts are queued then, from the staging thread that "
            "queued the positions' last piece (CudaUpload.h's afterFirst), and run during the rest of the copy; "
            "after it the records are gathered in sorted order, a random read a point (OctreeDriver.h's "
            "GatherSortedRecords: 249 µs at 10 M points in ncu, 3.27 ms at 100 M; since b422446 the leaf loop reads "
            "them through the indices instead). Built beside 823848b's engine "
            "and run in turn in two calls, the whole call took %s times the pinned copy at 10 M points against %s, "
            "and %s at 100 M against %s ([gpu/%s](gpu/%s)). Builds from device arrays, page-locked ones and the CPU "
            "sort after the copy with the records travelling, as before: from device arrays the device phases "
            "read %s times the sort at 10 M points against %s. From host arrays the keys and the sort now share "
            "the device with the staged copy and take longer (0.13–0.18 and 0.85–0.95 ms at 10 M points against "
            "0.06 and 0.57), out of the whole call's way; the benchmark gives both since, and the ratio to the sort "
            "reads the builds from device arrays. The benchmark of the kept engine there "
            "([gpu/%s](gpu/%s)): the whole call %s times the pinned copy at 10 M points and %s at 100 M, the build "
            "%s times the sort at 10 M points and %s at 100 M." % (
                spread(at(kept, 10000000, "call")), spread(at(before, 10000000, "call")),
                spread(at(kept, 100000000, "call")), spread(at(before, 100000000, "call")),
                OVERLAP_VARIANTS_FILE, OVERLAP_VARIANTS_FILE,
                spread(at(("main",), 10000000, "ratio")), spread(at(("before",), 10000000, "ratio")),
                OVERLAP_BENCH_FILE, OVERLAP_BENCH_FILE, spread(ten["call"]), spread(hundred["call"]),
                spread(ten["ratio"]), spread(hundred["ratio"])))
    return [text, ""]


# The thirtieth session's staging pieces on the H200 (COMMAND.md): piece
# sizes and the pieces without their shrinking, each built beside the
# engine before and run in turn (variants "piece1m" against "before-call1",
# "flat8" and "flat-call2" against "before-call2", "main-call3" against
# "before"), and the kept engine in a call of its own ("main").
PIECES_FILE = "variants-staging-pieces.txt"


def staged_copy_alone(path):
    """{(variant, n): [ms]} of the benchmark's "the engine's staged copy
    alone" in a GPU record, by variant (variant_matches)."""
    pattern = re.compile(r"upload of (\d+) points' .* the engine's staged copy alone ([0-9.]+) ms")
    found = {}
    for variant, m in variant_matches(path, pattern):
        found.setdefault((variant, int(m.group(1))), []).append(float(m.group(2)))
    return found


# The pieces the staging cut at 100 M points with 1 MB buffers and with
# 4 MB ones, as variants-staging-pieces.txt's header gives them.
PIECES_1MB, PIECES_4MB = 1848, 554


def _staging_pieces(ctx):
    """Fewer staging pieces, from their H200 file."""
    path = ctx.gpu_file(PIECES_FILE)
    if not path:
        return []
    rounds, alone = summary_figures(path), staged_copy_alone(path)
    call = lambda variants, n: sum((rounds[(v, n)]["call"] for v in variants), [])
    copy = lambda variants, n: sum((alone.get((v, n), []) for v in variants), [])
    kept, before = ("flat-call2", "main-call3"), ("before-call2", "before")
    one_mb, four_mb = copy(("piece1m",), 100000000), copy(("before-call1",), 100000000)
    mean = lambda values: sum(values) / len(values)
    per_piece = 1e3 * (mean(one_mb) - mean(four_mb)) / (PIECES_1MB - PIECES_4MB) if one_mb and four_mb else None
    text = ("**Fewer staging pieces** (the thirtieth session, on the H200, kept in e3412b8): each piece of the "
            "staged copy costs the copy time beyond its bytes. With 1 MB page-locked buffers where there are 4 MB, "
            "%d pieces at 100 M points where %d were cut, the engine's staged copy alone took %s ms against %s "
            "(about %s µs a piece); with 8 MB buffers (256 MB pinned) it was slower too, %s ms. Since e3412b8 the "
            "pieces grow from 0.5 MB as before but no longer shrink toward the run's end, which was to keep the "
            "copy engine's last pieces short: the threads mostly wait for the copy engine, not it for them, so it "
            "still has pieces queued when they take their last ones (StagingPieces.h's PieceBytes; 81 pieces at "
            "10 M points where 147 were cut). Built beside the engine before and run in turn in two calls, the whole "
            "call took %s times the pinned copy at 10 M points against %s, and the staged copy alone %s ms "
            "against %s; at 100 M points %s against %s. In a later call the kept engine read %s at 10 M points "
            "and %s at 100 M ([gpu/%s](gpu/%s))." % (
                PIECES_1MB, PIECES_4MB, spread(one_mb, "%.1f"), spread(four_mb, "%.1f"),
                "%.1f" % per_piece if per_piece else "–", spread(copy(("flat8",), 100000000), "%.1f"),
                spread(call(kept, 10000000)), spread(call(before, 10000000)),
                spread(copy(kept, 10000000), "%.2f"), spread(copy(before, 10000000), "%.2f"),
                spread(call(kept, 100000000)), spread(call(before, 100000000)),
                spread(call(("main",), 10000000)), spread(call(("main",), 100000000)), PIECES_FILE, PIECES_FILE))
    return [text + _dma_pieces(ctx, per_piece), ""]


# The thirty-ninth session's probe of ways around the staging
# (scripts/gpu/pageable-access.cu): its first line says whether the device
# reads pageable memory itself; then lines "huge|register  register R ms,
# copy C ms, unregister U ms" per size, the first size 190 MB.
PAGEABLE_FILE = "pageable-access.txt"


def _page_locking(ctx):
    """What page-locking a caller's array in place costs beside its copy,
    from the H200 probe, for the "Where the whole call goes" paragraph."""
    path = ctx.gpu_file(PAGEABLE_FILE)
    if not path:
        return ""
    lines = open(path).read().splitlines()
    pattern = re.compile(r"^(register|huge) +register ([0-9.]+) ms, copy ([0-9.]+) ms, unregister ([0-9.]+) ms")
    first = {}
    for m in filter(None, map(pattern.search, lines)):
        first.setdefault(m.group(1), [float(x) for x in m.group(2, 3, 4)])
    if len(first) < 2 or not any(line.startswith("pageable memory access 0") for line in lines):
        return ""
    return (" (on an H200 the register and the unregister of 190 MB took %.1f and %.1f ms around its %.1f ms "
            "copy, the register %.1f ms on an array of 2 MB pages; that device cannot read pageable memory itself: "
            "[gpu/%s](gpu/%s))" % (first["register"][0], first["register"][2], first["register"][1],
                                   first["huge"][0], PAGEABLE_FILE, PAGEABLE_FILE))


# The thirty-first session's copies from page-locked memory alone, whole
# and in pieces (scripts/gpu/pinned-pieces.cu, three runs): lines
# "pieces of K kB on S stream(s): ..., U us a piece beyond the whole".
DMA_PIECES_FILE = "pinned-pieces.txt"


def _dma_pieces(ctx, per_piece):
    """What a piece costs the copy engine alone, from its H200 file, of the
    `per_piece` µs a staged piece costs."""
    path = ctx.gpu_file(DMA_PIECES_FILE)
    if not path:
        return ""
    pattern = re.compile(r"pieces of +\d+ kB on +(\d+) stream\(s\): .*, ([0-9.]+) us a piece beyond the whole")
    us = {}
    for _, m in variant_matches(path, pattern):  # under the parts "== run N"
        us.setdefault(int(m.group(1)), []).append(float(m.group(2)))
    return (" Of the %s µs, the copy engine takes about half or more by itself: copies from page-locked memory "
            "alone, with no host copy beside them, cost %s µs a piece beyond the whole copy on one stream and %s "
            "over 16 streams, pieces of 256 kB to 8 MB of 190 MiB and 1900 MiB (the thirty-first session, "
            "scripts/gpu/pinned-pieces.cu, [gpu/%s](gpu/%s)); the rest comes with the staging threads' copies."
            % ("%.1f" % per_piece if per_piece else "–", spread(us.get(1, []), "%.1f"), spread(us.get(16, []), "%.1f"),
               DMA_PIECES_FILE, DMA_PIECES_FILE))


# The thirty-second session's pool of the engine's kind, its memory mapped,
# reused and trimmed (scripts/gpu/pool-regrowth.cu, calls 4 and 5): lines
# "... mapping costs M ms a GB; the trim that gives it back T ms (U ms a GB)".
POOL_FILE = "pool-regrowth.txt"


def _lean_builds(ctx, builds, mem_records):
    """What a build without the points pays for giving its memory back,
    from the pool's H200 file and this run's builds at depth 10."""
    path = ctx.gpu_file(POOL_FILE)
    if not path:
        return []
    pattern = re.compile(r"mapping costs ([0-9.]+) ms a GB; the trim that gives it back [0-9.]+ ms \(([0-9.]+) ms a GB")
    per_gb = [float(m.group(1)) + float(m.group(2)) for _, m in variant_matches(path, pattern)]
    if not per_gb:
        return []
    cases = []
    for r in builds:
        arrays = mem_records.get((r["n"], r["depth"]), {}).get("array_bytes_per_point")
        if r["depth"] == 10 and r["n"] >= 10000000 and arrays and r.get("lean_seconds"):
            gb = arrays * r["n"] / 1e9
            cases.append("%s points: %s against %s with the points kept, %.1f ms more, where the %.1f GB of arrays "
                         "the build with its points holds would cost %.1f–%.1f ms" % (
                             count(r["n"]), seconds(r["lean_seconds"]), seconds(r["seconds"]),
                             1e3 * (r["lean_seconds"] - r["seconds"]), gb, gb * min(per_gb), gb * max(per_gb)))
    if not cases:
        return []
    return [
        "**A build without the points** (`BuildOptions::keepPoints` off, as ParaView's representation builds) "
        "gives the allocator's memory back after it (Device::TrimCache), so that a static scene holds its nodes "
        "alone, and the next build maps that memory again. In a pool made as the engine makes it, mapping new "
        "memory costs beyond reusing it, plus the trim that gives it back, %s ms a GB (the thirty-second session, "
        "scripts/gpu/pool-regrowth.cu, [gpu/%s](gpu/%s)). In this run, %s. Keeping the memory would spend the "
        "memory goal." % (spread(per_gb), POOL_FILE, POOL_FILE, "; ".join(cases)),
        "",
    ]


STEPS_FILE = "profile-build-10m.txt"


def build_steps(lines):
    """(step, microseconds) per line of ncu-kernel-times.py --steps."""
    pattern = re.compile(r"^\s+([0-9.]+) us\s+(?:\d+x(?:\s+[0-9.]+ GB\s+[0-9.]+ TB/s)?)?\s+(.*)$")
    return [(m.group(2), float(m.group(1))) for m in map(pattern.match, lines) if m]


def _host_floor_at_10m(builds):
    """This run's lowest staged upload at 10 M points, the host's half of
    the staging and the pinned copy at once, against the pinned copy."""
    r = next((r for r in builds if r["n"] == 10000000 and r["depth"] == 10
              and r.get("host_staging_beside_copy_seconds")), None)
    if not r:
        return ""
    phases = device_phases(r)
    return (" In this report's run, at 10 M points, the host's half alone took %s, and with the pinned copy at once "
            "%s: %.2f times the pinned copy (%s), the lowest a staged upload could reach on this run's host "
            "(2.2–3.6 ms for the host's half, about 1.1 times for both at once, in the one pass's first calls). "
            "With the device phases after it (%s), a whole call could reach %.2f times there, against the goal's %g."
            % (seconds(r["host_staging_copy_seconds"]), seconds(r["host_staging_beside_copy_seconds"]),
               r["host_staging_beside_copy_seconds"] / r["pinned_upload_seconds"], seconds(r["pinned_upload_seconds"]),
               seconds(phases), (r["host_staging_beside_copy_seconds"] + phases) / r["pinned_upload_seconds"],
               GOAL_CALL_OVER_COPY))


def _steps_at_10m(ctx):
    """Where the device phases go at 10 M points, from ncu: the table and
    what it says of the goal (the phases within twice the sort)."""
    path = ctx.gpu_file(STEPS_FILE)
    if not path:
        return []
    with open(path) as f:
        lines = f.read().rstrip("\n").split("\n")
    steps = build_steps(lines[1:])  # under the title line
    table = "\n".join(lines[1:])
    us = dict(steps)
    # "levels near the root (one launch)" since 9c054dd: ncu-kernel-times.py's SMALL_LEVELS.
    levels = [(name, t) for name, t in steps if name.startswith(("leaves", "level ", "levels near"))]
    big, small = levels[:3], levels[3:]
    level_us = sum(t for _, t in levels)
    apart = [name for name, _ in small if name.startswith("level ")]
    launches = ("%d levels of one launch each" % len(apart) +
                (", the rest in one launch" if len(apart) < len(small) else ""))
    # The steps before the levels: the level sizes counted (the histogram before cd56a2a) and the
    # levels' run starts placed (ncu-kernel-times.py's STEPS).
    runs_us = sum(t for name, t in steps if name.startswith(("levels' run starts", "histogram")))
    return [
        "At 10 M points, where the device phases are furthest from the sort, Nsight Compute times each kernel of "
        "the second of two builds, summed here by step (gpu-check.sh's profile-build part, "
        "`ncu-kernel-times.py --steps`; %s). ncu runs the kernels one at a time with the caches flushed before "
        "each, so the small ones take longer than in a build, and the bounds' kernels, which run beside the "
        "copies, do not add up:" % gpu_source(ctx, STEPS_FILE),
        "",
        "```",
        table,
        "```",
        "",
        "The levels' run starts, counted with the level sizes and placed, take %.0f µs, and the levels' loops "
        "%.0f µs of the phases' %.0f, against the sort's %.0f: the leaves and the two levels above them %.0f µs, "
        "the levels nearer the root %.0f µs: %s. Within twice the sort, the keys, the run starts and the levels "
        "together would have to take no longer than the sort (here %.0f µs)." % (
            runs_us, level_us, us.get("device phases (keys, sort, level sizes, levels)", float("nan")),
            us.get("sort (CUB)", float("nan")), sum(t for _, t in big), sum(t for _, t in small), launches,
            us.get("keys", 0) + runs_us + level_us),
        "",
    ]


def gpu_records(ctx, name):
    path = ctx.gpu_file(name)
    return load_records(path) if path else None


def gpu_source(ctx, name):
    """Where a GPU table's figures came from, for the text."""
    made = ("made by the command in [gpu/COMMAND.md](gpu/COMMAND.md)" if ctx.gpu_command() else
            "made by scripts/gpu/gpu-check.sh on a GPU machine")
    return "[gpu/%s](gpu/%s), %s" % (name, name, made)


# ---------------------------------------------------------------- produce

def produce(ctx):
    record_machine(ctx, "build", "start")
    ctx.run("build-peers", [os.path.join(ctx.bin, "octoray_bench_peers"), "--cases", PEER_CASES,
                            "--repeats", PEER_REPEATS, "--octree-locator-max", OCTREE_LOCATOR_MAX,
                            "--json", fresh(ctx.work_path("build-peers.json"))])
    ctx.run("build-engine", [os.path.join(ctx.bin, "octoray_bench_build"), "--points", BUILD_POINTS,
                             "--sets", "uniform,clustered", "--backend", "cpu", "--repeats", BUILD_REPEATS,
                             "--json", fresh(ctx.work_path("build-engine.json"))])
    ct = scenes.ct_particles(ctx)
    ctx.run("build-quantisation", [os.path.join(ctx.bin, "octoray_bench_quantisation"), "--backend", "cpu",
                                   "--ct", ct, "--json", fresh(ctx.work_path("build-quantisation.json"))])
    record_machine(ctx, "build", "end")


# ---------------------------------------------------------------- render

def _peers(ctx, figures):
    records = load_records(ctx.work_path("build-peers.json"))
    if not records:
        return "No peer records (run `make report --only build`).\n", [], None
    cases = []
    for r in records:
        key = (r["name"].split("/")[-1], r["n"])
        if key not in cases:
            cases.append(key)

    def find(peer, s, n, backend):
        for r in records:
            if r["peer"] == peer and r["name"].endswith("/" + s) and r["n"] == n and r["backend"] == backend:
                return r
        return None

    rows, csv_rows, summary, plot = [], [], [], []
    for s, n in cases:
        pcl = find(PCL, s, n, "cpu-1thread")
        octl = find(OCTREE_LOCATOR, s, n, "cpu-1thread")
        st1 = find(STATIC_LOCATOR, s, n, "cpu-1thread")
        threads = sorted({r["backend"] for r in records if r["backend"] != "cpu-1thread"})
        stN = find(STATIC_LOCATOR, s, n, threads[0]) if threads else None
        one = pcl["seconds"]
        many = stN["seconds"] if stN else None
        pcl_cell = "%s (%s)" % (seconds(pcl["peer_seconds"]), "same tree" if pcl.get("same_tree") else "DIFFERENT TREE")
        # The paired ratio (each PCL build against an octoray build right
        # after it) when the run has it: robust to the load drifting.
        pcl_ratio = pcl.get("paired_ratio") or pcl["peer_seconds"] / one
        row = ["%s %s" % (s, count(n)), pcl["depth"], count(pcl["leaves"]), seconds(one), seconds(many) if many else "–",
               pcl_cell, "**%.1f×**" % pcl_ratio]
        if octl:
            row += ["%s (%s leaves)" % (seconds(octl["peer_seconds"]), count(octl["peer_leaves"])),
                    "%.1f×" % (octl["peer_seconds"] / one)]
        else:
            row += ["left out (time budget)", "–"]
        if st1 and stN:
            row += ["%s / %s" % (seconds(st1["peer_seconds"]), seconds(stN["peer_seconds"])),
                    "%.1f× / %.1f×" % (st1["peer_seconds"] / st1["seconds"], stN["peer_seconds"] / stN["seconds"])]
        rows.append(row)
        csv_rows.append([s, n, pcl["depth"], pcl["leaves"], one, many, pcl["peer_seconds"], pcl_ratio,
                         pcl.get("same_tree"),
                         octl["peer_seconds"] if octl else "", st1["peer_seconds"] if st1 else "",
                         stN["peer_seconds"] if stN else ""])
        plot.append(("%s\n%s" % (s, count(n)), one, many, pcl["peer_seconds"],
                     octl["peer_seconds"] if octl else None, st1["peer_seconds"] if st1 else None,
                     stN["peer_seconds"] if stN else None))
        if s == "uniform" and n == 10000000:
            summary.append(("octree build, 10 M points, 1 CPU thread", seconds(one), "PCL octree " +
                            seconds(pcl["peer_seconds"]), "%.1f×" % pcl_ratio))
    csv = ctx.write_csv("build-peers", ["set", "points", "depth", "leaves", "octoray_1thread_s", "octoray_threads_s",
                                        "pcl_s", "pcl_ratio_paired", "pcl_same_tree", "vtkOctreePointLocator_s",
                                        "vtkStaticPointLocator_1thread_s", "vtkStaticPointLocator_threads_s"], csv_rows)
    nthreads = threads[0].split("-")[1].replace("threads", "") if threads else "?"
    header = ["set, points", "depth", "leaves", "octoray 1 thr", "octoray %s thr" % nthreads, "PCL PointVector",
              "ratio (1 thr)", "vtkOctreePointLocator", "ratio", "vtkStaticPointLocator 1 / %s thr" % nthreads,
              "ratio 1 / %s thr" % nthreads]
    png, link = figures
    _plot_peers(png, plot, nthreads)
    text = ctx.table(header, rows) + "\n\n[CSV](%s) · ![build times](%s)\n" % (csv, link)
    return text, summary, records


def _plot_peers(png, plot, nthreads):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    labels = [p[0] for p in plot]
    series = [("octoray 1 thread", 1, "#1f77b4"), ("octoray %s threads" % nthreads, 2, "#6baed6"),
              ("PCL OctreePointCloudPointVector", 3, "#d62728"), ("vtkOctreePointLocator", 4, "#ff7f0e"),
              ("vtkStaticPointLocator 1 thread", 5, "#2ca02c"),
              ("vtkStaticPointLocator %s threads" % nthreads, 6, "#98df8a")]
    x = np.arange(len(plot))
    width = 0.8 / len(series)
    fig, ax = plt.subplots(figsize=(8, 4.8))
    for k, (name, i, colour) in enumerate(series):
        values = [p[i] if p[i] else np.nan for p in plot]
        ax.bar(x + (k - len(series) / 2 + 0.5) * width, values, width, label=name, color=colour)
    ax.set_xticks(x)
    ax.set_xticklabels(labels)
    ax.set_yscale("log")
    ax.set_ylabel("build time, s (log)")
    ax.set_title("Octree / locator build from the same points, one run (median)")
    ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.14))
    ax.grid(axis="y", which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def _engine(ctx):
    records = load_records(ctx.work_path("build-engine.json"))
    if not records:
        return "No engine build records.\n", "No memory records.\n"
    rows, mem_rows, csv_rows = [], [], []
    seen = set()
    for r in records:
        s = r["name"].split("/")[-1]
        threads = r["backend"].split("-")[1].replace("threads", "").replace("thread", "")
        rows.append([count(r["n"]), s, threads, r["depth"], count(r["nodes"]), "%.3f" % r["seconds"],
                     "%.3f" % r["min_seconds"], "%.1f" % (r["n"] / r["seconds"] / 1e6),
                     "%.3f / %.3f / %.3f" % (r["key_seconds"], r["sort_seconds"], r["level_seconds"])])
        csv_rows.append([r["n"], s, threads, r["depth"], r["leaves"], r["nodes"], r["seconds"], r["min_seconds"],
                         r["key_seconds"], r["sort_seconds"], r["level_seconds"], r["engine_bytes"], r["node_bytes"],
                         r["dense_skeleton_bytes"]])
        if (s, r["n"]) not in seen:
            seen.add((s, r["n"]))
            mem_rows.append(["%s %s" % (s, count(r["n"])), r["depth"], "%.1f" % (r["engine_bytes"] / r["n"]),
                             human_bytes(r["engine_bytes"]), "%.1f" % (r["node_bytes"] / r["n"]),
                             human_bytes(r["dense_skeleton_bytes"])])
    csv = ctx.write_csv("build-engine", ["points", "set", "threads", "depth", "leaves", "nodes", "median_s", "min_s",
                                         "keys_s", "sort_s", "levels_s", "engine_bytes", "node_bytes",
                                         "dense_skeleton_bytes"], csv_rows)
    engine = ctx.table(["points", "set", "threads", "depth", "nodes", "median s", "min s", "Mpts/s",
                        "keys / sort / levels s"], rows, "rlrrrrrrr") + "\n\n[CSV](%s)\n" % csv
    memory = ctx.table(["set, points", "depth", "octoray B/point", "octoray total", "node arrays B/point",
                        "dense skeleton"], mem_rows)
    return engine, memory


def _cuda(ctx):
    name = "bench-results-cuda.json"
    records = gpu_records(ctx, name)
    if records is None:
        return "CUDA build, update and memory: " + NOT_ON_GPU + ".\n", []
    builds = [r for r in records if r["name"] == "octree build"]
    mem_records = {(r["n"], r["depth"]): r for r in records if r["name"] == "gpu bytes per point"}
    mem = {key: r["seconds"] for key, r in mem_records.items()}
    # Runs since the report exist record the device phases (BuildStats) too.
    phases = all("sort_seconds" in r for r in builds)
    # And since issue 16, the pinned host-to-device copy of the same input.
    upload = all(r.get("pinned_upload_seconds") for r in builds)
    # And since the pinned staging: the upload's own time beside the plain
    # and registered copies, and the memory with and without kept points.
    staging = all("pageable_upload_seconds" in r for r in builds)
    # And since the staging's threads were kept: the host's half of the
    # staging alone, the caller's arrays copied into page-locked memory.
    host_copy = all(r.get("host_staging_copy_seconds") for r in builds)
    # And since the one pass: that half at once with the pinned copy, and
    # the engine's staged copy alone.
    one_pass = all(r.get("staged_copy_seconds") for r in builds)
    # And since the records travel with the keys: CUB's sort of what the
    # build sorts at depth 10 and less, 32-bit keys with 8-byte records (0
    # deeper, where it sorts the floor's pairs).
    own = any(r.get("build_sort_seconds") for r in builds)
    # And since 7ad2508: how many builds went before the timed ones (one
    # before it), which let the engine's memory pool settle.
    warm_ups = int(builds[0].get("warm_up_builds", 1)) if builds else 1
    warm_up_text = "one warm-up build" if warm_ups == 1 else "%d warm-up builds" % warm_ups
    rows, csv_rows, staging_rows = [], [], []
    for r in builds:
        if staging:
            m = mem_records.get((r["n"], r["depth"]), {})
            staging_rows.append([count(r["n"]), r["depth"], seconds(r["upload_seconds"]),
                                 seconds(r["pageable_upload_seconds"]), seconds(r["registered_upload_seconds"]),
                                 seconds(r["pinned_upload_seconds"])]
                                + ([seconds(r["host_staging_copy_seconds"])] if host_copy else [])
                                + ([seconds(r["host_staging_beside_copy_seconds"]),
                                    seconds(r["staged_copy_seconds"])] if one_pass else [])
                                + ["%.2f" % (r["upload_seconds"] / r["pinned_upload_seconds"]),
                                   "%.1f" % m.get("array_bytes_per_point", 0), "%.1f" % m.get("seconds", 0),
                                   seconds(r["lean_seconds"]), "%.1f" % m.get("lean_bytes_per_point", 0)])
        row = [count(r["n"]), r["depth"], seconds(r["seconds"])]
        if phases:
            device = device_phases(r)
            row += ["%s (%.2f / %.2f / %.2f)" % (seconds(device), r["key_seconds"] * 1e3, r["sort_seconds"] * 1e3,
                                                 r["level_seconds"] * 1e3)]
        row += [seconds(r["peer_seconds"]), "%.0f" % (r["seconds"] / r["peer_seconds"])]
        if phases:
            row += ["%.1f" % (device / r["peer_seconds"])]
        if own:
            p = r.get("build_sort_seconds")
            row += [seconds(p) if p else "pairs", "%.1f" % (device / p) if p and phases else ""]
        if phases:
            row += [count(r["nodes"])]
        if upload:
            row += [seconds(r["pinned_upload_seconds"]), "%.2f" % call_over_copy(r)]
        row += ["%.0f" % mem.get((r["n"], r["depth"]), 0)]
        rows.append(row)
        csv_rows.append([r["n"], r["depth"], r["seconds"], r["peer_seconds"], mem.get((r["n"], r["depth"])),
                         r.get("key_seconds", ""), r.get("sort_seconds", ""), r.get("level_seconds", ""),
                         r.get("nodes", ""), r.get("build_sort_seconds", "")])
    csv = ctx.write_csv("build-cuda", ["points", "depth", "build_s", "cub_sort_s", "gpu_bytes_per_point",
                                       "keys_s", "sort_s", "levels_s", "nodes", "build_sort_s"], csv_rows)
    header = ["points", "depth", "whole call"] + (["device phases, ms (keys / sort / levels)"] if phases else []) + \
        ["bare CUB sort", "call / sort"] + (["phases / sort"] if phases else []) + \
        (["CUB sort of 32-bit keys with records", "phases / that sort"] if own else []) + \
        (["nodes"] if phases else []) + \
        (["pinned copy of the input", "call / copy"] if upload else []) + ["GPU bytes/point"]
    updates = [r for r in records if r["name"].startswith("update")]
    urows = [[r["name"].split()[1], count(r["n"]), r["depth"], seconds(r["seconds"]), seconds(r["peer_seconds"]),
              "%.2f" % (r["seconds"] / r["peer_seconds"])] for r in updates]
    text = [
        "From %s. Gaussian clusters with colour and reflectivity, float positions. \"Whole call\" is `Engine::Build` "
        "including the upload of the points from the caller's pageable host memory; the floor is a bare "
        "`cub::DeviceRadixSort::SortPairs` of as many 64-bit keys (3·depth bits) with 32-bit indices, timed with CUDA "
        "events in the same run. Medians of 7 builds after %s. The device phases are the device's own time (CUDA "
        "events between "
        "them; the sort's holds the count of the levels' run starts since cd56a2a, at a requested depth, and "
        "their placement since 2dddea0); the attributes' upload goes with the positions'. GPU bytes per point include "
        "the sort buffers the engine keeps for rebuilds and the memory its allocator keeps for the next build (split "
        "in the second table). The pinned copy: the same input arrays as one block of page-locked host memory copied "
        "to the device (cudaMemcpy), what a whole call from host arrays cannot beat, timed after each of the 7 "
        "builds; *call / copy* is the median of those 7 pairs' ratios. At depth 10 and less the leaf keys fit 32 "
        "bits and the build sorts each with its point's record of attributes (here 8 bytes: colour and "
        "reflectivity; records of one or two words travel so, longer ones are gathered by index, "
        "OctreeKernels.h's SortedKeys); *CUB sort of 32-bit keys with records* is that sort of as many random "
        "keys, timed the same way, the same 12 bytes a point and pass as the floor's pairs, and *pairs* marks the "
        "depths whose keys do not fit 32 bits.%s" % (gpu_source(ctx, name), warm_up_text, "" if phases else
                                   " (This run's records predate the device phases; the next GPU run adds them.)"),
        "",
        ctx.table(header, rows),
        "",
        "[CSV](%s)" % csv,
        "",
        "The engine's sort runs at its floor. What separates the whole call from it is the upload of the points "
        "from pageable memory (most of it at 10 M and more); what separates the device phases from it are the "
        "keys, the levels' run starts and the levels: one loop for the leaves and one per level above them "
        "(Benchmarks/gpu/profile-build.txt lists their kernels for 100 M points). Every level's run starts come "
        "from one pass over the sorted points since cd56a2a: a point starts a node at every level from the first "
        "its key does not share with the previous key (DepthChoice.h's FirstNewLevels), so one pass counts each "
        "warp tile's points in each level's list, and the level sizes with them, in place of the histogram of "
        "neighbouring keys at a requested depth; a scan gives each tile its places, and a second pass places them, "
        "the leaves' list first (Device::CountNested and PlaceNested, CudaDevice.h's NestedCountKernel and "
        "NestedPlaceKernel). Each level above the leaves then takes one loop, where a CUB select and a loop took "
        "three launches. Since 2dddea0 the placement runs while the host reads the level sizes and reserves the "
        "node arrays (a queued copy, Device::QueueToHost), in the room the last build left for the inner levels' "
        "lists; placed after that, it had waited 0.04 ms for the host at 10 M points and 0.5 ms at 100 M. Built "
        "beside 18cba2c's engine and run in turn, the device phases at 10 M points took 1.126–1.129 ms against "
        "1.200 (1.98–2.01 times the sort against 2.11), at 1 M 0.257–0.268 against 0.329, and at 100 M 7.66–8.14 "
        "against 7.68, the level phase there still waiting for the host's reservations in some builds; in ncu at "
        "10 M points the count, the scan and the placement took 48 and 72 µs, the levels' loops 390, where the "
        "histogram took 29 µs and the levels with their selects 549 (Benchmarks/gpu/variants-nested-levels.txt). "
        "The placement's pass runs at 1.4 TB/s: each round of 32 points visits the lists from the shallowest that "
        "any of them starts, a ballot each. Nsight Compute finds it waiting on its loads (long-scoreboard stalls, "
        "8.4 of its 17 cycles a warp per issued instruction) at 48 registers, five blocks a multiprocessor. Since "
        "aa8b609 a warp tile holds 8 rounds, not 16, twice as many warps: built beside tiles of 16 and run in turn, "
        "the placement took 56.5 µs at 10 M points in ncu against 72.8 and 389 at 100 M against 536, the count's "
        "scan of twice as many tiles 28 µs more at 100 M, and the device phases by step 1043 µs against 1061 at "
        "10 M, 7420 against 7520 at 100 M (Benchmarks/gpu/variants-nested-tiles.txt). The count took a ballot a "
        "list and a round too, at 0.9 TB/s; since 29cc581 each lane adds its points into 5-bit fields, one a list, "
        "which the warp adds up two lists at a time. Built beside the count "
        "before and run in turn, its kernel took 34 µs at 10 M points in ncu against 40 (its three launches 283 "
        "µs against 298 at 100 M), and the device phases 1.114–1.125 ms against 1.129–1.133 in three rounds; "
        "their ratio to the sort, 1.97–2.00 against 1.94–1.99, moved with the sort's own time, 0.56–0.58 ms "
        "(Benchmarks/gpu/variants-count-fields.txt). The level phase also waited for the host, which reserved the node arrays before "
        "it queued the phase's first kernel: 0.2–0.3 ms at 10 M points while the engine's memory pool grew, over "
        "the first four builds of a size. From 2330cb0 the leaves' select ran on the device meanwhile (the nested "
        "lists replaced the selects since). Since "
        "7ad2508 the benchmark times its builds once the pool has settled. In three rounds of it, the level phase "
        "at 10 M points took 0.62 ms, where its kernels alone take 0.60, and 0.64–0.67 ms for the engine before "
        "(Benchmarks/gpu/variants-levels-order.txt). An inner node's children add up in float since bdad029 (at "
        "most eight terms, the error below 5e-7 a level): the inner levels' loop holds 40 registers where the sums "
        "in double took 56, six blocks a multiprocessor instead of four. Built beside the sums in double and run in "
        "turn, its five kernels took 0.199 ms at 10 M points against 0.243 in ncu (0.527 against 0.625 at 100 M), "
        "and the level phase 0.58 ms against 0.62 (Benchmarks/gpu/variants-inner-float.txt). Since 36ab25e the "
        "engine keeps no keys of the points (8 bytes a point that the keys kernel wrote for updates): a rebuild "
        "or an update computes them again from the positions, and at their depth, the cell's top bits spread in "
        "32-bit arithmetic where they fit (Morton.h's EncodeMortonAt); a build of a requested depth counts the "
        "histogram's level sizes alone (23 bins, where the automatic depth's two histograms take 46); and 8-bit "
        "colours add up as whole bytes, a leaf's in 64-bit integers. Built beside fc8eae0's engine and run in "
        "turn, in ncu the keys kernel took 57 µs at 10 M points against 84 (567 against 835 at 100 M), the "
        "histogram 29 against 40 (218 against 353), the leaves and level 9 1–3 % less, the device phases by step "
        "1129 µs against 1178 (7563 against 8050); in the benchmark the device phases at 10 M points took "
        "1.20–1.21 ms against 1.23–1.25, 2.06–2.20 times the sort against 2.09–2.24 (the sort read 0.55–0.60 ms "
        "in those calls), and 1.66–1.72 times at 100 M against 1.77–1.80 (Benchmarks/gpu/variants-unkept-keys.txt). "
        "With the device held so that the host had queued the whole level phase first, that phase took 0.552 ms at "
        "10 M points against 0.566–0.571: at depth 10 the build is bound by its kernels, not by the gaps between "
        "them; at depth 16 the phase took 2.63–2.65 ms so against 3.05–3.08, the host queueing its 16 levels in "
        "0.7–1.2 ms (Benchmarks/gpu/variants-levels-spin-2.txt). "
        "The levels' selects "
        "were then CUB's DeviceSelect::If, its predicate reading two keys; on the same sorted keys DeviceSelect::"
        "UniqueByKey took 1.45–1.76 times as long, and a select of tiles with a decoupled look-back written for "
        "them 1.06–2.89 times (Benchmarks/gpu/variants-run-starts-select.txt). The thirteenth session's first try of every level's run starts from one pass over the sorted points (a "
        "count pass, a scan and a placing pass after the histogram and the host's reservations; "
        "Benchmarks/gpu/variants-nested.txt, not kept) took 0.07–0.09 ms "
        "off the level phase at 10 M points and added 0.4–0.9 ms at 100 M, its two passes running at 0.8–1.3 TB/s "
        "against 1.4–1.8 for the selects. CUB's sort with 10-bit digits, three passes over the 30-bit keys "
        "instead of four, took 6.51 ms at 100 M points against 4.21 (Benchmarks/gpu/variants-wide-digits.txt, not "
        "kept): each pass scattered a tile over 1024 digits and ran at 1.21 TB/s against 2.29. "
        "The level loops add up only the slots of the attributes present, reading each record and node value a "
        "word at a time (PointArrays.h's ForEachRecordSlot, OctreeKernels.h's ForEachNodeSlot): before 05ba0e7 "
        "each point and child converted all 14 slots to double and added them, absent attributes' zeros too, "
        "and read the record a byte at a time. With the engine before built beside it and run in turn, the leaf "
        "kernel went from 1.63 to 1.32 ms at 100 M points (ncu) and the level phase from 3.68–3.74 to "
        "3.17–3.25 ms, the device phases from 2.04 to 1.92–1.94 times the floor (at 10 M 0.83–0.84 to "
        "0.76–0.78 ms; Benchmarks/gpu/variants-slots.txt). Three other ways with the leaf loop were slower at "
        "100 M points: its records staged a warp at a time in shared memory (4.17 ms: a warp of long leaves "
        "then adds them nearly one after another), the loop unrolled four times (6.40 ms), five blocks a "
        "multiprocessor at 48 registers (4.41 ms; Benchmarks/gpu/variants-leaf-loop.txt, with ncu's SASS "
        "counters of the old loop). On the H200 at 10 M points the leaf loop of 557ad59's engine waits on its "
        "loads (long scoreboard, 63 % of its stalls) at 42 % achieved occupancy and issues on 54 % of its "
        "cycles, about 380 warp instructions a warp of 32 leaves; level 9 alike "
        "(Benchmarks/gpu/profile-build-kernels-10m.txt). "
        "With fewer registers, eight blocks a multiprocessor did help it (**The lean loops**, below). "
        "Neither its leaves reduced in their parents' loop (a thread a parent: 376 µs where the two loops took "
        "265) nor its loads moved before its stores (164.4 µs against 164.0) helped "
        "(Benchmarks/gpu/variants-leaf-parents.txt, variants-loads-first.txt). "
        "The children's attributes behind one test again (05ba0e7 had dropped "
        "d58c257's) took the inner levels' ten kernels from 0.785 to 0.732 ms at 100 M points; the four or five levels near the root in one block of "
        "one launch took 33 µs where their 15 launches took 76, but every select of that build ran slower, and "
        "it was not kept (Benchmarks/gpu/variants-small-levels.txt). "
        "Each level's runs found and reduced in one kernel (a block-wide scan of the run starts with a decoupled "
        "look-back across tiles, then the tile's runs reduced from shared memory), where each level takes a CUB "
        "select and a loop, was slower where the levels are large: at 100 M points its leaf kernel took 2.26 ms in "
        "ncu against 1.60 for the select and the loop, 3.53 ms with tiles half as long; the levels near the root "
        "took 10–12 µs each against 16–17, which left the device phases at 10 M points within their spread "
        "(Benchmarks/gpu/variants-fused-runs.txt, not kept). "
        "The histogram of neighbouring keys compares the sorted leaf keys as the sort left them, in 32-bit "
        "arithmetic where they have 32 bits (DepthChoice.h's SharedLevels at a depth, 0c6e986); before, each "
        "of its three keys a point was shifted to full depth in 64 bits. In ncu the kernel took 325 µs at 100 "
        "M points against 424, and 40 µs at 10 M against 50, where four or eight reads a thread in flight had "
        "made it no faster (Benchmarks/gpu/variants-histogram-32bit.txt, variants-histogram-items.txt). "
        "Since bc58159 the automatic depth has no histogram pass of its own: the count of the levels' run starts "
        "at the sort's depth adds the alone histogram up beside its lists, whose counts are the newNode one "
        "(Device::CountNested's SideHistogram), and a level's run starts, which do not depend on the depth below "
        "it, are placed from those counts once the depth is chosen, where they were counted again at it; since "
        "a44f547 they are placed while the host reserves the node arrays. Built beside 54c04a7's engine and run in "
        "turn (`octoray_bench_build --depth 0 --backend cuda`), the device phases took 0.578–0.586 ms at 10 M "
        "uniform points against 0.594–0.602, 4.30–4.31 ms at 100 M against 4.45–4.47, and 0.8 % longer where the "
        "keys of 10 levels do not settle the depth and are sorted again at full depth (100 M clustered points, "
        "13.58–13.63 ms against 13.46–13.53): there the count of 22 lists with the histogram took 585 µs in ncu "
        "where the histogram alone took 416 (Benchmarks/gpu/variants-auto-depth-count.txt). "
        "Since ba501c9 such a cloud's keys are sorted again at 13 levels first (39 bits: five passes of CUB's 8-bit "
        "digits where full-depth keys take eight) where its level-10 cells hold 64 points or fewer on average, as "
        "a surface's cells split into by then; denser clouds go to full depth at once (DepthChoice.h's "
        "NextSortDepth). Built beside 9fe3050's engine and run in turn, the device phases for 100 M clustered "
        "points took 10.47 ms against 13.52, the whole call 35.7–36.4 ms against 39.0–39.4; clusters a "
        "ten-thousandth of the cube wide (octoray_bench_build's narrow set: depth 17 at 10 M points, 19 at 100 M, "
        "5·10⁴ points a level-10 cell) ran alike, where keys of 16 levels sorted first for every cloud had made "
        "their whole call 16–24 % longer. Sorting the points of each level-10 run alone "
        "(cub::DeviceSegmentedSort, after reading each point's full-depth key through its index) took as long as "
        "the 16-level sort at 100 M clustered points and five to seven times the full-depth sort for the narrow "
        "clusters, "
        "whose runs hold up to 3 M points (Benchmarks/gpu/variants-middle-sort.txt). "
        "Nodes of one point or one child storing its values as they are, without the sums in double, made the "
        "leaf kernel slower: 1.77 ms at 100 M points in ncu against 1.60 "
        "(Benchmarks/gpu/variants-one-value-nodes.txt, not kept). "
        "Since 9c054dd the levels of at most 16384 children (four or five near the root) are reduced together "
        "in one launch of one block (CudaDevice.h's SmallLevelsKernel: each level's run starts by a block-wide "
        "scan, then its nodes), which the fourteenth session's try had left because every select of its build "
        "ran slower; this time they did not, beyond one ncu run's spread. In ncu levels 4 to 0 took 32 µs "
        "where their 15 launches took 82 at 10 M points (79 at 100 M); in the benchmark the level phase at 1 M "
        "points went from 0.226–0.231 to 0.199–0.202 ms (0.194–0.195 without the run-start test written once), "
        "at 10 M from 0.677–0.679 to 0.649 and, in one round, 0.862 ms (0.659), and at 100 M it stayed within "
        "its spread (Benchmarks/gpu/variants-levels-near-root.txt). "
        "Node keys take 4 bytes where every level's fit 32 bits (depth 10 and less; Attributes.h's key and "
        "keyHigh, 7e47113): the level phase writes each once and reads it twice, and with the 64-bit keys before "
        "built beside it and run in turn it went from 3.46–3.67 to 2.89–3.10 ms at 100 M points, the device phases "
        "from 1.99–2.03 to 1.85–1.90 times the floor, and the arrays of every attribute from 15.41 to 13.17 bytes a "
        "point (Benchmarks/gpu/variants-node-keys.txt; at 10 M points that call's host was noisy, and the level "
        "phase, which counts the device waiting for the host, was not faster there; in ncu its kernels took 636 µs "
        "at 7e47113 against 715 at 34ca213: Benchmarks/gpu/profile-build-10m-34ca213.txt). "
        "The positions' bounds, which the keys need, are reduced on the device as the staged copy "
        "lands, and count in the upload. From 064700a each piece of the positions was reduced as it landed, on "
        "the stream that had copied it, where a CUB reduction after the upload had read them again (0.46 ms at "
        "100 M points, when the sort still waited for the whole copy); since a74e097 the positions "
        "are reduced in one loop once they have all landed, while the attributes are still on their way "
        "(Device::StageReduced: one ReduceRangeKernel launch in the profile). Eight rounds each in turn on an "
        "H200, the whole call at 1 M points took 2.61–3.25 times the pinned copy against 2.78–3.46 with a loop a "
        "piece (medians 2.80 and 2.94), at 10 M 1.29–1.39 against 1.34–1.51 (medians 1.335 and 1.355), at 100 M "
        "1.15–1.27 against 1.16–1.25 (1.18 and 1.20): at 10 M and 100 M points within the rounds' spread "
        "(Benchmarks/gpu/variants-whole-bounds.txt). "
        "Against the engine before 064700a (4621e56), built side by side in one call and run in turn, the keys phase went from "
        "1.42 to 0.87 ms at 100 M points and from 0.23–0.24 to 0.10–0.12 ms at 10 M, the device phases from "
        "10.0–10.1 to 9.45–9.48 ms (2.17–2.19 to 2.05 times the floor) and from 1.60 to 1.48–1.50 ms "
        "(Benchmarks/gpu/variants-bounds.txt, call 4; the level phase moves by up to 0.6 ms from run to run "
        "with the same kernels, 3.21–3.42 ms in calls 1 to 3 against 3.71–3.85 in call 4, which gave "
        "1.93–1.98 times the floor at 100 M in calls 1 to 3). The "
        "whole call follows the machine's host: 1.48 times the pinned copy at 100 M points in call 3's run of the "
        "report's benchmark, 1.52–2.36 for this engine and 2.37–2.49 for the one before in call 4, and 2.75 in "
        "that call 4's run of the report's benchmark, whose upload of the 1.9 GB took 86.5 ms against 41.2 in "
        "call 3's. "
        "Before the records travelled with the keys, the leaf kernel gathered each "
        "point's record from its place in the input, a random read a point: at 100 M points that kernel took "
        "4.55 ms and moved 8.3 GB, bound by how many random places the memory serves a second (32-byte fills and "
        "a separate gather loop took as long: Benchmarks/gpu/variants-packed-sort.txt). Moving the records with "
        "the keys costs the sort about 1.3 ms more at 100 M points (its 12 bytes a point and pass against 8 for "
        "packed words) and saved the leaves 2.1 ms; 64 registers a loop thread (at least 4 blocks a "
        "multiprocessor, CudaDevice.h) took 0.8 ms more off the leaf kernel and 0.14 ms off the inner levels. "
        "Against the engine before, built side by side in one call and run in turn, the device phases went from "
        "11.9–12.0 to 9.8–10.0 ms at 100 M points and from 1.83–1.88 to 1.57 ms at 10 M "
        "(Benchmarks/gpu/variants-records.txt, call 3). The sort now waits for the attributes, which it used to "
        "overlap, and the whole call stayed where it was within the runs' spread. A caller with pinned or "
        "device-resident points would not pay the upload.",
        "",
    ]
    text += _steps_at_10m(ctx)
    rounds = {n: more_rounds(ctx, n) for n in (10000000, 100000000)}
    if all(rounds.values()):
        here = {n: [r["call_over_pinned_copy"] for r in builds if r["depth"] == 10 and r["n"] == n
                    and r.get("call_over_pinned_copy")] for n in rounds}

        def listed(ratios):
            return ", ".join("%.2f" % r for r in ratios)

        sessions = "; ".join(
            "in the %s session, %s ([gpu/%s](gpu/%s), the rounds of %s)" % (
                session, listed(ratios), name, name, " and ".join('"%s"' % p for p in parts))
            for session, name, parts, ratios in rounds[10000000])
        text += [
            "Call / copy moves with the host's copy speed from run to run: at 10 M points and depth 10 it was %s in "
            "this run, and in rounds of %s's engine on other H200 machines: %s. At 100 M points, %s here and %s "
            "there." % (listed(here[10000000]), ROUNDS_ENGINE, sessions, listed(here[100000000]),
                        "; ".join(listed(ratios) for _, _, _, ratios in rounds[100000000])),
            "",
        ]
    if staging:
        text += [
            "Where the whole call goes, and what the engine holds. The engine copies a caller's pageable arrays of "
            + ("1 MB and more through page-locked buffers on up to 16 host threads, started once and kept, in "
               "pieces that grow from 0.5 to 4 MB over the run's start (half that of the reflectivity's 16-bit "
               "codes), which the threads take in turn as each "
               "becomes free "
               if host_copy else "16 MB and more through page-locked buffers on up to 8 host threads ")
            + "(Rendering/Engine/octoray/"
            "CudaUpload.h), " + ("all the arrays of a build in one pass, laid end to end (StagingPieces.h); "
                                 if one_pass else
                                 "the positions first and the attributes while the device computes the keys; ")
            + "*upload* is the host's "
            "time in those copies, the median of the 7 builds as are the device phases above (in runs of the "
            "benchmark before 25da958, the last build's own); *plain cudaMemcpy* is what it did before, *cudaHostRegister* page-locks the caller's "
            "arrays in place for the copy%s, *pinned* is the floor above%s. GPU bytes per point: the arrays alone; "
            "with the memory that the engine's allocator keeps for the next build (with the points kept, a "
            "rebuild fills a new octree beside the old one and then reuses the old one's memory instead of "
            "mapping new memory); and built without the points (`BuildOptions::keepPoints` off: node arrays "
            "only, the allocator's cache given back), with that build's whole call." % (
                _page_locking(ctx),
                ("; *host copy* is the host's half of the staging alone: the caller's arrays copied piece by "
                 "piece into the same threads' page-locked buffers (since c9c93d4 the reflectivity as its 16-bit "
                 "codes: 170 MB of the 190 at 10 M points; the pinned copy stays the input's, the goal's "
                 "measure), no DMA (octoray_bench_cuda's HostHalfOfStaging). "
                 "No upload through page-locked buffers takes less than the longer of the host copy and a pinned "
                 "copy of what it lands (before c9c93d4, the pinned copy here)" if host_copy else "")
                + ("; nor less than the two at once (*host copy and pinned copy at once*: both read the host's "
                   "memory); *staged copy alone* is the engine's staging of the same arrays with nothing queued "
                   "after it (a build reduces the positions' bounds in one loop once they have landed)"
                   if one_pass else "")),
            "",
            ctx.table(["points", "depth", "upload", "plain cudaMemcpy", "cudaHostRegister + copy", "pinned copy"]
                      + (["host copy"] if host_copy else [])
                      + (["host copy and pinned copy at once", "staged copy alone"] if one_pass else [])
                      + ["upload / pinned", "B/point, arrays", "B/point, with cache", "whole call, points not kept",
                         "B/point, points not kept"], staging_rows),
            "",
        ] + _lean_builds(ctx, builds, mem_records)
        if host_copy:
            text += [
                "The staging's threads start together and end together: with 4 MB pieces the copy engine waited "
                "while they filled their first buffers and the host while it copied their last ones, and the "
                "threads were started for each copy. With fb4365a's staging built beside it and run in turn "
                "(Benchmarks/gpu/variants-staging.txt), the whole call went from 2.88–2.96 to 2.48–2.56 times "
                "the pinned copy at 10 M points with pieces that grow from 0.5 MB at a stripe's start and shrink "
                "toward its end and threads kept, to 2.22–2.25 with 16 threads instead of 8; staging arrays from "
                "1 MB instead of 16 took the 1 M-point call from 5.87–6.44 to 4.32–4.39 times. The shrinking toward "
                "the end went in e3412b8 (**Fewer staging pieces**, below).",
                "",
            ]
        if one_pass:
            text += [
                "Each copy still paid those ramps, and a build made three: the positions, then the colours and "
                "the reflectivity while the device computed the keys. At 10 M points the engine's staging of the "
                "three arrays one copy each took 5.71–6.70 ms where one copy of the same bytes as one block took "
                "4.43–5.32 (Benchmarks/gpu/variants-one-pass.txt, calls 1 and 2). A build now stages all its "
                "arrays in one pass, laid end to end, each from a multiple of 768 bytes so that no piece splits "
                "a point (StagingPieces.h's StagingRun; the attributes' copies ride in the positions' pass, "
                "Device::StageReduced). Beside a9dce86's engine, built side by side and run in turn, three "
                "rounds, the whole call went from 2.21–2.22 to 1.83–1.94 times the pinned copy at 10 M points, "
                "from 4.52–4.81 to 3.68–4.02 at 1 M and from 1.50–1.65 to 1.42–1.49 at 100 M; the keys lose the "
                "attributes' copy to overlap (0.1 ms at 10 M). The host's memory bounds what is left: the host's "
                "half of the staging and the pinned copy at once take about 1.1 times the pinned copy at 10 M "
                "points (3.67–3.86 ms against 3.44–3.47 in that call), since both read the host's memory, and "
                "the staged copy alone stays 0.5–0.7 ms above that. An upload at that floor would still leave "
                "about 1.5 times at 10 M points (1.49–1.56 in that call), with the keys, the sort and the levels "
                "after it (about 1.5 ms), which need all the positions.%s" % _host_floor_at_10m(builds),
                "",
                "What a build's upload adds to the staging threads' pass, timed on the host part by part "
                "(Benchmarks/gpu/variants-upload-parts.txt, call 4): at 100 M points the memory's reservations, "
                "up to 2.8 ms where the pool maps new memory, and the records' reservation and ingest, 0.3–1.2 ms; "
                "the rest is the pass itself, 42.8–47.5 ms in the first twelve builds of 100 M points in that run, "
                "where the staged copy alone took 39.8. The bounds' kernels on the pieces were not what the pass lost at "
                "100 M points: with them reduced in one launch after the copy, or every four pieces, the whole call "
                "there took 1.57–1.59 and 1.50–1.56 times the pinned copy against 1.56–1.60 (call 5), within the "
                "host's spread (the staged copy alone moved between 38.7 and 49.2 ms from run to run); at 1 M "
                "points, where they weigh more, one loop once the positions have landed made the call's median about 5 % "
                "shorter in the fortieth session's rounds, and a74e097 keeps it (above).",
                "",
                "Where the staging's pass loses, timed piece by piece (a diagnostic build of CudaUpload.h, "
                "Benchmarks/gpu/variants-staging-timeline.txt, read by scripts/gpu/staging-timeline.py): with one "
                "stripe of the run a thread, most threads copied theirs of 190 MB in 2.1–2.8 ms and one or two in "
                "4–6 ms, at half the others' speed, as two threads sharing a core do; the threads' last host copies "
                "ended a median 3.1 ms apart in copies of 4.9–6.5 ms. Since c6857bf the run is cut into pieces in "
                "order and each thread takes the next as it becomes free (StagingPieces.h's CutPieces and "
                "PieceDealer). Built beside 522c9b1's staging and run in turn, three rounds, the host's half alone "
                "took 2.15–2.46 ms at 10 M points against 2.23–2.94, and 22.0–25.1 ms at 100 M against 32.9–34.2; "
                "but the staged copy alone took 4.58–4.67 ms against 4.44–4.60, and the whole call 1.75–1.80 times "
                "the pinned copy against 1.73–2.08 at 10 M points, 1.40–1.46 against 1.43–1.44 at 100 M "
                "(Benchmarks/gpu/variants-staging-dealt.txt): what the staged copy waits for is the copy engine, "
                "reading the page-locked buffers while the host writes the next ones. Fewer, larger pieces (80 at "
                "10 M points where the dealt staging cuts 146) changed nothing there, nor did three buffers a "
                "thread (2.08–2.13 times at 10 M points; variants-staging-timeline.txt). Non-temporal stores into "
                "the buffers, which spare the host's memory the write-allocate's reads, made the call slower: 1.78–1.80 "
                "times at 10 M points against 1.69–1.77 with memcpy (variants-staging-stores.txt); likely because "
                "that host's 300 MiB L3 holds the 128 MB of buffers, from which the DMA reads what ordinary stores "
                "wrote.",
                "",
            ] + _direct_records(ctx) + _spatial_order(ctx) + _lean_loops(ctx) + _h200(ctx) + _sort_during_upload(ctx) + _staging_pieces(ctx)
    r = named_record(records, "gpu bytes per point, every attribute")
    if r:
        arrays = [(k, v) for k, v in r.items() if k.startswith("node ") or k.startswith("point ")
                  or k in ("sort buffers", "allocator cache")]
        text += [
            "**Every attribute** a scene of colours, a transfer function and lights uses: %s points as above with "
            "8-bit colours, scalars (a ramp across the clusters), reflectivity and normals (radial), depth %d, "
            "built without the points: %s nodes, %.2f GPU bytes per point in arrays (%.2f with the allocator's "
            "cache). Each node array as the engine's memory report names it (`Engine::Memory`), in bytes per "
            "point:" % (count(r["n"]), r["depth"], count(r["nodes"]), r["seconds"], r["total_bytes_per_point"]),
            "",
            ctx.table(["array", "bytes/point"], [[name, "%.2f" % value] for name, value in arrays]),
            "",
        ]
    build = named_record(records, "device points build")
    if build:
        primary = named_record(records, "device points primary 1920x1080")
        full = named_record(records, "device points shadows+bounce 1920x1080")
        text += [
            "**%s points on one GPU** (`octoray_bench_cuda --billion 1e9`): Gaussian clusters like the ones above, "
            "generated on the device from a fixed seed (xyz float and 8-bit RGB), built from device memory at "
            "depth 10 without the points (the engine copies them on the device, then keeps the node arrays "
            "alone), traced at 1920×1080. One build, the first, its allocations included: %s (sort %s, levels %s), "
            "%s nodes, %.2f GPU bytes per point. Frames: primary rays %s (%.0f frames/s); Phong + shadows + one "
            "bounce %s (%.0f frames/s)." % (
                count(build["n"]), seconds(build["seconds"]), seconds(build["sort_seconds"]),
                seconds(build["level_seconds"]), count(build["nodes"]), build["bytes_per_point"],
                seconds(primary["seconds"]), 1 / primary["seconds"], seconds(full["seconds"]), 1 / full["seconds"]),
            "",
        ]
    tiled = gpu_records(ctx, TILED_FILE) or []
    if tiled:
        frames = ", ".join("%s×%s %s (%.0f frames/s, %s of them tracing; median of %d orbit frames)" % (
            r["width"], r["height"], seconds(r["seconds"]), 1 / r["seconds"], seconds(r["trace_s"]), r["frames"])
            for r in tiled)
        first = tiled[0]
        text += [
            "**A real scan tiled to %s points** (%s; a call of its own, %s; `octoray_bench_orbit --points 0 --file "
            "Data/External/PCL/table_scene_lms400.pcd --tile 1e9 --tile-depth 12 --methods octoray`): the LMS400 "
            "laser scan (460 400 points) copied side by side on a square grid in host memory, handed to "
            "vtkOctreeVolumeMapper as one vtkPolyData (KeepPointsForUpdates off, leaf depth 12) and drawn in an "
            "offscreen EGL window over a camera orbit. First picture (the pageable upload, the build and the first "
            "frame) %s; GPU memory the mapper added %.2f bytes per point; median frames %s. "
            "[Picture at 1920×1080](gpu/tiled-billion-1920x1080.png)." % (
                count(first["n"]), gpu_source(ctx, TILED_FILE), ctx.gpu_call(TILED_SUMMARY) or TILED_SUMMARY,
                seconds(first["first_picture_s"]),
                first["gpu_bytes"] / first["n"], frames),
            "",
        ]
    text += [
        "Update of moved points against a full rebuild of the same points (whole calls, positions uploaded from "
        "the host and checked for NaN/Inf on the device first); both moves change the topology, so the update "
        "computes and sorts the keys again in the same buffers rather than adjusting counts in place:",
        "",
        ctx.table(["moved", "points", "depth", "update", "rebuild", "update / rebuild"], urows),
    ]
    summary = []
    ten = [r for r in builds if r["n"] == 10000000 and r["depth"] == 10]
    if ten:
        # The device phases against the sort they contain are what the build
        # itself costs; the whole call is mostly the upload from pageable
        # memory, which a caller with pinned or device-resident points skips.
        r = ten[0]
        if phases:
            device = device_phases(r)
            against = "bare CUB radix sort " + seconds(r["peer_seconds"])
            ratio = "%.2f× the sort" % (device / r["peer_seconds"])
            if r.get("build_sort_seconds"):
                against += " (of the 32-bit keys with 8-byte records the build sorts: %s)" % \
                    seconds(r["build_sort_seconds"])
                ratio += " (%.2f×)" % (device / r["build_sort_seconds"])
            against += "; issue 16's goal ≤ %g× the sort" % GOAL_OVER_SORT
            summary.append(("CUDA octree build, 10 M points, depth 10, device phases (GPU run; whole call with "
                            "the upload: %s)" % seconds(r["seconds"]), seconds(device), against, ratio))
        else:
            summary.append(("CUDA octree build, 10 M points, depth 10 (whole call, GPU run)", seconds(r["seconds"]),
                            "bare CUB radix sort " + seconds(r["peer_seconds"]),
                            "%.0f× the sort" % (r["seconds"] / r["peer_seconds"])))
    return "\n".join(text) + "\n", summary + _lean_row(ctx) + _goal_rows(builds, records, phases, upload)


def _lean_row(ctx):
    """The README summary's row of the lean loops' rounds (three more rounds
    of this run's device phases, which b422446 left as they were): their
    device phases against the sort beside them."""
    path = ctx.gpu_file(LEAN_FILE)
    if not path:
        return []
    rounds = summary_figures(path)
    main = [rounds[("main", n)] for n in (10000000, 100000000)]
    return [("CUDA octree build, 10 M / 100 M points, depth 10, device phases, three more rounds of the lean loops' "
             "engine (4881ff3, on an H200 beside the engine before, Benchmarks/gpu/%s)" % LEAN_FILE,
             " / ".join(spread(m["phases"], "%.3f") + " ms" for m in main),
             "bare CUB radix sort %s; issue 16's goal ≤ %g× the sort" % (
                 " / ".join(spread(m["floor"], "%.3f") + " ms" for m in main), GOAL_OVER_SORT),
             " / ".join(spread(m["ratio"]) + "×" for m in main))]


def _goal_rows(builds, records, phases, upload):
    """The README summary's rows for issue 16's build and size goals of this
    run: the 100 M build, the whole call against the pinned copy, the bytes
    per point of every attribute, the billion points' frame rate."""
    rows = []
    deep = {r["n"]: r for r in builds if r["depth"] == 10}
    big = deep.get(100000000)
    if big and phases:
        device = device_phases(big)
        rows.append(("CUDA octree build, 100 M points, depth 10, device phases (GPU run)", seconds(device),
                     "bare CUB radix sort %s; issue 16's goals ≤ %s and ≤ %g× the sort" %
                     (seconds(big["peer_seconds"]), seconds(GOAL_BUILD_100M), GOAL_OVER_SORT),
                     "%.2f× the sort" % (device / big["peer_seconds"])))
    calls = [deep[n] for n in (10000000, 100000000) if n in deep]
    if upload and calls:
        rows.append(("CUDA octree build from pageable host arrays, whole call, %s points, depth 10 (GPU run)" %
                     " / ".join(count(r["n"]) for r in calls),
                     " / ".join(seconds(r["seconds"]) for r in calls),
                     "pinned copy of the same bytes %s; issue 16's goal ≤ %g×" %
                     (" / ".join(seconds(r["pinned_upload_seconds"]) for r in calls), GOAL_CALL_OVER_COPY),
                     " / ".join("%.2f×" % call_over_copy(r) for r in calls) +
                     (" (median of the pairs)" if all("call_over_pinned_copy" in r for r in calls) else "")))
    r = named_record(records, "gpu bytes per point, every attribute")
    if r:
        rows.append(("GPU memory, %s points, depth %d, every attribute (GPU run)" % (count(r["n"]), r["depth"]),
                     "%.2f bytes/point" % r["seconds"], "issue 16's goal ≤ %g bytes/point" % GOAL_BYTES_PER_POINT,
                     "%.2f× the goal" % (r["seconds"] / GOAL_BYTES_PER_POINT)))
    primary = named_record(records, "device points primary 1920x1080")
    if primary:
        rows.append(("%s device-generated points on one GPU, primary rays 1920×1080 (GPU run)" %
                     count(primary["n"]), "%.0f frames/s" % (1 / primary["seconds"]),
                     "issue 16's goal ≥ %g frames/s" % GOAL_BILLION_FRAMES,
                     "%.0f× the goal" % (1 / primary["seconds"] / GOAL_BILLION_FRAMES)))
    return rows


def _quantisation(ctx):
    records = load_records(ctx.work_path("build-quantisation.json"))
    if not records:
        return "No quantisation records.\n"
    scenes_in = []
    for r in records:
        s = r["name"].split("/")[-1]
        if s not in scenes_in:
            scenes_in.append(s)
    gpu = gpu_records(ctx, "bench-quantisation-cuda.json")
    gpu_by = {(r["name"], r["depth"]): r for r in gpu or []}
    describe = {
        "ct": "CT stack (Data/DICOM/CT5N, voxels above −500 HU as points; millimetres)",
        "lidar": "LiDAR tile (Data/Particles/lidar_simple.particles; data units of the file)",
        "spheres": "sphere field (48 spheres, points on their surfaces, in the unit cube)",
    }
    parts, csv_rows = [], []
    worst = 0.0
    worst_colour = [0.0, 0.0]  # steps of 1/255: leaves, inner nodes
    worst_normal = [0.0, 0.0]  # distance between vectors: leaves, inner nodes
    worst_scalar = [0.0, 0.0]  # steps of the scalar range / 65532: leaves, inner nodes
    worst_mirror = [0.0, 0.0]  # reflectivity, absolute: leaves, inner nodes
    gpu_same = True
    for s in scenes_in:
        rows = []
        for r in (x for x in records if x["name"].endswith("/" + s)):
            worst = max(worst, r["max_distance"] / r["bound"])
            colour = "colour_leaf_steps" in r
            if colour:
                worst_colour = [max(worst_colour[0], r["colour_leaf_steps"]),
                                max(worst_colour[1], r["colour_inner_steps"])]
            scalar = "scalar_leaf_steps" in r
            if scalar:
                worst_scalar = [max(worst_scalar[0], r["scalar_leaf_steps"]),
                                max(worst_scalar[1], r["scalar_inner_steps"])]
            normal = "normal_leaf_distance" in r
            if normal:
                worst_normal = [max(worst_normal[0], r["normal_leaf_distance"]),
                                max(worst_normal[1], r["normal_inner_distance"])]
            mirror = "reflectivity_leaf_error" in r
            if mirror:
                worst_mirror = [max(worst_mirror[0], r["reflectivity_leaf_error"]),
                                max(worst_mirror[1], r["reflectivity_inner_error"])]
            g = gpu_by.get((r["name"], r["depth"]))
            if g is not None:
                gpu_same = gpu_same and abs(g["max_distance"] - r["max_distance"]) <= 1e-12 * r["cube_size"] \
                    and abs(g["mean_distance"] - r["mean_distance"]) <= 1e-12 * r["cube_size"]
            if r["depth"] % 2 == 1 or r["depth"] == 21:  # every other depth here; all in the CSV
                rows.append([r["depth"], "%.4g" % r["leaf_side"], "%.4g" % r["max_distance"], "%.4g" % r["mean_distance"],
                             "%.3f" % (r["max_distance"] / r["bound"]), count(r["nodes"]),
                             "%.2f" % (r["seconds"] * 1e3), "%.2f" % (r["bytes"] / 1e6),
                             ("%.2f" % (g["seconds"] * 1e3)) if g else "–",
                             ("%.2f / %.2f / %.1f" % (r["colour_leaf_steps"], r["colour_inner_steps"],
                                                      r["colour_root_bound_steps"])) if colour else "–",
                             ("%.2f / %.2f / %.1f" % (r["scalar_leaf_steps"], r["scalar_inner_steps"],
                                                      r["scalar_root_bound_steps"])) if scalar else "–",
                             ("%.2f / %.2f / %.1f" % (1e3 * r["normal_leaf_distance"], 1e3 * r["normal_inner_distance"],
                                                      1e3 * r["normal_root_bound"])) if normal else "–",
                             ("%.2f / %.2f / %.1f" % (1e6 * r["reflectivity_leaf_error"],
                                                      1e6 * r["reflectivity_inner_error"],
                                                      1e6 * r["reflectivity_root_bound"])) if mirror else "–"])
            csv_rows.append([s, r["n"], r["depth"], r["cube_size"], r["leaf_side"], r["max_distance"],
                             r["mean_distance"], r["bound"], r["nodes"], r["seconds"], r["bytes"],
                             g["seconds"] if g else "", r.get("colour_leaf_steps", ""),
                             r.get("colour_inner_steps", ""), r.get("scalar_leaf_steps", ""),
                             r.get("scalar_inner_steps", ""), r.get("normal_leaf_distance", ""),
                             r.get("normal_inner_distance", ""), r.get("reflectivity_leaf_error", ""),
                             r.get("reflectivity_inner_error", "")])
        n = next(x["n"] for x in records if x["name"].endswith("/" + s))
        parts.append("**%s**, %s points, root cube side %.6g:\n\n" % (describe.get(s, s), count(n), next(
            x["cube_size"] for x in records if x["name"].endswith("/" + s))) + ctx.table(
            ["depth", "leaf side", "max distance", "mean distance", "max / bound", "nodes", "build ms (CPU)",
             "engine MB", "build ms (CUDA)", "colour error, steps: leaves / inner / bound",
             "scalar error, steps: leaves / inner / bound",
             "normal error ×10⁻³: leaves / inner / bound",
             "reflectivity error ×10⁻⁶: leaves / inner / bound"], rows, "rrrrrrrrrrrrr"))
    csv = ctx.write_csv("build-quantisation", ["scene", "points", "depth", "cube_size", "leaf_side", "max_distance",
                                               "mean_distance", "bound", "nodes", "build_s_cpu", "engine_bytes",
                                               "build_s_cuda", "colour_leaf_steps", "colour_inner_steps",
                                               "scalar_leaf_steps", "scalar_inner_steps",
                                               "normal_leaf_distance", "normal_inner_distance",
                                               "reflectivity_leaf_error", "reflectivity_inner_error"], csv_rows)
    png, link = ctx.figure_path("build-quantisation")
    _plot_quantisation(png, records, scenes_in, describe)
    gpu_line = ("The CUDA column is from %s; its distances %s the CPU's (the same tree)." % (
        gpu_source(ctx, "bench-quantisation-cuda.json"), "equal" if gpu_same else "DIFFER FROM")) if gpu else \
        "CUDA column: " + NOT_ON_GPU + " (`octoray_bench_quantisation --backend cuda`)."
    return ("\n\n".join(parts) + "\n\n[CSV](%s) · ![quantisation error against depth](%s)\n\n" % (csv, link) +
            "Odd depths and 21 shown; every depth is in the CSV. Build times of the small scenes are a fraction "
            "of a millisecond and swing with the machine's load; the error columns do not depend on it. "
            "Largest max / bound over every scene and depth: %.3f (≤ 1 by construction; the run fails if a distance "
            "passes the bound). %s\n\n"
            "8-bit colours are stored as bytes (Rendering/Engine/octoray/Attributes.h: 4 bytes a node where four "
            "floats took 16; float colours, HDR included, stay floats). The colour column measures that rounding on "
            "the scenes with 8-bit colours: each node's stored channels against the exact mean of the 8-bit "
            "channels of the points beneath it (Quantisation.h, the same walk), in steps of 1/255, the largest at "
            "the leaves and above them, beside the bound at the root. A leaf's mean is rounded once (bound half a "
            "step); an inner node's is the count-weighted mean of its children's rounded means, rounded again "
            "(bound half a step more per level); the run fails past a node's bound. Largest over every scene and "
            "depth: %.2f steps at the leaves, %.2f above them.\n\n"
            "Scalars are stored in 16 bits where a float took 32 (Rendering/Engine/octoray/Scalar16.h): 65,532 "
            "equal steps over the range of the build's finite scalars, kept with the octree; −∞, +∞ and NaN have "
            "codes of their own. The scalar column measures that rounding on the scenes with scalars: each node's "
            "decoded scalar against the exact mean of its points' scalars (in double), in steps of the range "
            "/ 65,532, beside the bound at the root: half a step for the points' codes, the leaf's mean and each "
            "level up, plus two float roundings of the range's ends in decoding (which is why a leaf of one point "
            "can show a little over half a step). The run fails past a node's bound. Largest over every scene and "
            "depth: %.3f steps at the leaves, %.3f above them. A step is 64 times finer than an entry of the "
            "transfer function's table (1,024 entries) where the table spans the data's range.\n\n"
            "Normals are stored in one 4-byte word where three floats took 12 (Rendering/Engine/octoray/"
            "OctahedralNormal.h): the direction on the octahedron, 12 bits a coordinate, the length (the mean of "
            "unit normals is shorter where they disagree) in 8 bits. The last column measures that rounding on the "
            "scenes with normals: the distance between each node's decoded normal and the exact mean of its points' "
            "unit normals (computed in double), in thousandths, the largest at the leaves and above them, beside "
            "the bound at the root: the points' own rounding (at most 2√6/4094 = 1.2×10⁻³ in angle), plus, at the "
            "leaves and again at each level up, that angle and half a length step (1/510). The run fails past a "
            "node's bound. Largest over every scene and depth: %.2f×10⁻³ at the leaves, %.2f×10⁻³ above them "
            "(1×10⁻³ is 0.057° for a unit normal).\n\n"
            "Reflectivity, a mirror ray's weight from 0 to 1, arrives in 16 bits since c9c93d4 "
            "(Rendering/Engine/octoray/Attributes.h's UnitInput): each point's value is clamped to 0..1 and "
            "rounded to one of 65,532 equal steps (Scalar16.h's unit codes) as the CUDA staging copies it, so "
            "that 2 bytes a point cross the bus where the caller's float took 4 (at 100 M points the whole call "
            "took 1.18–1.24 times the pinned copy against 1.29–1.35 for the floats, in rounds in turn; at 10 M "
            "the rounds overlapped: [gpu/variants-unit-codes.txt](gpu/variants-unit-codes.txt)); nodes keep "
            "float means of those values. The last column measures it on the scenes with reflectivity: each "
            "node's value against the exact mean of its points' floats (in double), beside the bound: half a step "
            "(7.6×10⁻⁶) and the float sums' 2×10⁻⁶. The run fails past it. Largest over every scene and depth: "
            "%.2f×10⁻⁶ at the leaves, %.2f×10⁻⁶ above them, a five-hundredth of what moves an 8-bit channel "
            "(3.9×10⁻³).\n" % (
                worst, gpu_line, worst_colour[0], worst_colour[1], worst_scalar[0], worst_scalar[1],
                1e3 * worst_normal[0], 1e3 * worst_normal[1], 1e6 * worst_mirror[0], 1e6 * worst_mirror[1]))


def _plot_quantisation(png, records, scene_names, describe):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    colours = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"]
    for k, s in enumerate(scene_names):
        rs = [r for r in records if r["name"].endswith("/" + s)]
        d = [r["depth"] for r in rs]
        c = colours[k % len(colours)]
        # Relative to the root cube, so scenes in mm, m and unit cubes share an axis.
        axes[0].semilogy(d, [r["max_distance"] / r["cube_size"] for r in rs], "-o", ms=3, color=c,
                         label="%s: max" % s)
        axes[0].semilogy(d, [r["mean_distance"] / r["cube_size"] for r in rs], "--", color=c, label="%s: mean" % s)
        axes[1].semilogy(d, [r["bytes"] / 1e6 for r in rs], "-o", ms=3, color=c, label="%s: engine MB" % s)
        axes[1].semilogy(d, [r["seconds"] * 1e3 for r in rs], ":", color=c, label="%s: build ms" % s)
    rs = [r for r in records if r["name"].endswith("/" + scene_names[0])]
    axes[0].semilogy([r["depth"] for r in rs], [r["bound"] / r["cube_size"] for r in rs], "k:",
                     label="bound √3/2 · side / 2^depth")
    axes[0].set_xlabel("leaf depth")
    axes[0].set_ylabel("point to leaf-centre distance / root cube side")
    axes[0].set_title("Quantisation error (log)")
    axes[0].legend(fontsize=7)
    axes[0].grid(which="both", alpha=0.3)
    axes[1].set_xlabel("leaf depth")
    axes[1].set_title("Engine memory (MB) and build time (ms), CPU")
    axes[1].legend(fontsize=7)
    axes[1].grid(which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def render(ctx):
    peers, summary, peer_records = _peers(ctx, ctx.figure_path("build-peers"))
    engine, memory = _engine(ctx)
    cuda, cuda_summary = _cuda(ctx)
    quantisation = _quantisation(ctx)
    octl_max = float(OCTREE_LOCATOR_MAX)
    text = """
{machine}

Point sets (fixed seed, Benchmarks/Engine/BenchUtil.h): `uniform` = uniform in the unit cube; `clustered` = 32
Gaussian blobs, sigma 0.02, centres uniform in the cube. Depth is octoray's automatic choice (the median leaf holds
one point); PCL gets the same root cube and resolution = leaf voxel, and builds the identical tree (leaf and branch
counts compared in the run: "same tree" below).

### Octoray against PCL and VTK (CPU, same points, same run)

Command:

    {peers_cmd}

Every build starts from nothing (fresh engine, fresh PCL octree, fresh locator); freeing a tree is not timed.
octoray: median of {peer_repeats} after 1 warm-up. PCL and vtkOctreePointLocator: median of 3, no warm-up
(vtkOctreePointLocator: 1 build at 5 M points and more). vtkStaticPointLocator: median of {peer_repeats} after 1 warm-up. vtkOctreePointLocator gets MaximumPointsPerRegion =
octoray's mean points per leaf rounded up; vtkStaticPointLocator the same NumberOfPointsPerBucket. Ratio = peer time
/ octoray time with the same thread count; for PCL it is the median over its builds of PCL's time / the time of a
single-threaded octoray build run right after it (with glibc's free lists consolidated in between, untimed), so that
load drifting on this shared machine between the octoray block and the PCL block does not move it.
vtkOctreePointLocator is left out above {octl} points: it takes about a minute per 10 M build on this machine, more
than the report's time budget allows (`octoray_bench_peers --cases uniform:1e7` measures it).

{peers}

Issue 2's goal (single-threaded ≥ 5× faster than PCL on 10 M points) is read from the 10 M uniform row.

### Engine alone (CPU)

Command:

    {engine_cmd}

One engine rebuilt repeatedly (buffers reused, as when an animation is rebuilt per frame): median of {repeats} after
1 warm-up. Phases from BuildStats (medians): keys = Morton keys, sort = radix sort, levels = unique keys per
level, links and averages; the positions' bounds are reduced where the positions are staged and count in none of
them (the median holds them).

{engine}

Memory of octoray (`Engine::Memory().Total()`: point copy, sort buffers and node arrays) against the
thesis's dense pointer skeleton of the same depth, 8 B × (8^(L+1)−1)/7:

{memory}

Reading these figures:

- The sort is the largest phase and gains little from a second thread on this VM: the automatic depth first sorts
  32-bit keys of 10 levels, 30 bits = 3 passes of 10-bit digits (RadixSort.cpp), each with its point's record where
  that is one or two words, else with its index (OctreeKernels.h's SortedKeys), bound by the scattered writes rather
  than by compute; only where those levels do not settle the depth does it sort again, with indices: keys of 13
  levels (39 bits, 4 passes) where its level-10 cells hold few points, and full-depth keys (63 bits, 6 passes) where
  those do not settle it either or the cells are dense (DepthChoice.h's NextSortDepth). 2-thread medians on this
  shared machine swing from run to run; read the 1-thread column for ratios.
- B/point is dominated by what the engine keeps besides nodes (float xyz 12 B, the sort's keys and their second
  buffer, the records in sorted order; the points' keys are not kept: a rebuild computes them again from the
  positions); the node arrays alone are the smaller part (*node arrays B/point*). The dense skeleton is smaller than
  octoray only at shallow depth on uniform data; from depth 9 on it is larger and grows 8× per level.
- vtkSMPTools in Debian's ParaView defaults to the Sequential backend; the benchmark switches it to STDThread so
  vtkStaticPointLocator's threaded build is measured.

### CUDA backend (GPU run)

{cuda}

### Quantisation error against leaf depth

Command:

    {scene_cmd}
    {quant_cmd}

Drawing a point as its leaf voxel moves it to the voxel's centre; the octree's depth trades that error for nodes and
memory. For every leaf depth 1–21 the engine builds the octree (fresh engine per depth; build time median of 3 after
a warm-up; engine MB = `Engine::Memory().Total()`), the tree is copied to the host (`Engine::CopyToHost`), and each
point is walked from the root through the stored child masks to its leaf, whose centre comes from the leaf's stored
Morton key and the engine's double-precision root cube (Rendering/Engine/octoray/Quantisation.h). Distances are in the
scene's data units. Why the figure is trustworthy: the walk fails if the tree lacks a point's leaf, no distance may
exceed the analytic bound (half the leaf diagonal, √3/2 · side / 2^depth; max / bound below), and the engine test
`Quantisation.*` (Testing/Engine/TestQuantisation.cpp, in `make test`) checks the same measurement against a
brute-force recomputation from point, root cube and depth alone (no Morton keys, no tree), and that points at
voxel corners give exactly the bound and points at centres exactly 0.

{quantisation}
""".format(machine=machine_text(ctx, "build"), peers_cmd=ctx.command("build-peers"), octl=count(octl_max),
           peers=peers, peer_repeats=PEER_REPEATS, engine_cmd=ctx.command("build-engine"), repeats=BUILD_REPEATS, engine=engine, memory=memory,
           cuda=cuda, scene_cmd=scenes.with_python_path(ctx.command("scene-ct5n")), quant_cmd=ctx.command("build-quantisation"),
           quantisation=quantisation)
    return Section(text, summary + cuda_summary)
