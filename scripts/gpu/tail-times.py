#!/usr/bin/env python3
"""Where a build from host arrays spends the time after its staging, from
the "tail:" lines that OctreeDriver.h built with
Benchmarks/gpu/variants/tail.patch writes to stderr, one a build from a
caller's host arrays whose sort ran during the upload: host times since the
call began (the staging returned, the records queued, the level sizes read,
the levels queued, the device synchronised) and device times from an event
queued on the default stream once the staging returned ("landed"). The
benchmark's stdout and these lines interleave, so the builds are told apart
by their figures, not by the lines around them: a depth-10 build is one
whose levels took under 0.7 ms at 10 M points and under 8 ms at 100 M
(depth 16 takes 1.6 and 13 ms and more), the sizes by the staging's time. Medians, 10th and
90th percentiles of each.

    tail-times.py LOG    (source-tail.log of source-variants.sh)
"""
import re
import statistics
import sys

FIELDS = ("host: staged", "records queued", "level sizes read", "levels queued", "synchronised",
          "device: landed to records done", "records to levels", "levels", "landed to end")


def main():
    rows = []
    for line in open(sys.argv[1]):
        at = line.find("tail: ")
        if at >= 0:
            rows.append([float(x) for x in re.findall(r"\d+\.\d+", line[at:])])
    groups = {
        "10 M points, depth 10": [r for r in rows if 3.0 < r[0] < 10.0 and r[7] < 0.7],
        "100 M points, depth 10": [r for r in rows if r[0] >= 10.0 and r[7] < 8.0],
    }
    for name, group in groups.items():
        print(f"{name}: {len(group)} builds (ms: median, 10th-90th percentile)")
        for j, field in enumerate(FIELDS):
            values = sorted(r[j] for r in group)
            print("  %-32s %7.3f  %7.3f-%.3f" % (field, statistics.median(values), values[len(values) // 10],
                                                 values[9 * len(values) // 10]))
        after = sorted(r[4] - r[0] for r in group)
        print("  %-32s %7.3f  %7.3f-%.3f" % ("host: staged to synchronised", statistics.median(after),
                                             after[len(after) // 10], after[9 * len(after) // 10]))


if __name__ == "__main__":
    main()
