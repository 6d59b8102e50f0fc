#!/usr/bin/python3
"""Regenerates Benchmarks/RESULTS.md, its CSV files and plots (issue 7).

    make report                      # = Benchmarks/Report/make_report.py --build build
    Benchmarks/Report/make_report.py --build build --only quality,stability
    Benchmarks/Report/make_report.py --build build --render-only   # no programs run

Each section of the report is a module `section_<name>.py` beside this file
with

    TITLE = "..."                    # the section's heading
    def produce(ctx): ...            # runs its programs (ctx.run), writes raw
                                     # results under ctx.work
    def render(ctx) -> Section: ...  # reads them (and the GPU run's files in
                                     # ctx.gpu), writes CSV/plots, returns Markdown

`produce` runs on this machine (CPU rows). GPU rows are never measured here:
they are read from Benchmarks/gpu/, the output of scripts/gpu/gpu-check.sh
on a GPU machine, committed with the command that made it (gpu/COMMAND.md).
A section that has no GPU file says so in its table instead of leaving a gap.

Raw results under ctx.work (build/report/) are rebuilt from scratch by every
`produce`; everything `render` writes goes to Benchmarks/ (RESULTS.md)
and Benchmarks/report/ (CSV, PNG) so it can be committed and linked.
"""
import argparse
import csv
import importlib
import json
import os
import re
import shlex
import subprocess
import sys
import time
from dataclasses import dataclass, field

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# The report's order. A module listed here that does not exist yet is skipped
# with a note, so sections can land one at a time.
SECTIONS = [
    "build",        # octree build (CPU vs PCL / VTK locators; CUDA vs the CUB sort), update, memory,
                    # quantisation error vs depth
    "render",       # render throughput per mode (CPU; CUDA)
    "quality",      # render error vs time per quality knob, per scene, per backend
    "stability",    # extreme and stiff cases, both backends
    "pictures",     # the mapper vs vtkPointInterpolator/vtkGaussianSplatter + vtkSmartVolumeMapper,
                    # vtkPointGaussianMapper; the mapper's own cost in a VTK window
    "readers",      # readers vs VTK's own and pandas
    "thesis",       # the thesis's table 2 and two-sphere timings, ours beside them
    "gpu",          # the GPU run's checks: tests and compute-sanitizer
    "mapper",       # the CUDA mapper in VTK windows on the GPU: its tests, memcheck, the orbit
                    # against VTK's GPU mappers
]

README_BEGIN = "<!-- report:summary begin (written by make report) -->"
README_END = "<!-- report:summary end -->"


@dataclass
class Section:
    markdown: str
    # Rows for the README's summary table: (what, octoray, compared with, ratio).
    summary: list = field(default_factory=list)


class Context:
    def __init__(self, build, work, out):
        self.root = ROOT
        self.build = os.path.abspath(build)
        self.bin = os.path.join(self.build, "bin")
        self.work = os.path.abspath(work)
        self.out = os.path.abspath(out)
        self.figures = os.path.join(self.out, "report")
        self.gpu = os.path.join(self.out, "gpu")
        os.makedirs(self.work, exist_ok=True)
        os.makedirs(self.figures, exist_ok=True)
        self.commands = {}

    # ------------------------------------------------------------ running

    def run(self, name, argv, env=None, timeout=3600, display=False):
        """Runs argv (list) from the build folder, logs to work/<name>.log,
        remembers the command (shown in RESULTS.md) and returns stdout.
        display=True: the program needs an X display (the OpenGL pictures);
        without DISPLAY it runs under xvfb-run."""
        argv = [str(a) for a in argv]
        shown = " ".join(shlex.quote(self.relative(a)) for a in argv)
        if display and not os.environ.get("DISPLAY"):
            argv = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24"] + argv
        self.commands[name] = shown
        full_env = dict(os.environ)
        full_env.update(env or {})
        t0 = time.time()
        print(f"report: {name}: {shown}", flush=True)
        proc = subprocess.run(argv, cwd=self.build, env=full_env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, timeout=timeout)
        with open(os.path.join(self.work, name + ".log"), "w") as log:
            log.write(f"$ {shown}\n{proc.stdout}")
        if proc.returncode != 0:
            tail = "\n".join(proc.stdout.splitlines()[-30:])
            raise RuntimeError(f"report: {name} failed (exit {proc.returncode}):\n{tail}")
        print(f"report: {name}: {time.time() - t0:.1f} s", flush=True)
        return proc.stdout

    def command(self, name):
        """The command line a section's figures came from, for the text."""
        return self.commands.get(name) or self._logged_command(name)

    def _logged_command(self, name):
        try:
            with open(os.path.join(self.work, name + ".log")) as log:
                first = log.readline()
            return first[2:].strip() if first.startswith("$ ") else "(not run)"
        except OSError:
            return "(not run)"

    def relative(self, path):
        """Paths inside the repository written relative to it, so commands in
        RESULTS.md read the same on every machine: an argument that is such
        a path, or one that ends with it (--gtest_output=xml:PATH)."""
        if isinstance(path, str) and os.path.isabs(path) and path.startswith(self.root + os.sep):
            return os.path.relpath(path, self.root)
        if isinstance(path, str) and (self.root + os.sep) in path:
            return path.replace(self.root + os.sep, "")
        return path

    # ------------------------------------------------------------ files

    def work_path(self, *parts):
        return os.path.join(self.work, *parts)

    def load_json(self, path):
        with open(path) as f:
            return json.load(f)

    def gpu_file(self, name):
        """A file of the committed GPU run, or None when there is none."""
        path = os.path.join(self.gpu, name)
        return path if os.path.exists(path) else None

    def gpu_call(self, summary):
        """The day and the device of a call of its own, as "DAY on an
        DEVICE" with a link to its closing table (the file `summary`, whose
        heading line gpu-check.sh writes); None where there is none."""
        path = self.gpu_file(summary)
        if not path:
            return None
        with open(path) as f:
            heading = gpu_check_heading(f.read())
        return heading and f"{heading[0]} on an {heading[1]} ([gpu/{summary}](gpu/{summary}))"

    def gpu_command(self):
        path = os.path.join(self.gpu, "COMMAND.md")
        if not os.path.exists(path):
            return None
        # The indented lines of the first block of commands (blank lines
        # between them; the prose after it tells of earlier calls) are the
        # commands (a trailing backslash continues one; a '#' starts a remark
        # on how long it took), joined by "; ".
        commands, current = [], ""
        with open(path) as f:
            for line in f:
                if not line.startswith("    "):
                    if commands and line.strip():
                        break
                    continue
                if commands and not current and line.strip().startswith("#"):
                    break  # the remarks that begin the next call
                current += line.split(" #")[0].strip()
                if current.endswith("\\"):
                    current = current[:-1] + " "
                else:
                    if current:  # a remark alone on its line is no command
                        commands.append(" ".join(current.split()))
                    current = ""
        return "; ".join(commands)

    def write_csv(self, name, header, rows):
        """Writes Benchmarks/report/<name>.csv; returns the link for RESULTS.md."""
        path = os.path.join(self.figures, name + ".csv")
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            w.writerows(rows)
        return "report/" + name + ".csv"

    def figure_path(self, name):
        """(absolute path to save a PNG to, link for RESULTS.md)."""
        return os.path.join(self.figures, name + ".png"), "report/" + name + ".png"

    # ------------------------------------------------------------ text

    @staticmethod
    def table(header, rows, align=None):
        """A Markdown table; align: string of 'l'/'r' per column (default:
        first column left, the rest right)."""
        align = align or ("l" + "r" * (len(header) - 1))
        marks = ["---:" if a == "r" else "---" for a in align]
        lines = ["| " + " | ".join(str(h) for h in header) + " |", "| " + " | ".join(marks) + " |"]
        lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
        return "\n".join(lines)


def gpu_check_heading(text):
    """(day, device) from the heading line that gpu-check.sh writes atop a
    call's closing table ("== octoray GPU check, DAY: DEVICE, driver,
    memory =="); None where the text has none."""
    heading = re.search(r"GPU check, (\d{4}-\d\d-\d\d): ([^,]+),", text)
    return heading.groups() if heading else None


# The gpu-check.sh summaries the GPU sections read: the report's call
# (summary.txt), then the calls that ran compute-sanitizer apart from it
# (COMMAND.md says which): its other tools where the report's call left
# them out, and racecheck, the slowest.
GPU_SUMMARIES = ("summary.txt", "summary-sanitize.txt", "summary-racecheck.txt")

def gpu_summaries(folder, names=GPU_SUMMARIES):
    """[(file name, text)] of the summaries `names` present in `folder`."""
    found = []
    for name in names:
        path = os.path.join(folder, name)
        if os.path.exists(path):
            with open(path) as f:
                found.append((name, f.read()))
    return found


def gpu_summary_link(name):
    """What a row adds to a figure from summary file `name`: nothing for the
    report's call, else a link to the call's file."""
    return "" if name == GPU_SUMMARIES[0] else f" ([gpu/{name}](gpu/{name}))"


def file_parts(path):
    """{header: [lines]} of a GPU record whose parts start with "== header"
    (Benchmarks/gpu's tests and variants files); lines before the first
    header are left out."""
    parts, current = {}, None
    with open(path) as f:
        for line in f:
            if line.startswith("== "):
                current = parts.setdefault(line[3:].strip(), [])
            elif current is not None:
                current.append(line.rstrip("\n"))
    return parts


def load_section(name):
    try:
        return importlib.import_module("section_" + name)
    except ModuleNotFoundError as e:
        if e.name == "section_" + name:
            return None
        raise


def write_readme_summary(rows):
    readme = os.path.join(ROOT, "README.md")
    with open(readme) as f:
        text = f.read()
    if README_BEGIN not in text or README_END not in text:
        print("report: README.md has no summary markers; summary not written", file=sys.stderr)
        return
    table = Context.table(["what", "octoray", "compared with", "ratio"], rows, "lrrr")
    body = (f"{README_BEGIN}\n{table}\n\nFrom [Benchmarks/RESULTS.md](Benchmarks/RESULTS.md), "
            f"where each figure has the command that measured it.\n{README_END}")
    head, rest = text.split(README_BEGIN, 1)
    _, tail = rest.split(README_END, 1)
    with open(readme, "w") as f:
        f.write(head + body + tail)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--work", help="raw results (default: BUILD/report)")
    parser.add_argument("--out", default=os.path.join(ROOT, "Benchmarks"))
    parser.add_argument("--only", help="comma-separated sections to produce (others are re-rendered from earlier raw results)")
    parser.add_argument("--render-only", action="store_true", help="run no program; re-render from raw results")
    args = parser.parse_args()

    sys.path.insert(0, HERE)
    ctx = Context(args.build, args.work or os.path.join(args.build, "report"), args.out)
    only = set(args.only.split(",")) if args.only else None

    parts, summary, missing = [], [], []
    for name in SECTIONS:
        module = load_section(name)
        if module is None:
            missing.append(name)
            continue
        if not args.render_only and (only is None or name in only):
            module.produce(ctx)
        section = module.render(ctx)
        parts.append(f"## {module.TITLE}\n\n{section.markdown.strip()}\n")
        summary += section.summary

    gpu = ctx.gpu_command()
    header = [
        "# Benchmark results and the report",
        "",
        "Written by `make report` (Benchmarks/Report/make_report.py): every table, CSV and plot below",
        "is regenerated from scratch on this machine (CPU rows); GPU rows are read from the files",
        "of the last GPU run in [gpu/](gpu/), made by: " + (f"`{gpu}`" if gpu else "(no GPU run committed)") + ".",
        "Each section gives the command its figures came from. Machines here are shared and",
        "noisy, so speed is reported as a ratio against a peer measured in the same run.",
        "",
    ]
    if missing:
        header += ["Sections not in this report yet: " + ", ".join(missing) + ".", ""]
    if summary:
        header += ["## Summary", "", Context.table(["what", "octoray", "compared with", "ratio"], summary, "lrrr"), ""]
    with open(os.path.join(ctx.out, "RESULTS.md"), "w") as f:
        f.write("\n".join(header) + "\n" + "\n".join(parts))
    if summary:
        write_readme_summary(summary)
    print(f"report: wrote {os.path.join(ctx.out, 'RESULTS.md')}")


if __name__ == "__main__":
    main()
