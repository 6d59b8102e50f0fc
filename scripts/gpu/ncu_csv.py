"""The table of an Nsight Compute CSV (ncu --csv, any page): its rows as
dicts, from the "ID" header on (ncu writes its own messages before it).
Shared by ncu-summary.py and ncu-kernel-times.py."""
import csv


def rows(path):
    with open(path, newline="") as f:
        lines = f.read().splitlines()
    start = next((i for i, line in enumerate(lines) if line.startswith('"ID"')), None)
    if start is None:
        raise SystemExit(f"{path}: no CSV header; is it ncu --csv output?")
    return list(csv.DictReader(lines[start:]))
