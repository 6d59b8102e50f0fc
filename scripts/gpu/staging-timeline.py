#!/usr/bin/env python3
"""Where a staged copy's time goes, from the timeline that the diagnostic
variant of CudaUpload.h writes (Benchmarks/gpu/variants/staging-timeline.patch,
$OCTORAY_STAGING_TIMELINE): for each timed copy, the time until the first
DMA could start (the first pieces' host copies), the copy engine's idle
time in between (a piece's DMA starts at the latest of its host copy's end
and the previous DMA's end, and lasts its bytes at RATE), the tail after
the last host copy, and the staging threads' end spread and time blocked
waiting for their buffers' DMAs. Medians over the copies of a size and kind.

    staging-timeline.py TIMELINE [RATE_GB_S]   (RATE: the pinned copy's, 54.8 by default)
    staging-timeline.py --lanes TIMELINE       (each copy's threads: when their last host
                                                copy ended / how long they copied, ms)
"""
import re
import statistics
import sys
from collections import defaultdict

COPY = re.compile(r"^copy (\d+) bytes (\d+) parts (\d+) landed (\d+) total_us ([\d.]+)")
PIECE = re.compile(r"^piece lane (\d+) n (\d+) bytes (\d+) wait0 ([\d.]+) wait1 ([\d.]+) copied ([\d.]+) "
                   r"dma_done ([-\d.]+)")


def read(path):
    copies, current = [], None
    for line in open(path):
        m = COPY.match(line)
        if m:
            current = {"bytes": int(m.group(2)), "landed": int(m.group(4)) > 0, "total": float(m.group(5)),
                       "pieces": []}
            copies.append(current)
            continue
        m = PIECE.match(line)
        if m and current is not None:
            lane, n, b = (int(m.group(k)) for k in (1, 2, 3))
            w0, w1, c, d = (float(m.group(k)) for k in (4, 5, 6, 7))
            current["pieces"].append({"lane": lane, "n": n, "bytes": b, "w0": w0, "w1": w1, "copied": c, "done": d})
    return copies


def analyse(copy, rate):
    """Microseconds: first DMA start, engine idle after it, tail after the
    last host copy, lanes' end spread, blocked time per lane (median), the
    engine's busy time at RATE."""
    pieces = sorted(copy["pieces"], key=lambda p: p["done"])
    us_per_byte = 1e-3 / rate  # rate in GB/s: bytes / (rate * 1e3) us
    busy = sum(p["bytes"] for p in pieces) * us_per_byte
    first_start = min(p["copied"] for p in pieces)
    engine_free, idle = first_start, 0.0
    for p in sorted(pieces, key=lambda p: p["copied"]):
        start = max(p["copied"], engine_free)
        idle += start - engine_free
        engine_free = start + p["bytes"] * us_per_byte
    last_copied = max(p["copied"] for p in pieces)
    last_done = max(p["done"] for p in pieces)
    lanes = defaultdict(list)
    for p in pieces:
        lanes[p["lane"]].append(p)
    ends = [max(q["done"] for q in ps) for ps in lanes.values()]
    host_ends = [max(q["copied"] for q in ps) for ps in lanes.values()]
    blocked = [sum(q["w1"] - q["w0"] for q in ps) for ps in lanes.values()]
    copying = [sum(q["copied"] - q["w1"] for q in ps) for ps in lanes.values()]
    return {
        "total": copy["total"], "busy": busy, "first DMA start": first_start, "engine idle after": idle,
        "modelled end": engine_free, "measured last DMA": last_done, "tail after last host copy": last_done - last_copied,
        "host copies end spread": max(host_ends) - min(host_ends), "lanes' end spread": max(ends) - min(ends),
        "blocked a lane": statistics.median(blocked), "copying a lane": statistics.median(copying),
        "pieces": len(pieces),
        "DMA rate from first start, GB/s": sum(p["bytes"] for p in pieces) / (last_done - first_start) / 1e3,
    }


def print_lanes(copies):
    for copy in copies:
        lanes = defaultdict(list)
        for p in copy["pieces"]:
            lanes[p["lane"]].append(p)
        cells = [f"{max(q['copied'] for q in ps) / 1e3:.1f}/{sum(q['copied'] - q['w1'] for q in ps) / 1e3:.1f}"
                 for _, ps in sorted(lanes.items())]
        print(f"{copy['bytes'] / 1e6:.0f} MB {'build' if copy['landed'] else 'alone'} "
              f"{copy['total'] / 1e3:.2f} ms: " + " ".join(cells))


def main():
    if sys.argv[1] == "--lanes":
        print_lanes(read(sys.argv[2]))
        return
    path = sys.argv[1]
    rate = float(sys.argv[2]) if len(sys.argv) > 2 else 54.8
    groups = defaultdict(list)
    for copy in read(path):
        if copy["pieces"]:
            groups[(copy["bytes"], copy["landed"])].append(analyse(copy, rate))
    for (size, landed), rows in sorted(groups.items()):
        print(f"== {size / 1e6:.0f} MB, {'a build (pieces reduced as they land)' if landed else 'the staged copy alone'}: "
              f"{len(rows)} copies, medians in us (the copy engine modelled at {rate} GB/s)")
        for key in rows[0]:
            values = [r[key] for r in rows]
            print(f"  {key:28s} {statistics.median(values):10.1f}   ({min(values):.1f} - {max(values):.1f})")


if __name__ == "__main__":
    main()
