#!/usr/bin/python3
"""Checks that a fetched point-cloud file is what Data/README.md says it is.

    /usr/bin/python3 scripts/data/headers.py FILE pcd POINTS WIDTH HEIGHT DATA FIELD...
    /usr/bin/python3 scripts/data/headers.py FILE ply VERTICES

pcd: the header (PCL's PCD v0.7) has POINTS, WIDTH, HEIGHT, DATA (ascii,
binary, binary_compressed) and FIELDS as given; the body is as long as the
header says (ascii: one line per point; binary: POINTS * point size bytes;
binary_compressed: the compressed size after its two sizes, and an
uncompressed size of POINTS * point size).
ply: an ASCII PLY whose `element vertex` count is VERTICES, with that many
vertex lines of as many numbers as vertex properties, then the other elements.
Prints one line that describes the file; exits with a message that names the
file otherwise.
"""
import struct
import sys


def fail(path, msg):
    sys.exit("fetch-data: %s: %s" % (path, msg))


def pcd(path, points, width, height, data, fields):
    with open(path, "rb") as f:
        raw = f.read()
    header, pos = {}, 0
    while "DATA" not in header:
        end = raw.find(b"\n", pos)
        if end < 0:
            fail(path, "no DATA line in the PCD header")
        line = raw[pos:end].decode("ascii", "replace").strip()
        pos = end + 1
        if line and not line.startswith("#"):
            key, *values = line.split()
            header[key] = values
    want = {"POINTS": [points], "WIDTH": [width], "HEIGHT": [height], "DATA": [data],
            "FIELDS": fields.split()}
    for key, value in want.items():
        if header.get(key) != value:
            fail(path, "PCD header has %s %s, expected %s"
                 % (key, " ".join(header.get(key, ["(none)"])), " ".join(value)))
    n = int(points)
    size = sum(int(s) * int(c) for s, c in zip(header["SIZE"], header.get("COUNT", ["1"] * 99)))
    body = raw[pos:]
    if data == "ascii":
        lines = [l for l in body.split(b"\n") if l.strip()]
        if len(lines) != n or any(len(l.split()) != len(want["FIELDS"]) for l in (lines[0], lines[-1])):
            fail(path, "%d data lines, expected %d of %d values" % (len(lines), n, len(want["FIELDS"])))
    elif data == "binary":
        if len(body) != n * size:
            fail(path, "%d data bytes, expected %d points of %d bytes" % (len(body), n, size))
    else:
        compressed, uncompressed = struct.unpack("<II", body[:8])
        if uncompressed != n * size or 8 + compressed > len(body):
            fail(path, "compressed block of %d bytes (file has %d) expanding to %d, expected %d"
                 % (compressed, len(body) - 8, uncompressed, n * size))
    print("fetch-data: %s: PCD %s, %d points (%sx%s), fields %s"
          % (path, data, n, width, height, fields))


def ply(path, vertices):
    with open(path, "rb") as f:
        lines = f.read().split(b"\n")
    if lines[0].strip() != b"ply" or lines[1].split()[:2] != [b"format", b"ascii"]:
        fail(path, "not an ASCII PLY file")
    elements, props, i = [], 0, 2
    while lines[i].strip() != b"end_header":
        words = lines[i].split()
        if words[:1] == [b"element"]:
            elements.append((words[1].decode(), int(words[2])))
        elif words[:1] == [b"property"] and elements[-1][0] == "vertex":
            props += 1
        i += 1
        if i >= len(lines):
            fail(path, "no end_header")
    counts = dict(elements)
    if counts.get("vertex") != int(vertices):
        fail(path, "element vertex %s, expected %s" % (counts.get("vertex"), vertices))
    body = [l for l in lines[i + 1:] if l.strip()]
    if len(body) != sum(counts.values()):
        fail(path, "%d lines after the header, the elements %s need %d"
             % (len(body), counts, sum(counts.values())))
    first_elem = elements[0][0]
    if first_elem == "vertex":
        for line in (body[0], body[counts["vertex"] - 1]):
            if len(line.split()) != props:
                fail(path, "vertex line %r has not %d values" % (line[:80], props))
    print("fetch-data: %s: PLY ascii, %s" % (path, ", ".join("%d %s" % (c, e) for e, c in elements)))


if __name__ == "__main__":
    if len(sys.argv) >= 8 and sys.argv[2] == "pcd":
        pcd(sys.argv[1], *sys.argv[3:7], " ".join(sys.argv[7:]))
    elif len(sys.argv) == 4 and sys.argv[2] == "ply":
        ply(sys.argv[1], sys.argv[3])
    else:
        sys.exit(__doc__)
