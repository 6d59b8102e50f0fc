#!/usr/bin/env python3
"""Where a build's device time goes: from an Nsight Compute CSV of every
kernel of a program (ncu --csv --page raw --metrics
gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum), the
time per kernel name summed over the launches of the last of BUILDS equal
runs, longest first, with the launch count and, where the CSV has the DRAM
bytes, the DRAM traffic and its rate. Used by gpu-check.sh's profile-build
part on `octoray_bench_cuda --profile-build N` (two builds).

    ncu-kernel-times.py PROFILE.csv [BUILDS] [--launches]

With --launches, every launch of that last run in order instead, in
microseconds (the level phase's selects and loops, level by level).
"""
import re
import sys

from ncu_csv import rows

# The units row's names, as this ncu writes them ("ns", "byte") and as
# older ones did ("nsecond", "Kbyte").
TIME_TO_MS = {"ns": 1e-6, "nsecond": 1e-6, "us": 1e-3, "usecond": 1e-3, "ms": 1.0, "msecond": 1.0, "s": 1e3,
              "second": 1e3}
BYTES_TO_GB = {"byte": 1e-9, "Kbyte": 1e-6, "KB": 1e-6, "Mbyte": 1e-3, "MB": 1e-3, "Gbyte": 1.0, "GB": 1.0}
DRAM = ("dram__bytes_read.sum", "dram__bytes_write.sum")


def launches(path):
    """(kernel name, ms, DRAM GB or None) per launch."""
    table = rows(path)
    units = table[0] if table and not table[0]["ID"].strip().isdigit() else {}

    def value(row, metric, scales, default_unit):
        return float(row[metric].replace(",", "")) * scales[units.get(metric, default_unit)]

    for row in table:
        if not row["ID"].strip().isdigit():
            continue
        gb = sum(value(row, m, BYTES_TO_GB, "byte") for m in DRAM) if all(m in row for m in DRAM) else None
        yield row["Kernel Name"], value(row, "gpu__time_duration.sum", TIME_TO_MS, "nsecond"), gb


def short_names(full_names):
    """Each full kernel name shortened to its template head; names that
    shorten alike (a function's lambdas, which differ only in how the
    profiler numbers them) are told apart by a variant number."""
    heads = {}
    for full in full_names:
        heads.setdefault(re.sub(r"\(.*", "", full).strip()[:100], []).append(full)
    out = {}
    for head, fulls in heads.items():
        for k, full in enumerate(fulls):
            out[full] = head if len(fulls) == 1 else f"{head} (variant {k + 1})"
    return out



def main():
    args = [a for a in sys.argv[1:] if a != "--launches"]
    path = args[0]
    builds = int(args[1]) if len(args) > 1 else 2
    everything = list(launches(path))
    last = everything[len(everything) - len(everything) // builds:]
    names = short_names(dict.fromkeys(full for full, _, _ in everything))
    if "--launches" in sys.argv:
        print(f"{path}: the last of {builds} builds, every launch in order")
        for full, ms, _ in last:
            print(f"  {1000 * ms:9.1f} us  {names[full]}")
        return
    per = {}
    for full, ms, gb in last:
        total, count, traffic = per.get(names[full], (0.0, 0, 0.0))
        per[names[full]] = (total + ms, count + 1, None if gb is None or traffic is None else traffic + gb)
    total = sum(t for t, _, _ in per.values())
    print(f"{path}: the last of {builds} builds, {len(last)} kernel launches, {total:.3f} ms of kernels")
    for name, (ms, count, gb) in sorted(per.items(), key=lambda kv: -kv[1][0]):
        dram = f"  {gb:7.3f} GB DRAM {gb / ms:6.2f} TB/s" if gb is not None and ms > 0 else ""
        print(f"  {ms:9.3f} ms {100 * ms / total:5.1f}%  {count:4d}x{dram}  {name}")


if __name__ == "__main__":
    main()
