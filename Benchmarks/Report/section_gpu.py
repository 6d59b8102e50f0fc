"""The GPU run's checks: engine tests on both backends and compute-sanitizer.

Nothing is measured here: the files come from scripts/gpu/gpu-check.sh on a
GPU machine (copied into Benchmarks/gpu/ with COMMAND.md)."""
import os
import re
import xml.etree.ElementTree as ET

from make_report import Section, file_parts, gpu_check_heading, gpu_summaries, gpu_summary_link

TITLE = "GPU checks: tests and compute-sanitizer (from the GPU run)"

# (log name in summary.txt, what it checks)
SANITIZERS = [
    ("memcheck", "compute-sanitizer memcheck: out-of-bounds and misaligned device memory accesses"),
    ("memcheck-refused", "memcheck over the refused-launch tests (API errors are the point there, so not reported)"),
    ("racecheck", "racecheck: shared-memory data races"),
    ("initcheck", "initcheck: reads of uninitialised device memory"),
    ("synccheck", "synccheck: invalid uses of __syncthreads and warp synchronisation"),
]


def produce(ctx):
    pass  # measured on the GPU machine only


def test_counts(xml_path):
    """(all, passed, failed, skipped) for the whole run and for the CUDA tests."""
    root = ET.parse(xml_path).getroot()
    counts = {"all": [0, 0, 0, 0], "cuda": [0, 0, 0, 0]}
    for case in root.iter("testcase"):
        name = f"{case.get('classname')}.{case.get('name')}"
        failed = case.find("failure") is not None
        skipped = case.get("result") == "skipped" or case.find("skipped") is not None
        for group in ("all", "cuda"):
            if group == "cuda" and "CUDA" not in name and "CudaFaults" not in name:
                continue
            c = counts[group]
            c[0] += 1
            c[2 if failed else 3 if skipped else 1] += 1
    return counts


# The CUDA device's primitives against the CPU device's checks, on an H200
# (the twenty-seventh session's calls, COMMAND.md): a part "== call N, what"
# of the file each.
DEVICE_CHECKS_FILE = "engine-tests-cuda-device.txt"


def _device_checks(ctx):
    """What the file says of the CUDA device's primitive tests."""
    path = ctx.gpu_file(DEVICE_CHECKS_FILE)
    if not path:
        return []
    parts = file_parts(path)
    lines = [line for part in parts.values() for line in part]
    tests = [line for line in parts.get("call 1, engine tests (CudaDeviceCUDA)", []) if "] CudaDeviceCUDA." in line]
    passed = sum("OK ] CudaDeviceCUDA." in line for line in tests)
    sabotaged = sum("FAILED  ] CudaDeviceCUDA." in line for line in parts.get("call 2, the sabotaged copy", []))
    tools = []
    for tool in ("memcheck", "initcheck", "synccheck"):
        found = next((re.search(r"ERROR SUMMARY: (.*)$", line) for line in lines if line.startswith(tool + ":")), None)
        tools.append("%s %s" % (tool, found.group(1) if found else "not run"))
    race = next((re.search(r"RACECHECK SUMMARY: (.*)$", line) for line in parts.get("call 5, racecheck", [])
                 if "RACECHECK SUMMARY" in line), None)
    tools.append("racecheck %s" % (race.group(1) if race else "not run"))
    return [
        "The CUDA device's primitives under the build driver (ForEach, Reduce, Select, the nested "
        "lists with their side histogram, every sort, the run starts and the first failing step) are held to the CPU device's checks "
        "(Testing/Engine/DeviceChecks.h, suite `CudaDeviceCUDA`). On an NVIDIA H200 (the twenty-seventh "
        "session's calls, [gpu/%s](gpu/%s)): %d of %d passed; compute-sanitizer over them: %s; built against "
        "a CudaDevice.h that drops an item or a key bit in each primitive, %d of %d failed."
        % (DEVICE_CHECKS_FILE, DEVICE_CHECKS_FILE, passed, len(tests), "; ".join(tools), sabotaged, len(tests)),
        "",
    ]


# The two checks the thirty-first session added (StageReduced and
# ReduceSmallLevels, on both devices): their tests, compute-sanitizer and
# the sabotaged engine in call 2's parts "== call 2, ..." of the first.
STAGING_CHECKS_FILE = "variants-gather-staged.txt"
STAGING_CHECKS = ("StageReducedCopiesReducesAndCallsBack", "SmallLevelsReduceEachLevelAfterTheOneBelow")


def _staging_checks(ctx):
    """What call 2 of the file says of the two checks it added."""
    path = ctx.gpu_file(STAGING_CHECKS_FILE)
    if not path:
        return []
    parts = file_parts(path)

    def count(part, result):  # each test's own line: "[  FAILED  ] CudaDeviceCUDA.NAME (270 ms)"
        pattern = re.compile(r"\[ +%s +\] CudaDeviceCUDA\.(%s) \(" % (result, "|".join(STAGING_CHECKS)))
        return sum(bool(pattern.search(line)) for line in parts.get(part, []))
    passed = count("call 2, the device checks among main's engine tests", "OK")
    sabotaged = count("call 2, the new checks against the sabotaged engine (staging-checks-sabotage.sh)", "FAILED")
    tools = ["%s %s" % (m.group(1), m.group(2)) for m in (
        re.match(r"(\w+) rc \d+ =+ (?:ERROR|RACECHECK) SUMMARY: (.*?) \[", line)
        for line in parts.get("call 2, the new checks under compute-sanitizer", [])) if m]
    return [
        "Since the thirty-first session the device's staged copy with its reduction (StageReduced: the copies, "
        "the result, and a loop queued once the array has landed, while the arrays along are still on their "
        "way) and the small levels near the root (ReduceSmallLevels, each level after the one below) are held "
        "to checks of their own on both devices. On an NVIDIA H200 ([gpu/%s](gpu/%s), call 2): %d of %d "
        "passed; compute-sanitizer over them: %s; against an engine that reduces the small levels from the root "
        "down and runs the copy's afterFirst without waiting for the first array's pieces, %d of %d failed."
        % (STAGING_CHECKS_FILE, STAGING_CHECKS_FILE, passed, len(STAGING_CHECKS), "; ".join(tools), sabotaged,
           len(STAGING_CHECKS)),
        "",
    ]


TOOL_CHECKS_FILE = "summary-tool-check.txt"


def tool_check_calls(path):
    """[(header, lines)] of the calls recorded in TOOL_CHECKS_FILE, in order:
    each part starts with "== " and a header of its own; the closing table
    it holds starts with "== octoray GPU check", which is not a part."""
    calls = []
    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("== ") and not line.startswith("== octoray GPU check"):
                calls.append((line[3:], []))
            elif calls:
                calls[-1][1].append(line)
    return calls


def _later_calls(ctx, last=3):
    """The last calls of TOOL_CHECKS_FILE (tests and sanitizers on later
    commits than the report's run), each with its counts."""
    path = ctx.gpu_file(TOOL_CHECKS_FILE)
    if not path:
        return []
    rows = []
    for header, lines in tool_check_calls(path)[-last:]:
        text = "\n".join(lines)
        engine = re.search(r"^\[  PASSED  \] (\d+) tests\.$", text, re.M)
        failed = re.search(r"^\[  FAILED  \] (\d+) tests?, listed below:$", text, re.M)
        mapper = re.search(r"^(\d+)% tests passed out of (\d+)$", text, re.M)
        tools = len(re.findall(r"^\d+/\d+ Test +#\d+: engine\.tool\S* \.+ +Passed", text, re.M))
        sanitizers = re.findall(r"^[\w-]+: +(\d+) =+ ERROR SUMMARY: (\d+) errors", text, re.M)
        errors = sum(int(e) for _, e in sanitizers)
        runs = sum(int(n) for n, _ in sanitizers)
        rows.append((header.split(" (")[0],
                     (f"{engine.group(1)} passed" if engine else "no count")
                     + (f", {failed.group(1)} failed" if failed else ""),
                     ("%s of %s passed" % (mapper.group(2), mapper.group(2)) if mapper and mapper.group(1) == "100"
                      else f"{mapper.group(1)} % of {mapper.group(2)} passed" if mapper else "no count"),
                     f"{tools} passed",
                     f"{errors} errors over {runs} runs" if sanitizers else "not run"))
    return [
        "Later calls, tests and sanitizers alone, on the commits each names ([gpu/%s](gpu/%s), where each "
        "part says what changed; commands in [gpu/COMMAND.md](gpu/COMMAND.md)):" % (TOOL_CHECKS_FILE,
                                                                                  TOOL_CHECKS_FILE),
        "",
        ctx.table(["call", "engine tests", "mapper tests", "tool tests", "compute-sanitizer"], rows, "lllll"),
        "",
    ]


ESTIMATED_NORMALS_FILE = "estimated-normals.txt"


def _estimated_normals(ctx):
    """What normals estimated from the voxels cost and how far their
    pictures are from the points' own, from ESTIMATED_NORMALS_FILE."""
    path = ctx.gpu_file(ESTIMATED_NORMALS_FILE)
    if not path:
        return []
    with open(path) as f:
        # The latest run: each run after the first is appended below a
        # line of dashes.
        text = re.split(r"^-{20,}$", f.read(), flags=re.M)[-1]
    clusters = re.findall(r"^render depth (\d+), Phong \+ shadows \+ 1 bounce: [\d.]+ ms, (\d+) Mrays/s.*\n"
                          r"render depth \1, normals estimated from the voxels in ([\d.]+) ms \((\d+) nodes\); "
                          r"Phong \+ shadows \+ 1 bounce by them: [\d.]+ ms, (\d+) Mrays/s$", text, re.M)
    spheres = re.findall(r"^(CPU \(\d+ threads\)|CUDA \([^)]*\)),.*\n(?:.*\n){5}"
                         r"\| estimated from the voxels \| ([\d.]+) \| [\d.]+ \| ([\d.]+) \|\n"
                         r"\| occupancy of six neighbours \| - \| - \| ([\d.]+) \|$", text, re.M)
    parts = ["at depth %s %s ms for %s nodes, and Phong with shadows and a bounce by them %s Mrays/s against %s "
             "by occupancy" % (depth, ms, f"{int(nodes):,}", by, occupancy)
             for depth, occupancy, ms, nodes, by in clusters]
    on = ["%s ms on %s" % (ms, backend) for backend, ms, _, _ in spheres]
    differences = {(d, o) for _, _, d, o in spheres}
    return [
        "Normals estimated from the voxels for points without them (the engine's NormalEstimation.h, the "
        "mapper's EstimateNormals, on by default; made once per octree; the latest run of [gpu/%s](gpu/%s)): for the 10 M "
        "clustered points %s. For the sphere field's 1 M points at depth 8 they took %s; its Phong picture by "
        "them is %s/255 from the one by the points' own radial normals, on average over the pixels, and by the "
        "six neighbours' occupancy %s/255."
        % (ESTIMATED_NORMALS_FILE, ESTIMATED_NORMALS_FILE, "; ".join(parts), " and ".join(on),
           " and ".join(d for d, _ in sorted(differences)), " and ".join(o for _, o in sorted(differences))),
        "",
    ]


def render(ctx):
    summary_path = ctx.gpu_file("summary.txt")
    if not summary_path:
        return Section("Not run on a GPU yet: `scripts/gpu/gpu-check.sh OUTDIR` on a GPU machine writes the "
                       "files this section reads.")
    # The report's call is summary.txt; a tool that ran in a call of its own
    # (COMMAND.md) is read from that call's file, which its row names.
    summary = gpu_summaries(os.path.dirname(summary_path))[0][1]
    device = ""
    if ctx.gpu_file("gpu.txt"):
        with open(ctx.gpu_file("gpu.txt")) as f:
            device = f.read().strip()
    heading = gpu_check_heading(summary)

    rows = []
    if ctx.gpu_file("engine-tests.xml"):
        counts = test_counts(ctx.gpu_file("engine-tests.xml"))
        for group, label in (("all", "engine tests, both backends"), ("cuda", "of which CUDA tests")):
            total, passed, failed, skipped = counts[group]
            rows.append((label, f"{passed} passed, {failed} failed, {skipped} skipped of {total}"))
    clean = 0
    for log, what in SANITIZERS:
        result = "no summary line"
        for name, text in gpu_summaries(os.path.dirname(summary_path)):
            found = re.search(rf"^{re.escape(log)}:\s+(?:\d+ )?=+ (?:ERROR SUMMARY|RACECHECK SUMMARY): (.*)$", text, re.M)
            if found:
                step = re.search(rf"^{re.escape(log)}\s+(pass|FAIL)\b", text, re.M)
                result = found.group(1) + (f" (exit status: {step.group(1)})" if step else "")
                clean += found.group(1).startswith("0 ")
                result += gpu_summary_link(name)
                break
        rows.append((what, result))
    steps = [line for line in summary.splitlines() if re.match(r"^[a-z0-9-]+\s+(pass|FAIL)\s+\d+ ms$", line)]

    text = [
        f"Device: {device or 'see gpu/gpu.txt'}; run of {heading[0] if heading else 'unknown date'}. Command: "
        f"`{ctx.gpu_command() or 'scripts/gpu/gpu-check.sh OUTDIR'}`.",
        "",
        "gpu-check.sh builds the whole project for sm_90 against VTK 9.2 with EGL (the GPU machine has",
        "only CUDA, CMake and a compiler; VTK comes with the call), runs every engine test on both backends",
        "(the CPU backend is the reference the CUDA pictures and octrees are compared with), then the",
        "CUDA tests under each compute-sanitizer tool. The fault tests are among them: out of memory injected at every",
        "allocation site of build, update and render through the engine's memory budget",
        "(`CudaFaults.*`), and a launch refused by the CUDA runtime at every kernel of build, update",
        "and render (`CudaFaultsLaunch.*`, through octoray/FaultInjection.h): each failure names what",
        "failed; a failed build or render leaves the previous octree and the next frame intact; an",
        "update refused after it began writing drops the octree and says so until the next build.",
        "",
        ctx.table(["check", "result"], rows, "ll"),
        "",
        "Steps and their wall time on the GPU machine:",
        "",
        "```",
        *steps,
        "```",
        "",
        *_device_checks(ctx),
        *_staging_checks(ctx),
        *_later_calls(ctx),
        *_estimated_normals(ctx),
        "The VTK mapper's tests on the GPU are in the next section. Not run on the GPU: the ParaView",
        "plugin (ParaView is not built there); its CPU backend runs in `make test`.",
    ]
    summary_rows = []
    if ctx.gpu_file("engine-tests.xml"):
        summary_rows.append((f"engine tests on {device.split(',')[0] if device else 'the GPU'}", rows[0][1],
                             "compute-sanitizer", f"{clean} of {len(SANITIZERS)} tool runs clean"))
    return Section("\n".join(text), summary_rows)
