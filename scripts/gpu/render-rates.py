#!/usr/bin/env python3
"""The render benchmark's rates over rounds: for each frame of
octoray_bench_cuda's "render depth D, KIND: ... N Mrays/s" lines (one a
frame and round), the lowest, highest and mean Mrays/s. The figures of the
render variants' "summary" lines.

    render-rates.py LOG...    (source-NAME.log of source-variants.sh)
"""
import collections
import re
import statistics
import sys

LINE = re.compile(r"^render (depth \d+, [^:]+): .*?([\d.]+) Mrays/s")


def main():
    for path in sys.argv[1:]:
        print(f"== {path}")
        rates = collections.defaultdict(list)
        for line in open(path):
            m = LINE.match(line)
            if m:
                rates[m.group(1)].append(float(m.group(2)))
        for frame, values in rates.items():
            print(f"  summary {frame}: {min(values):.0f}-{max(values):.0f} Mrays/s, "
                  f"mean {statistics.mean(values):.0f} over {len(values)} rounds")


if __name__ == "__main__":
    main()
