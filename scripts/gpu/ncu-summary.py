#!/usr/bin/env python3
"""A short table from Nsight Compute's CSV details pages (ncu --csv --page
details): per profiled kernel, its time, memory and compute throughput,
cache hit rates, occupancy, registers and the top stall reasons (warp cycles
per issued instruction spent in each). Used by gpu-check.sh's profile part.

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
]
STALL_PREFIX = "smsp__average_warps_issue_stalled_"
STALL_SUFFIX = "_per_issue_active.ratio"


def summarise(path):
    table = rows(path)
    if not table:
        print(f"{path}: no kernel profiled")
        return
    kernel = table[0]["Kernel Name"]
    values = {r["Metric Name"]: (r["Metric Value"], r["Metric Unit"]) for r in table}
    print(f"{path.rsplit('/', 1)[-1]}: {kernel[:100]}")
    for label, name in FIGURES:
        if name in values:
            value, unit = values[name]
            print(f"  {label:36s} {value} {unit}")
    stalls = []
    for name, (value, _) in values.items():
        # "selected" is the cycle a warp issues, not a stall.
        if name.startswith(STALL_PREFIX) and name.endswith(STALL_SUFFIX) and name != STALL_PREFIX + "selected" + STALL_SUFFIX:
            try:
                stalls.append((float(value.replace(",", "")), name[len(STALL_PREFIX):-len(STALL_SUFFIX)]))
            except ValueError:
                pass
    stalls.sort(reverse=True)
    if stalls:
        total = sum(s for s, _ in stalls)
        top = ", ".join(f"{reason} {cycles:.1f} ({100 * cycles / total:.0f}%)" for cycles, reason in stalls[:5])
        print(f"  {'top stalls, cycles per issue':36s} {top}")


for p in sys.argv[1:]:
    summarise(p)
