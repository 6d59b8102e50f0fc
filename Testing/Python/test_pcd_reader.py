"""vtkPCDReader on real PCD files against an independent decoding (label python).

The real files are the example clouds of Debian's python3-pcl package, which
`make data` unpacks into Data/External/PCL (the package itself is never
installed). Each is decoded here a second way, without the reader: the header
by a few lines of Python, binary_compressed bodies by this file's own LZF
decoder in pure Python, ascii bodies by numpy.loadtxt; then the reader's
points, counts, bounds, colours and every other array are compared with it.
"""
import os
import struct
import time

import numpy as np
import pytest

import vtk
import octoray
from conftest import DATA, Messages, array, points

PCL = os.path.join(DATA, "External", "PCL")
SCAN = os.path.join(PCL, "table_scene_lms400.pcd")


def need(path):
    """The file, or a failure that says how to get it (never a silent skip)."""
    if not os.path.exists(path):
        pytest.fail("%s is missing: `make data` fetches it (the example clouds of Debian's "
                    "python3-pcl, unpacked without installing the package)" % path)
    return path


# ---- The independent decoding.

def lzf_decompress(src, expected):
    """LZF as the PCD format uses it: control byte c < 32 copies c + 1
    literal bytes; otherwise length c >> 5 (7: plus the next byte) + 2 bytes
    from ((c & 31) << 8) + next byte + 1 bytes back, byte by byte."""
    out = bytearray()
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        i += 1
        if c < 32:
            out += src[i:i + c + 1]
            i += c + 1
        else:
            length = c >> 5
            if length == 7:
                length += src[i]
                i += 1
            back = ((c & 31) << 8) + src[i] + 1
            i += 1
            length += 2
            start = len(out) - back
            assert start >= 0, "back-reference before the start"
            if back >= length:
                out += out[start:start + length]
            else:
                for k in range(length):
                    out.append(out[start + k])
    assert len(out) == expected, (len(out), expected)
    return bytes(out)


DTYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("U", 1): "u1", ("U", 2): "<u2", ("U", 4): "<u4",
          ("U", 8): "<u8", ("I", 1): "i1", ("I", 2): "<i2", ("I", 4): "<i4", ("I", 8): "<i8"}


def decode(path):
    """(header dict, {field: array of shape (points, count)}) for a PCD file."""
    raw = open(path, "rb").read()
    header, pos = {}, 0
    while True:
        end = raw.index(b"\n", pos)
        words = raw[pos:end].decode("ascii").split()
        pos = end + 1
        if not words or words[0].startswith("#"):
            continue
        header[words[0]] = words[1:]
        if words[0] == "DATA":
            break
    names = header["FIELDS"]
    sizes = [int(s) for s in header.get("SIZE", ["4"] * len(names))]
    types = header.get("TYPE", ["F"] * len(names))
    counts = [int(c) for c in header.get("COUNT", ["1"] * len(names))]
    n = int(header["POINTS"][0])
    dtypes = [np.dtype(DTYPES[(t, s)]) for t, s in zip(types, sizes)]
    fields = {}
    form = header["DATA"][0]
    if form == "ascii":
        table = np.loadtxt(raw[pos:].decode("ascii").splitlines(), dtype=np.float64, ndmin=2)
        assert table.shape == (n, sum(counts))
        col = 0
        for name, dt, c in zip(names, dtypes, counts):
            fields[name] = table[:, col:col + c].astype(dt)
            col += c
    elif form == "binary":
        record = np.dtype([(name if name != "_" else "_%d" % k, dt, (c,))
                           for k, (name, dt, c) in enumerate(zip(names, dtypes, counts))])
        table = np.frombuffer(raw, record, count=n, offset=pos)
        fields = {name: table[name].reshape(n, -1) for name in names if name != "_"}
    else:
        compressed, uncompressed = struct.unpack_from("<II", raw, pos)
        block = lzf_decompress(raw[pos + 8:pos + 8 + compressed], uncompressed)
        at = 0
        for name, dt, c in zip(names, dtypes, counts):
            if name == "_":
                continue
            fields[name] = np.frombuffer(block, dt, count=n * c, offset=at).reshape(n, c)
            at += n * c * dt.itemsize
        assert at == uncompressed
    return header, fields


def colours(fields):
    """RGB or RGBA from the packed rgb / rgba bits, as PCL packs them."""
    name = "rgba" if "rgba" in fields else "rgb"
    bits = np.ascontiguousarray(fields[name][:, 0]).view(np.uint32)
    rgb = np.stack([(bits >> 16) & 255, (bits >> 8) & 255, bits & 255] +
                   ([bits >> 24] if name == "rgba" else []), axis=1)
    return rgb.astype(np.uint8)


def read(path, precision=vtk.vtkAlgorithm.SINGLE_PRECISION):
    r = octoray.vtkPCDReader()
    messages = Messages(r)
    r.SetFileName(path)
    r.SetOutputPointsPrecision(precision)
    r.Update()
    assert r.GetErrorMessage() == "", r.GetErrorMessage()
    assert not messages.errors
    return r, r.GetOutput(), messages


def compare(path):
    """The reader against the independent decoding, array by array."""
    header, fields = decode(path)
    r, out, messages = read(path)
    n = int(header["POINTS"][0])
    xyz = np.hstack([fields["x"], fields["y"], fields["z"]]).astype(np.float32)
    keep = np.isfinite(xyz).all(axis=1)
    skipped = int((~keep).sum())
    assert out.GetNumberOfPoints() == n - skipped
    assert r.GetNumberOfSkippedPoints() == skipped
    assert out.GetFieldData().GetArray("SkippedPointCount").GetValue(0) == skipped
    # One warning for the skipped points, naming the file and the count.
    skip_warnings = [w for w in messages.warnings if "skipped" in w]
    assert len(skip_warnings) == (1 if skipped else 0)
    if skipped:
        assert path in skip_warnings[0] and "skipped %d of %d points" % (skipped, n) in skip_warnings[0]
    assert np.array_equal(points(out), xyz[keep])
    bounds = out.GetBounds()
    for axis in range(3):
        assert bounds[2 * axis] == xyz[keep, axis].min()
        assert bounds[2 * axis + 1] == xyz[keep, axis].max()
    done = {"x", "y", "z", "_"}
    if "rgb" in fields or "rgba" in fields:
        got = array(out, "Colors")
        assert np.array_equal(got, colours(fields)[keep])
        assert out.GetPointData().GetScalars().GetName() == "Colors"
        done |= {"rgb", "rgba"}
    if "normal_x" in fields:
        normals = np.hstack([fields["normal_" + a] for a in "xyz"]).astype(np.float32)[keep]
        assert np.array_equal(array(out, "Normals"), normals, equal_nan=True)
        done |= {"normal_x", "normal_y", "normal_z"}
    for name, values in fields.items():
        if name in done:
            continue
        # In the type the file stores: nothing rounded to float.
        got = array(out, "Intensity" if name == "intensity" else name)
        want = values[keep]
        assert got.dtype == want.dtype, (name, got.dtype, want.dtype)
        assert np.array_equal(got.reshape(want.shape), want, equal_nan=True), name
    return header, fields, out, keep


def test_table_scene_lms400():
    """The real scan: 460,400 points, binary_compressed; counts, bounds and
    the intensity range against the independent decoding."""
    header, fields, out, keep = compare(need(SCAN))
    assert header["DATA"] == ["binary_compressed"]
    assert int(header["POINTS"][0]) == 460400 and keep.all()
    assert out.GetNumberOfPoints() == 460400 and out.GetNumberOfVerts() == 460400
    intensity = array(out, "Intensity")
    assert (intensity.min(), intensity.max()) == (fields["intensity"].min(), fields["intensity"].max())
    assert out.GetPointData().GetScalars().GetName() == "Intensity"
    # A real range, not zeros: a table top about 1.2 m from the scanner.
    lo, hi = intensity.min(), intensity.max()
    assert 0 <= lo < hi
    b = out.GetBounds()
    assert all(b[2 * a + 1] - b[2 * a] > 0.5 for a in range(3))


def test_table_scene_lms400_double_precision():
    path = need(SCAN)
    _, fields = decode(path)
    _, out, _ = read(path, vtk.vtkAlgorithm.DOUBLE_PRECISION)
    assert out.GetPoints().GetDataType() == vtk.VTK_DOUBLE
    xyz = np.hstack([fields["x"], fields["y"], fields["z"]]).astype(np.float64)
    assert np.array_equal(points(out), xyz)


def test_table_scene_lms400_time():
    """Reading the scan: best of five, printed (make bench keeps the numbers)."""
    path = need(SCAN)
    best = float("inf")
    for _ in range(5):
        r = octoray.vtkPCDReader()
        r.SetFileName(path)
        start = time.perf_counter()
        r.Update()
        best = min(best, time.perf_counter() - start)
        assert r.GetOutput().GetNumberOfPoints() == 460400
    print("table_scene_lms400.pcd: %.1f ms, %.0f MB/s of the %d-byte file"
          % (best * 1e3, os.path.getsize(path) / best / 1e6, os.path.getsize(path)))


# The other example clouds of the package: organised 640 x 480 clouds with
# NaN cells and packed colours, ascii files, a compressed scan without
# colours. `make data` fetches the table scan for certain; these only where
# it unpacked them too (a skip that names the file, never a silent one).
OTHERS = ["table_scene_mug_stereo_textured.pcd", "milk_cartoon_all_small_clorox.pcd", "milk.pcd",
          "bun0.pcd", "test_pcd.pcd", "lamppost.pcd"]


@pytest.mark.parametrize("name", OTHERS)
def test_package_clouds(name):
    path = os.path.join(PCL, name)
    if not os.path.exists(path):
        pytest.skip("%s not unpacked (make data fetches python3-pcl's example clouds)" % path)
    header, fields, out, keep = compare(path)
    if header["HEIGHT"] != ["1"]:
        # Organised: the NaN cells of the depth camera left out and counted.
        assert not keep.all()
        fd = out.GetFieldData()
        assert fd.GetArray("PCDWidth").GetValue(0) == int(header["WIDTH"][0])
        assert fd.GetArray("PCDHeight").GetValue(0) == int(header["HEIGHT"][0])


@pytest.mark.parametrize("form", ["ascii", "binary"])
def test_fields_keep_their_type(tmp_path, form):
    """A double timestamp and a uint32 label as the file stores them (read
    into float arrays, 1700000000.1 became 1700000000 and 16777217 became
    16777216)."""
    stamps = np.array([1700000000.0, 1700000000.1, 1700000000.2])
    labels = np.array([16777217, 4000000001, 7], np.uint32)
    head = ("VERSION 0.7\nFIELDS x y z timestamp label\nSIZE 4 4 4 8 4\nTYPE F F F F U\nCOUNT 1 1 1 1 1\n"
            "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA %s\n" % form)
    path = os.path.join(str(tmp_path), "typed.pcd")
    with open(path, "wb") as f:
        f.write(head.encode())
        for k in range(3):
            if form == "ascii":
                f.write(("%d 0 0 %.10f %d\n" % (k, stamps[k], labels[k])).encode())
            else:
                f.write(struct.pack("<fffdI", k, 0, 0, stamps[k], labels[k]))
    compare(path)
    r, out, messages = read(path)
    assert array(out, "timestamp").dtype == np.float64 and array(out, "label").dtype == np.uint32
    assert array(out, "timestamp").tolist() == stamps.tolist()
    assert array(out, "label").tolist() == labels.tolist()


def test_errors_from_python(tmp_path):
    """A damaged file through the wrapping: the message names file and line,
    the previous output stays."""
    good = tmp_path / "good.pcd"
    good.write_text("FIELDS x y z\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n")
    r = octoray.vtkPCDReader()
    messages = Messages(r)
    r.SetFileName(str(good))
    r.Update()
    assert r.GetOutput().GetNumberOfPoints() == 2 and r.GetFieldNames() == "x y z"
    good.write_text("FIELDS x y z\nSIZE 4 4\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n")
    r.Update()
    assert r.GetErrorMessage() == "%s:2: SIZE lists 2 value(s), FIELDS (line 1) lists 3 field(s)" % good
    assert messages.errors and str(good) in messages.errors[-1]
    assert r.GetOutput().GetNumberOfPoints() == 2


def test_independent_lzf_decoder_is_itself_right():
    """The reference decoder on a hand-made stream with an overlapping copy."""
    stream = bytes([0x02]) + b"abc" + bytes([0xE0, 0x03, 0x02])  # 'abc' + 12 bytes from 3 back
    assert lzf_decompress(stream, 15) == b"abc" * 5


def test_gzip_compressed_file(tmp_path):
    """A gzip-compressed PCD (x.pcd.gz) is read as the file it holds, like a
    gzip-compressed particle file (the module's file source inflates it)."""
    import gzip
    text = ("VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\n"
            "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA binary\n").encode()
    body = struct.pack("<fffIfffI", 1, 2, 3, 0x00FF8000, 4, 5, 6, 0x000000FF)
    path = tmp_path / "cloud.pcd.gz"
    path.write_bytes(gzip.compress(text + body))
    _, out, _ = read(str(path))
    assert points(out).tolist() == [[1, 2, 3], [4, 5, 6]]
    assert array(out, "Colors").tolist() == [[255, 128, 0], [0, 0, 255]]
