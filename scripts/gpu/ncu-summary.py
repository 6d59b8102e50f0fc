#!/usr/bin/env python3
"""A short table from Nsight Compute's CSV details pages (ncu --csv --page
details): per profiled launch, its time, memory and compute throughput,
cache hit rates, occupancy, registers and the top stall reasons (warp cycles
per issued instruction spent in each). Used by gpu-check.sh's profile part
and variants-check.sh's render section (ncu-render.sh makes the CSV).

    ncu-summary.py PROFILE.csv...
"""
import sys

from ncu_csv import rows

# (label, ncu's metric name as the details page writes it)
FIGURES = [
    ("duration", "Duration"),
    ("memory throughput", "Memory Throughput"),
    ("DRAM throughput", "DRAM Throughput"),
    ("L1/TEX hit rate", "L1/TEX Hit Rate"),
    ("L2 hit rate", "L2 Hit Rate"),
    ("compute (SM) throughput", "Compute (SM) Throughput"),
    ("achieved occupancy", "Achieved Occupancy"),
    ("theoretical occupancy", "Theoretical Occupancy"),
    ("registers per thread", "Registers Per Thread"),
    ("warp cycles per issued instruction", "Warp Cycles Per Issued Instruction"),
    ("executed instructions", "Executed Instructions"),
    ("issue slots busy", "Issue Slots Busy"),
    ("active threads per warp", "Avg. Active Threads Per Warp"),
]
STALL_PREFIX = "smsp__average_warps_issue_stalled_"
STALL_SUFFIX = "_per_issue_active.ratio"
PIPE_PREFIX = "sm__inst_executed_pipe_"
PIPE_SUFFIX = ".avg.pct_of_peak_sustained_active"


def top(values, prefix, suffix, skip=()):
    """The five largest figures of the metrics named prefix + X + suffix."""
    found = []
    for name, (value, _) in values.items():
        reason = name[len(prefix):-len(suffix)]
        if name.startswith(prefix) and name.endswith(suffix) and reason not in skip:
            try:
                found.append((float(value.replace(",", "")), reason))
            except ValueError:
                pass
    return sorted(found, reverse=True)[:5], sum(v for v, _ in found)


def summarise(path):
    table = rows(path)
    if not table:
        print(f"{path}: no kernel profiled")
        return
    launches = {}  # each profiled launch's rows, by its ID, in order
    for r in table:
        launches.setdefault(r["ID"], []).append(r)
    for launch in launches.values():
        summarise_launch(path, launch)


def summarise_launch(path, table):
    kernel = table[0]["Kernel Name"]
    values = {r["Metric Name"]: (r["Metric Value"], r["Metric Unit"]) for r in table}
    print(f"{path.rsplit('/', 1)[-1]}: {kernel[:100]}")
    for label, name in FIGURES:
        if name in values:
            value, unit = values[name]
            print(f"  {label:36s} {value} {unit}")
    # "selected" is the cycle a warp issues, not a stall.
    stalls, total = top(values, STALL_PREFIX, STALL_SUFFIX, skip=("selected",))
    if stalls:
        listed = ", ".join(f"{reason} {cycles:.1f} ({100 * cycles / total:.0f}%)" for cycles, reason in stalls)
        print(f"  {'top stalls, cycles per issue':36s} {listed}")
    pipes, _ = top(values, PIPE_PREFIX, PIPE_SUFFIX)
    if pipes:
        listed = ", ".join(f"{pipe} {share:.0f}%" for share, pipe in pipes)
        print(f"  {'busiest pipes, % of peak':36s} {listed}")


for p in sys.argv[1:]:
    summarise(p)
