#!/usr/bin/env python3
"""Writes the seed corpus of the PCD fuzz target (Testing/Fuzz/corpus/pcd; run
once, the files are committed). Each seed starts with the target's flag byte
(bit 0: double precision; bits 1-7 size the raw LZF decoder's output), then a
PCD file: the three DATA forms of a small organised cloud with every kind of
field, old and reordered headers, and the damaged files of the reader's
tests. binary_compressed bodies are made by the LZF compressor below (greedy
3-byte matches, overlapping runs included)."""
import os
import struct

here = os.path.dirname(os.path.abspath(__file__))
out_dir = os.path.join(here, "corpus", "pcd")


def lzf(data):
    out, lit, table, i, n = bytearray(), bytearray(), {}, 0, len(data)

    def flush():
        for k in range(0, len(lit), 32):
            run = lit[k:k + 32]
            out.append(len(run) - 1)
            out.extend(run)
        lit.clear()

    while i < n:
        key = data[i:i + 3]
        cand = table.get(key) if len(key) == 3 else None
        if len(key) == 3:
            table[key] = i
        if cand is not None and i - cand <= 8192:
            length = 3
            while i + length < n and length < 264 and data[cand + length] == data[i + length]:
                length += 1
            flush()
            d, l = i - cand - 1, length - 2
            if l < 7:
                out.append((l << 5) | (d >> 8))
            else:
                out += bytes([(7 << 5) | (d >> 8), l - 7])
            out.append(d & 255)
            i += length
        else:
            lit.append(data[i])
            i += 1
    flush()
    return bytes(out)


FIELDS = [("x", "F", 4, 1), ("y", "F", 4, 1), ("z", "F", 4, 1), ("rgb", "U", 4, 1),
          ("intensity", "F", 4, 1), ("normal_x", "F", 4, 1), ("normal_y", "F", 4, 1),
          ("normal_z", "F", 4, 1), ("_", "U", 1, 2), ("label", "I", 2, 1), ("t", "F", 8, 1),
          ("fpfh", "F", 4, 3)]
FMT = {("F", 4): "f", ("F", 8): "d", ("U", 1): "B", ("U", 4): "I", ("I", 2): "h"}


def header(fields, w, h, form):
    cols = lambda k: " ".join(str(f[k]) for f in fields)
    return ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS %s\nSIZE %s\nTYPE %s\n"
            "COUNT %s\nWIDTH %d\nHEIGHT %d\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA %s\n"
            % (cols(0), cols(2), cols(1), cols(3), w, h, w * h, form)).encode()


def cloud(w=3, h=2):
    nan = float("nan")
    pts = []
    for p in range(w * h):
        xyz = (nan, nan, nan) if p == 4 else (p * 0.5, -p, 1.0 + p)
        pts.append(list(xyz) + [0xFF102030 + p, 0.25 * p, 0.0, 0.6, -0.8, 7, 8, -3 + p,
                                1e9 + p, p, 2 * p, 3 * p])
    return pts


def encode(fields, w, h, pts, form):
    out = header(fields, w, h, form)
    if form == "ascii":
        for p in pts:
            out += (" ".join("nan" if v != v else repr(v) if isinstance(v, float) else str(v)
                             for v in p) + "\n").encode()
        return out
    def put(f, v):
        return struct.pack("<" + FMT[(f[1], f[2])], v)
    if form == "binary":
        for p in pts:
            k = 0
            for f in fields:
                for c in range(f[3]):
                    out += put(f, p[k])
                    k += 1
        return out
    block, k = b"", 0
    for f in fields:
        if f[0] != "_":
            for p in pts:
                for c in range(f[3]):
                    block += put(f, p[k + c])
        k += f[3]
    z = lzf(block)
    return out + struct.pack("<II", len(z), len(block)) + z


seeds = {}
for form in ("ascii", "binary", "binary_compressed"):
    seeds["rich_" + form] = encode(FIELDS, 3, 2, cloud(), form)
rgba = [("x", "F", 4, 1), ("y", "F", 4, 1), ("z", "F", 4, 1), ("rgba", "U", 4, 1)]
seeds["rgba_compressed"] = encode(rgba, 4, 1, [[i, i, i, 0x80FF00FF] for i in range(4)],
                                  "binary_compressed")
xyz = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
seeds.update({
    "v5": b"# .PCD v.5\nVERSION .5\nCOLUMNS x y z\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n",
    "reordered": b"# c\n\nWIDTH 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nFIELDS x y z\nHEIGHT 2\n"
                 b"COUNT 1 1 1\nTYPE F F F\nSIZE 4 4 4\nVERSION 0.7\nDATA ascii\n1 2 3\n\n4 5 6\n",
    "crlf": b"FIELDS x y z\r\nPOINTS 1\r\nDATA ascii\r\n1\t2 3\r\n",
    "bad_size_count": b"VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4\nTYPE F F F F\nPOINTS 1\nDATA ascii\n",
    "bad_wh": (xyz + "WIDTH 3\nHEIGHT 2\nPOINTS 5\nDATA ascii\n").encode(),
    "bad_data": (xyz + "POINTS 1\nDATA binary_lz4\n1 2 3\n").encode(),
    "bad_ascii_word": (xyz + "POINTS 2\nDATA ascii\n1 2 3\n1 abc 3\n").encode(),
    "bad_ascii_range": b"FIELDS x y z l\nTYPE F F F U\nSIZE 4 4 4 1\nPOINTS 1\nDATA ascii\n1 2 3 256\n",
    "truncated_binary": seeds["rich_binary"][:-20],
    "truncated_compressed": seeds["rich_binary_compressed"][:-7],
    "corrupt_lzf_backref": (xyz + "POINTS 1\nDATA binary_compressed\n").encode()
    + struct.pack("<II", 5, 12) + b"\x01ab\x20\x05",
    "corrupt_lzf_long": (xyz + "POINTS 1\nDATA binary_compressed\n").encode()
    + struct.pack("<II", 8, 12) + b"\x03abcd\xe0\xff\x03",
    "block_ratio": (xyz + "WIDTH 100000\nHEIGHT 1\nPOINTS 100000\nDATA binary_compressed\n").encode()
    + struct.pack("<II", 4, 1200000) + b"\x00\x00\x00\x00",
})
# Raw LZF streams for the decoder part (the flag byte sizes its output).
run = lzf(b"a" * 300 + bytes(range(256)) * 3 + b"xyz" * 50)
seeds["raw_lzf_runs"] = run

os.makedirs(out_dir, exist_ok=True)
for name, data in seeds.items():
    flag = 0 if not name.startswith("raw") else 0xFE
    if "rich_binary" == name:
        flag = 1  # double precision
    with open(os.path.join(out_dir, name), "wb") as f:
        f.write(bytes([flag]) + data)
print("wrote %d seeds to %s" % (len(seeds), out_dir))
