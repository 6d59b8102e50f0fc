#!/usr/bin/env python3
"""Where a build's device time goes: from an Nsight Compute CSV of every
kernel of a program (ncu --csv --page raw --metrics gpu__time_duration.sum),
the time per kernel name summed over the launches of the last of BUILDS
equal runs, longest first, with the launch count. Used by gpu-check.sh's
profile-build part on `octoray_bench_cuda --profile-build N` (two builds).

    ncu-kernel-times.py PROFILE.csv [BUILDS]
"""
import csv
import re
import sys


def launches(path):
    with open(path, newline="") as f:
        lines = f.read().splitlines()
    start = next((i for i, line in enumerate(lines) if line.startswith('"ID"')), None)
    if start is None:
        raise SystemExit(f"{path}: no CSV header; is it ncu --csv output?")
    table = list(csv.DictReader(lines[start:]))
    units = table[0] if table and not table[0]["ID"].strip().isdigit() else None
    scale = {"nsecond": 1e-6, "usecond": 1e-3, "msecond": 1.0, "second": 1e3}.get(
        (units or {}).get("gpu__time_duration.sum", "nsecond"), 1e-6)
    for row in table:
        if not row["ID"].strip().isdigit():
            continue
        full = row["Kernel Name"]
        # Lambdas of one function differ only in their number: keep it.
        lambdas = re.findall(r"\{lambda\([^)]*\)#(\d+)\}", full)
        name = re.sub(r"\(.*", "", full).strip()[:100] + "".join(" lambda #" + n for n in lambdas[-1:])
        yield name, float(row["gpu__time_duration.sum"].replace(",", "")) * scale


def main():
    path = sys.argv[1]
    builds = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    everything = list(launches(path))
    last = everything[len(everything) - len(everything) // builds:]
    per = {}
    for name, ms in last:
        total, count = per.get(name, (0.0, 0))
        per[name] = (total + ms, count + 1)
    total = sum(t for t, _ in per.values())
    print(f"{path}: the last of {builds} builds, {len(last)} kernel launches, {total:.3f} ms of kernels")
    for name, (ms, count) in sorted(per.items(), key=lambda kv: -kv[1][0]):
        print(f"  {ms:9.3f} ms {100 * ms / total:5.1f}%  {count:4d}x  {name}")


if __name__ == "__main__":
    main()
