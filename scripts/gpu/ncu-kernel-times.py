#!/usr/bin/env python3
"""Where a build's device time goes: from an Nsight Compute CSV of every
kernel of a program (ncu --csv --page raw --metrics gpu__time_duration.sum),
the time per kernel name summed over the launches of the last of BUILDS
equal runs, longest first, with the launch count. Used by gpu-check.sh's
profile-build part on `octoray_bench_cuda --profile-build N` (two builds).

    ncu-kernel-times.py PROFILE.csv [BUILDS]
"""
import re
import sys

from ncu_csv import rows


def launches(path):
    table = rows(path)
    units = table[0] if table and not table[0]["ID"].strip().isdigit() else None
    scale = {"nsecond": 1e-6, "usecond": 1e-3, "msecond": 1.0, "second": 1e3}.get(
        (units or {}).get("gpu__time_duration.sum", "nsecond"), 1e-6)
    for row in table:
        if not row["ID"].strip().isdigit():
            continue
        yield row["Kernel Name"], float(row["gpu__time_duration.sum"].replace(",", "")) * scale


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
    path = sys.argv[1]
    builds = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    everything = list(launches(path))
    last = everything[len(everything) - len(everything) // builds:]
    names = short_names(dict.fromkeys(full for full, _ in everything))
    per = {}
    for full, ms in last:
        name = names[full]
        total, count = per.get(name, (0.0, 0))
        per[name] = (total + ms, count + 1)
    total = sum(t for t, _ in per.values())
    print(f"{path}: the last of {builds} builds, {len(last)} kernel launches, {total:.3f} ms of kernels")
    for name, (ms, count) in sorted(per.items(), key=lambda kv: -kv[1][0]):
        print(f"  {ms:9.3f} ms {100 * ms / total:5.1f}%  {count:4d}x  {name}")


if __name__ == "__main__":
    main()
