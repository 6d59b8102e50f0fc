#!/usr/bin/env python3
"""What a kernel's instructions are: from Nsight Compute's source page of
its SASS (ncu --section SourceCounters --page source --print-source sass),
for the K-th table of the file (ncu 2025.3 writes two tables a profiled
kernel, alike: the first kernel's is 0, the second's 2), the warp
instructions executed and the stall samples per opcode, most executed
first, and the most sampled instructions. Used on the build's leaf and inner
loops (Benchmarks/gpu/variants-leaf-loop.txt) and on the render kernel's
traversal (variants-mirror-table.txt).

    ncu-sass-opcodes.py SOURCE.txt [K] [--loop]

With --loop, the hottest loop instead: the instructions executed at least
a quarter as often as the most executed one (a loop's body, its branches
that most steps take, and its joins, which both sides of a branch execute),
in order, with their counts and stall samples; its steps, the count most of
those instructions share; and the warp instructions a step, all the
kernel's executed instructions over its steps.
"""
import collections
import sys


def tables(lines):
    """(first line, last line) of each table: its header starts with "Address"."""
    starts = [i for i, line in enumerate(lines) if line.startswith("Address ")]
    return list(zip(starts, starts[1:] + [len(lines)]))


def instructions(lines, first, last):
    """(SASS text, stall samples, warp instructions executed) per row."""
    numbers_at = lines[first].index("Warp S")  # the first counter column
    for line in lines[first + 1:last]:
        if not line.startswith("0x"):
            continue
        fields = line[numbers_at:].split()
        try:
            samples, executed = int(fields[0]), int(fields[3])
        except (IndexError, ValueError):
            continue
        yield line[19:numbers_at].strip(), samples, executed


def opcode(sass):
    words = sass.split()
    word = words[1] if words[0].startswith("@") else words[0]
    return word.split(".")[0]


def print_loop(rows):
    most = max(count for _, _, count in rows)
    hot = [(sass, samples, count) for sass, samples, count in rows if count * 4 >= most]
    steps = collections.Counter(count for _, _, count in hot).most_common(1)[0][0]
    total = sum(count for _, _, count in rows)
    print(f"{len(hot)} instructions in the loop, {steps} steps; {total} warp instructions executed, "
          f"{total / steps:.1f} a step")
    print("executed, samples, instruction")
    for sass, samples, count in hot:
        print(f"  {count:10d} {samples:7d}  {sass[:70]}")


def main():
    args = [a for a in sys.argv[1:] if a != "--loop"]
    lines = open(args[0]).read().split("\n")
    k = int(args[1]) if len(args) > 1 else 0
    rows = list(instructions(lines, *tables(lines)[k]))
    if "--loop" in sys.argv:
        print_loop(rows)
        return
    executed = collections.Counter()
    sampled = collections.Counter()
    for sass, samples, count in rows:
        executed[opcode(sass)] += count
        sampled[opcode(sass)] += samples
    print(f"{len(rows)} instructions, {sum(sampled.values())} stall samples, "
          f"{sum(executed.values())} warp instructions executed")
    print("by opcode: warp instructions executed, stall samples")
    for name, count in executed.most_common(25):
        print(f"  {name:10s} {count:12d} {sampled[name]:8d}")
    print("most sampled: samples, executed, instruction")
    for sass, samples, count in sorted(rows, key=lambda r: -r[1])[:16]:
        print(f"  {samples:7d} {count:10d}  {sass[:70]}")


if __name__ == "__main__":
    main()
