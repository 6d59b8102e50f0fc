"""Numerical stability: the extreme and stiff cases of issue 7, one engine
test each (suite Stability, Testing/Engine/TestStability.cpp), on both
backends. Each test records what it compared ("check") and what it measured
("outcome") as properties of its <testcase> in the GoogleTest XML; this
section turns that XML into the table. The CPU column is run here; the CUDA
column comes from the GPU run's XML of the whole engine test binary
(Benchmarks/gpu/engine-tests.xml)."""
import os
import xml.etree.ElementTree as ET

from make_report import Section

TITLE = "Numerical stability"

CPU_XML = "stability-cpu.xml"
GPU_XML = "engine-tests.xml"  # octoray_engine_tests --gtest_output=xml:$out/engine-tests.xml on the GPU machine
NOT_ON_GPU = "not run on a GPU yet"

# The list, in its order: test name in the Stability suite, and the
# row's label.
ROWS = [
    ("AxisAlignedRays", "axis-aligned rays (exactly along voxel faces)"),
    ("GrazingRays", "grazing rays (10 to 0.01 degrees to a face)"),
    ("CameraInsideTheData", "camera inside the data"),
    ("CameraAMillionBoxSizesAway", "camera 1e6 box sizes away"),
    ("CoordinatesOffsetBy1e7", "coordinates offset by 1e7"),
    ("Extent1eMinus6", "extent 1e-6"),
    ("Extent1e6", "extent 1e6"),
    ("OnePoint", "one point"),
    ("CoincidentPoints", "coincident points"),
    ("FlatData", "flat data (a plane)"),
    ("CollinearData", "collinear data (a line)"),
    ("Depth21", "depth 21"),
    ("SpecularPower1e4", "specular power 1e4"),
    ("LightInsideAVoxel", "a light inside a voxel"),
    ("RefractionIndex1", "refraction index 1.0"),
    ("RefractionIndex1_5", "refraction index 1.5"),
    ("RefractionIndex10", "refraction index 10"),
    ("TotalInternalReflection", "total internal reflection"),
    ("OpacityZeroEverywhere", "opacity 0 everywhere"),
    ("OpacityOneEverywhere", "opacity 1 everywhere"),
    ("HdrColours", "HDR colours (components above 1)"),
]


def produce(ctx):
    xml = ctx.work_path(CPU_XML)
    if os.path.exists(xml):
        os.remove(xml)
    try:
        ctx.run("stability-cpu", [os.path.join(ctx.bin, "octoray_engine_tests"), "--gtest_filter=*Stability*",
                                  "--gtest_output=xml:" + xml])
    except RuntimeError as e:
        # A failing case is a row of the table (its failure message), not a
        # report that stops; the XML is written either way.
        print(f"report: stability: some cases failed; the table says which\n{e}", flush=True)


def _results(path):
    """{(test, backend): result} of the Stability suite in a GoogleTest XML
    file. GoogleTest 1.12 writes RecordProperty values as <properties> of the
    <testcase>; older versions as attributes of it: both are read."""
    out = {}
    if not path or not os.path.exists(path):
        return out
    root = ET.parse(path).getroot()
    for case in root.iter("testcase"):
        if not case.get("classname", "").endswith("Stability"):
            continue
        name, _, backend = case.get("name", "").partition("/")
        props = {p.get("name"): p.get("value") for p in case.iter("property")}
        for key in ("check", "outcome"):
            props.setdefault(key, case.get(key))
        failure = case.find("failure")
        skipped = case.find("skipped")
        if case.get("status") == "notrun" or case.get("result") == "suppressed":
            status, detail = "not run", ""
        elif failure is not None:
            status, detail = "FAIL", _message(failure)
        elif skipped is not None or case.get("result") == "skipped":
            status, detail = "skipped", _message(skipped) if skipped is not None else ""
        else:
            status, detail = "pass", ""
        out[(name, backend)] = dict(status=status, detail=detail, check=props.get("check") or "",
                                    outcome=props.get("outcome") or "", seconds=float(case.get("time") or 0))
    return out


def _message(element):
    """The message of a <failure> or <skipped>: its text without the leading
    file:line, on one line."""
    text = (element.text or element.get("message") or "").strip()
    lines = [l.strip() for l in text.splitlines() if l.strip()]
    if lines and ":" in lines[0] and lines[0].split(":")[-1].isdigit():
        lines = lines[1:]
    return " ".join(lines)[:300]


def _cell(result, absent):
    if result is None:
        return absent
    if result["status"] == "pass":
        return "pass: " + result["outcome"]
    if result["status"] == "FAIL":
        seen = (" (measured: " + result["outcome"] + ")") if result["outcome"] else ""
        return "**FAIL**: " + result["detail"] + seen
    if result["status"] == "skipped":
        return "skipped: " + result["detail"]
    return result["status"]


def _escape(text):
    return text.replace("|", "\\|").replace("\n", " ")


def render(ctx):
    cpu = _results(ctx.work_path(CPU_XML))
    gpu_path = ctx.gpu_file(GPU_XML)
    gpu = _results(gpu_path)

    known = [name for name, _ in ROWS]
    extra = sorted({name for name, _ in list(cpu) + list(gpu) if name not in known})
    rows = ROWS + [(name, name) for name in extra]  # cases added since this list, so none is dropped

    table, csv_rows = [], []
    for name, label in rows:
        c, g = cpu.get((name, "CPU")), gpu.get((name, "CUDA"))
        check = (c or g or {}).get("check", "")
        cpu_cell = _cell(c, "not run")
        gpu_cell = _cell(g, NOT_ON_GPU if gpu_path is None else "not in the GPU run")
        table.append([label, _escape(check), _escape(cpu_cell), _escape(gpu_cell)])
        csv_rows.append([label, "Backends/Stability." + name, check,
                         c["status"] if c else "not run", c["outcome"] if c else "",
                         g["status"] if g else ("" if gpu_path is None else "not in the GPU run"),
                         g["outcome"] if g else ""])
    csv_link = ctx.write_csv("stability", ["case", "test", "check", "cpu_status", "cpu_outcome", "cuda_status",
                                           "cuda_outcome"], csv_rows)

    def tally(results, backend):
        mine = [r for (n, b), r in results.items() if b == backend]
        ran = [r for r in mine if r["status"] in ("pass", "FAIL")]
        return sum(r["status"] == "pass" for r in ran), len(ran), len(mine)

    cpu_pass, cpu_ran, _ = tally(cpu, "CPU")
    gpu_pass, gpu_ran, gpu_all = tally(gpu, "CUDA")
    if gpu_path is None:
        gpu_text = "CUDA " + NOT_ON_GPU
    elif gpu_ran == 0:
        gpu_text = f"CUDA: {gpu_all} cases in the GPU run, none ran"
    else:
        gpu_text = f"{gpu_pass}/{gpu_ran} CUDA"
    summary = [("numerical stability cases", f"{cpu_pass}/{cpu_ran} pass CPU, {gpu_text}",
                "independent references (brute force in double, analytic)", "–")]

    gpu_source = (f"the GPU run's `{GPU_XML}` in [gpu/](gpu/), made by `{ctx.gpu_command()}`"
                  if gpu_path and ctx.gpu_command() else
                  (f"the GPU run's `{GPU_XML}` in [gpu/](gpu/)" if gpu_path else
                   "no GPU run yet: `octoray_engine_tests --gtest_output=xml:$out/engine-tests.xml` on the GPU "
                   "machine (scripts/gpu/gpu-check.sh) fills it"))
    text = f"""
Every row is a test of the engine's suite `Stability` (Testing/Engine/TestStability.cpp), run by `make test`
on both backends (`Backends/Stability.<case>/CPU` and `/CUDA`; the CUDA half is skipped, with the reason,
where no GPU is usable). Each case renders or builds something extreme and compares it with a reference
made independently of the engine, with the tolerance given in the second column:

- *brute-force first hit*: every pixel's ray tested against every leaf box of the octree in double
  precision (Testing/Engine/TestRenderSupport.h), no traversal, no float. Trustworthy because it is a
  different algorithm in higher precision; where the engine's float ray and the double reference may
  legitimately disagree (a ray grazing a leaf's edge, or meeting two leaves at one distance) the test
  counts a *tie* instead of an error, and only when the reference itself is within the stated margin of
  the other verdict;
- *octree reference*: every node's key, count, children and averaged attributes against a map built by a
  bit-by-bit Morton interleave in double (Testing/Engine/TestSupport.h);
- *analytic*: geometry worked out in double for the scene (a box's outline, the cell under a hit point,
  Snell's law and the critical angle, the Phong formula, the ambient term alone under an enclosed light).

CPU column: `{ctx.command("stability-cpu")}` on this machine. CUDA column: {gpu_source}. Each outcome is the
test's own measurement (its `outcome` property in the XML); a failing case shows its failure message.
Table as CSV: [{csv_link}]({csv_link}).

{ctx.table(["case", "checked against (tolerance)", "CPU outcome", "CUDA outcome"], table, "llll")}
"""
    return Section(text, summary)
