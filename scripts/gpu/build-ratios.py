#!/usr/bin/env python3
"""The build benchmark's two ratios from octoray_bench_cuda's "build n=...
depth=10" lines (one a build size and round): phases = keys + sort +
levels, the device's, of the builds from device arrays where the line gives
them (since the keys and the sort of a build from host arrays run while its
attributes upload), else of the builds from host arrays; floor = CUB's sort
of the same keys' bits with 32-bit values measured beside it; phases /
floor; and the whole call over the pinned copy of the same bytes (median of
the pairs), as the line gives it. The figures of the variants files'
"summary" lines.

    build-ratios.py LOG...    (source-NAME.log of source-variants.sh)
"""
import re
import sys

LINE = re.compile(r"^build n=(\d+) depth=10: [\d.]+ ms \(upload [\d.]+, keys ([\d.]+), sort ([\d.]+), "
                  r"levels ([\d.]+) ms(?:; from device arrays keys ([\d.]+), sort ([\d.]+), levels ([\d.]+) ms)?\), "
                  r"bare CUB sort ([\d.]+) ms.*whole call ([\d.]+)x")


def main():
    for path in sys.argv[1:]:
        print(f"== {path}")
        for line in open(path):
            m = LINE.match(line)
            if not m:
                continue
            n = int(m.group(1))
            first = 5 if m.group(5) else 2  # the phases from device arrays where given
            phases = sum(float(m.group(k)) for k in range(first, first + 3))
            floor = float(m.group(8))
            print(f"  summary n={n}: phases {phases:.3f} ms, floor {floor:.3f} ms, "
                  f"phases / floor {phases / floor:.2f}, call / pinned copy {m.group(9)}")


if __name__ == "__main__":
    main()
