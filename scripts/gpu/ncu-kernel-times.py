#!/usr/bin/env python3
"""Where a build's device time goes: from an Nsight Compute CSV of every
kernel of a program (ncu --csv --page raw --metrics
gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum), the
time per kernel name summed over the launches of the last of BUILDS equal
runs, longest first, with the launch count and, where the CSV has the DRAM
bytes, the DRAM traffic and its rate. Used by gpu-check.sh's profile-build
part on `octoray_bench_cuda --profile-build N` (two builds).

    ncu-kernel-times.py PROFILE.csv [BUILDS] [--launches | --steps]

With --launches, every launch of that last run in order instead, in
microseconds (the level phase's selects and loops, level by level). With
--steps, the last run's launches summed by the build's steps, in the order
the build queues them: the positions' bounds (during the upload), the keys,
the records, the sort, the levels' run starts counted with their sizes and
placed (before cd56a2a: the histogram of neighbouring keys), the records
gathered in sorted order (a build from host arrays from 022a550 to
607a057), then each level from the leaves (level 10, the depth of
--profile-build) up (a loop each; before cd56a2a a CUB select and a loop,
the select beginning with its DeviceCompactInitKernel), the levels near
the root in one launch
(SmallLevelsKernel), and the device phases' sum (keys, sort, level sizes,
levels: what the benchmark's phases of a build from device arrays time, but
the records; such a build gathers none).
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



# The build's steps before its levels, by a piece of each kernel's name.
# The first that matches names the step (the histogram's kernel is a
# lambda of QueueSort, as the keys' is).
STEPS = (("positions' bounds (in the upload)", ("ReduceRangeKernel", "reduce::DeviceReduce")),
         ("histogram of neighbouring keys", ("cuda::HistogramKernel",)),
         ("levels' run starts counted, their sizes", ("NestedCountKernel", "scan::DeviceScan")),
         ("levels' run starts placed", ("NestedPlaceKernel",)),
         ("records", ("IngestAttributes",)),
         ("records gathered in sorted order", ("GatherSortedRecords",)),
         ("sort (CUB)", ("DeviceRadixSort",)),
         ("keys", ("QueueSort",)))
PHASES = ("keys", "sort (CUB)", "histogram of neighbouring keys", "levels' run starts counted, their sizes",
          "levels' run starts placed")
PROFILE_BUILD_DEPTH = 10  # octoray_bench_cuda --profile-build's
SMALL_LEVELS = "levels near the root (one launch)"


def steps(last):
    """(step, launches, ms, GB or None) for the run's launches, in order;
    the levels from the leaves (the depth) up to the root (level 0), each
    from its select's init kernel where it has a select (builds before
    cd56a2a), else its loop."""
    table, levels, selected = {}, 0, False
    for full, ms, gb in last:
        step = next((name for name, keys in STEPS if any(k in full for k in keys)), None)
        if "DeviceCompactInitKernel" in full:
            levels, selected = levels + 1, True
        elif "LinkLevels" in full or "ReduceNodes" in full:  # the level loops' lambdas (ReduceNodes since 4881ff3)
            levels, selected = levels + (0 if selected else 1), False
        if "SmallLevelsKernel" in full:
            step = SMALL_LEVELS
        elif step is None or selected:
            step = -levels  # a level, counted from the leaves; named below
        count, total, traffic = table.get(step, (0, 0.0, 0.0))
        table[step] = (count + 1, total + ms, None if gb is None or traffic is None else traffic + gb)

    def name(step):
        if not isinstance(step, int):
            return step
        level = PROFILE_BUILD_DEPTH + 1 + step
        return "other" if step == 0 else f"leaves (level {level})" if step == -1 else f"level {level}"
    return [(name(step),) + values for step, values in table.items()]


def print_steps(path, builds, last):
    print(f"{path}: the last of {builds} builds by step")
    phases = 0.0
    for step, count, ms, gb in steps(last):
        if step in PHASES or step == SMALL_LEVELS or step.startswith(("leaves", "level ")):
            phases += ms
        dram = f"  {gb:6.3f} GB {gb / ms:5.2f} TB/s" if gb is not None and ms > 0 else ""
        print(f"  {1000 * ms:8.1f} us  {count:3d}x{dram}  {step}")
    print(f"  {1000 * phases:8.1f} us        device phases (keys, sort, level sizes, levels)")


def main():
    args = [a for a in sys.argv[1:] if a not in ("--launches", "--steps")]
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
    if "--steps" in sys.argv:
        print_steps(path, builds, last)
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
