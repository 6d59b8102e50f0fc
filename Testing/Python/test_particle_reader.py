"""vtkParticleTextReader (octoray.vtkParticleReader): formats, errors, lenient
mode, gzip, parallel parsing, round trip through vtkParticleTextWriter."""
import gzip
import os

import numpy as np
import pytest
import vtk
import octoray

from conftest import Messages, array, points


def write(tmp_path, name, text, mode="w"):
    path = os.path.join(str(tmp_path), name)
    with open(path, mode) as f:
        f.write(text)
    return path


def read(path, **options):
    r = octoray.vtkParticleReader()
    msgs = Messages(r)
    r.SetFileName(path)
    for key, value in options.items():
        getattr(r, "Set" + key)(value)
    r.Update()
    return r, r.GetOutput(), msgs


def test_python_names():
    # The name and the C++ class are the same class.
    assert octoray.vtkParticleReader is octoray.vtkParticleTextReader
    assert octoray.vtkParticleReader().GetClassName() == "vtkParticleTextReader"
    # VTK's own vtkParticleReader is a different class and stays usable.
    assert vtk.vtkParticleReader().GetClassName() == "vtkParticleReader"


def test_thesis_format(tmp_path):
    path = write(tmp_path, "p.txt",
                 "1 2 3 255 0 0 0.5 1.33\n4 5 6 0 255 0 0 0\n7 8 9 0 0 255 1 1.5\n")
    r, out, msgs = read(path)
    assert not msgs.errors
    assert r.GetColumnNames() == "x y z r g b reflectivity refraction"
    assert out.GetNumberOfPoints() == 3
    assert out.GetNumberOfVerts() == 3
    assert out.GetPoints().GetDataType() == vtk.VTK_FLOAT
    np.testing.assert_array_equal(points(out), [[1, 2, 3], [4, 5, 6], [7, 8, 9]])
    colors = out.GetPointData().GetArray("Colors")
    assert colors.GetDataType() == vtk.VTK_UNSIGNED_CHAR
    np.testing.assert_array_equal(array(out, "Colors"), [[255, 0, 0], [0, 255, 0], [0, 0, 255]])
    np.testing.assert_allclose(array(out, "Reflectivity"), [0.5, 0, 1])
    np.testing.assert_allclose(array(out, "Refraction"), np.float32([1.33, 0, 1.5]))
    assert out.GetPointData().GetArray("Scalars") is None


@pytest.mark.parametrize("text,cols,arrays", [
    ("1 2 3\n4 5 6\n", "x y z", []),
    ("1 2 3 0.25\n4 5 6 -7\n", "x y z scalar", ["Scalars"]),
    ("1 2 3 10 20 30\n4 5 6 40 50 60\n", "x y z r g b", ["Colors"]),
])
def test_column_counts(tmp_path, text, cols, arrays):
    r, out, msgs = read(write(tmp_path, "p.txt", text))
    assert not msgs.errors
    assert r.GetColumnNames() == cols
    assert out.GetNumberOfPoints() == 2
    names = sorted(out.GetPointData().GetArrayName(i)
                   for i in range(out.GetPointData().GetNumberOfArrays()))
    assert names == sorted(arrays)
    if "Scalars" in arrays:
        np.testing.assert_array_equal(array(out, "Scalars"), [0.25, -7])
    if "Colors" in arrays:
        np.testing.assert_array_equal(array(out, "Colors"), [[10, 20, 30], [40, 50, 60]])


def test_header_any_order_and_extras(tmp_path):
    text = ("# produced by a scanner\n"
            "# intensity b g r z y x time\n"
            "5 3 2 1 30 20 10 0.5\n"
            "6 6 5 4 60 50 40 1.5\n")
    r, out, msgs = read(write(tmp_path, "p.txt", text))
    assert not msgs.errors, msgs.errors
    np.testing.assert_array_equal(points(out), [[10, 20, 30], [40, 50, 60]])
    np.testing.assert_array_equal(array(out, "Colors"), [[1, 2, 3], [4, 5, 6]])
    np.testing.assert_array_equal(array(out, "intensity"), [5, 6])
    np.testing.assert_array_equal(array(out, "time"), [0.5, 1.5])


def test_csv_header_without_hash(tmp_path):
    r, out, msgs = read(write(tmp_path, "p.csv", "x,y,z,scalar\n1,2,3,4\n5,6,7,8\n"))
    assert not msgs.errors
    np.testing.assert_array_equal(points(out), [[1, 2, 3], [5, 6, 7]])
    np.testing.assert_array_equal(array(out, "Scalars"), [4, 8])


def test_separators_comments_blank_lines_crlf(tmp_path):
    text = ("# comment\r\n\r\n"
            "1\t2\t3\r\n"
            "  4,5 ,  6  \r\n"
            "# another comment\n"
            "\n"
            "+7 8.5e0 -9   # trailing comment\n"
            "1e-3,\t2E+2, .5")  # no final newline
    r, out, msgs = read(write(tmp_path, "p.txt", text, "w"))
    assert not msgs.errors, msgs.errors
    np.testing.assert_allclose(points(out), np.float32([[1, 2, 3], [4, 5, 6], [7, 8.5, -9],
                                                        [1e-3, 200, 0.5]]))


def test_gzip(tmp_path):
    text = "# x y z r g b\n" + "".join("%d %d %d 1 2 3\n" % (i, i + 1, i + 2) for i in range(1000))
    path = os.path.join(str(tmp_path), "p.txt.gz")
    with gzip.open(path, "wt") as f:
        f.write(text)
    r, out, msgs = read(path)
    assert not msgs.errors
    assert out.GetNumberOfPoints() == 1000
    assert points(out)[999].tolist() == [999, 1000, 1001]
    # Two gzip members concatenated are one text (gzip -c a b > c).
    path2 = os.path.join(str(tmp_path), "two.gz")
    with open(path2, "wb") as f:
        f.write(gzip.compress(b"1 2 3\n") + gzip.compress(b"4 5 6\n"))
    r, out, msgs = read(path2)
    assert out.GetNumberOfPoints() == 2


def test_truncated_gzip(tmp_path):
    blob = gzip.compress(("1 2 3\n" * 5000).encode())
    path = write(tmp_path, "cut.gz", blob[: len(blob) // 2], "wb")
    r, out, msgs = read(path)
    assert out.GetNumberOfPoints() == 0
    assert len(msgs.errors) == 1
    assert "cut.gz: truncated gzip data" in r.GetErrorMessage()
    assert "truncated gzip data" in msgs.errors[0]


def test_double_precision_and_no_vertices(tmp_path):
    path = write(tmp_path, "p.txt", "637012.24 849028.31 431.66\n")
    r, out, _ = read(path, OutputPointsPrecision=vtk.vtkAlgorithm.DOUBLE_PRECISION,
                     GenerateVertices=False)
    assert out.GetPoints().GetDataType() == vtk.VTK_DOUBLE
    assert points(out)[0].tolist() == [637012.24, 849028.31, 431.66]
    assert out.GetNumberOfVerts() == 0


@pytest.mark.parametrize("text,message", [
    ("1 2 3\n4 5\n", "p.txt:2:4: expected 3 columns (x y z), found 2"),
    ("1 2 3\n4 5 6 7\n", "p.txt:2:1: expected 3 columns (x y z), found 4"),
    ("1 2 3\n4 abc 6\n", "p.txt:2:3: expected a number for column 2 (y), found 'abc'"),
    ("1 2 3\n4 5 6x\n", "p.txt:2:5: expected a number for column 3 (z), found '6x'"),
    ("1 2 3\n4 nan 6\n", "p.txt:2:3: expected a finite number for column 2 (y), found 'nan'"),
    ("1 2 3\n4 5 -inf\n", "p.txt:2:5: expected a finite number for column 3 (z), found '-inf'"),
    ("1 2 3\n4,,6\n", "p.txt:2:3: expected a number for column 2 after the comma, found an empty field"),
    ("1 2 3 0 0 0\n1 2 3 0 256 0\n",
     "p.txt:2:9: expected a whole colour value 0-255 (scale 0-1 colours by 255) for column 5 (g), found '256'"),
    ("1 2 3 0 0 0 1.5 0\n", "p.txt:1:13: expected a reflectivity 0-1 for column 7 (reflectivity), found '1.5'"),
    # Open3D's .xyzrgb: colours 0-1, which read as whole numbers were black.
    ("1 2 3 0.2 0.7 0.5\n",
     "p.txt:1:7: expected a whole colour value 0-255 (scale 0-1 colours by 255) for column 4 (r), found '0.2'"),
    # Classic Mac OS line ends ran together into one line of six columns.
    ("1 2 3\r4 5 6\r", "p.txt:1:6: a carriage return inside a line: lines that end in CR alone (classic Mac OS) "
     "are not read; convert the file to LF or CRLF line ends"),
    ("# x y z\r1 2 3\r", "p.txt:1:8: a carriage return inside a line"),
    # A decimal comma was read as a field separator: 1 5 2 5 3 5.
    ("1,5 2,5 3,5\n", "p.txt:1:2: a comma between digits in a line whose fields are parted by blanks: a decimal "
     "comma? Write decimals with a point (1.5); a comma parts fields"),
    ("1.5, 2.5, 3.5\n1,2,3\n", None),  # commas part fields, with or without blanks
    # A number beyond single precision was "expected a number".
    ("1 2 3\n1e39 0 0\n", "p.txt:2:1: expected a number within single precision's range (OutputPointsPrecision "
     "double reads more) for column 1 (x), found '1e39'"),
    ("1 2\n", "p.txt:1:1: expected 3 (x y z), 4 (x y z scalar), 6 (x y z r g b) or 8"),
    ("# x y q\n1 2 3\n", None),  # not a header (no z): a comment, then 3 columns
    ("# x y z x\n1 2 3 4\n", "p.txt:1:1: bad header line: column 'x' is named twice"),
    ("# only a comment\n\n", "p.txt:2:1: no particle lines in the file (only comments or blank lines); "
     "expected lines of x y z ..."),
    ("# a comment\n\nX Y Z r g b\n# another\n",
     "p.txt:4:1: no particle lines in the file (only a header, comments or blank lines); expected lines of "
     "X Y Z r g b"),
    ("# a comment\n# x y z\n# x y z scalar\n1 2 3 4\n",  # the first header line names the columns
     "p.txt:4:1: expected 3 columns (x y z), found 4"),
])
def test_errors_strict(tmp_path, text, message):
    path = write(tmp_path, "p.txt", text)
    r, out, msgs = read(path)
    if message is None:
        assert not msgs.errors
        return
    assert out.GetNumberOfPoints() == 0
    assert len(msgs.errors) == 1
    assert message in r.GetErrorMessage(), r.GetErrorMessage()
    assert message in msgs.errors[0]
    assert path in r.GetErrorMessage()


def test_utf8_byte_order_mark(tmp_path):
    """A spreadsheet's "CSV UTF-8" starts with a byte order mark: read past
    it, header and all."""
    path = write(tmp_path, "excel.csv", b"\xef\xbb\xbfx,y,z\r\n1,2,3\r\n4,5,6\r\n", "wb")
    r, out, msgs = read(path)
    assert not msgs.errors, msgs.errors
    assert points(out).tolist() == [[1, 2, 3], [4, 5, 6]]


def test_binary_file_is_named(tmp_path):
    """A binary file (here a PNG's first bytes) is named for what it is, at
    its first byte that no particle line holds."""
    path = write(tmp_path, "picture.txt", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "wb")
    r, out, msgs = read(path)
    assert out.GetNumberOfPoints() == 0
    assert r.GetErrorMessage() == (path + ":1:1: a byte 0x89, which no particle line holds: a binary file (an image, "
                                   "a LAS file?), not particle text"), r.GetErrorMessage()


def test_missing_file(tmp_path):
    path = os.path.join(str(tmp_path), "nope.txt")
    r, out, msgs = read(path)
    assert out.GetNumberOfPoints() == 0
    assert r.GetErrorMessage() == path + ": cannot open the file: No such file or directory"


def test_zero_byte_file(tmp_path):
    path = write(tmp_path, "empty.txt", "")
    r, out, msgs = read(path)
    assert out.GetNumberOfPoints() == 0
    assert r.GetErrorMessage().startswith(path + ": the file is empty (0 bytes)")
    assert len(msgs.errors) == 1


def test_one_line_file(tmp_path):
    for text in ("1 2 3 4 5 6 0.5 1.5\n", "1 2 3 4 5 6 0.5 1.5"):
        r, out, msgs = read(write(tmp_path, "one.txt", text))
        assert not msgs.errors
        assert out.GetNumberOfPoints() == 1
        assert points(out)[0].tolist() == [1, 2, 3]


def test_lenient_counts(tmp_path):
    lines = []
    bad = []
    for i in range(1, 101):
        if i % 7 == 0:
            lines.append("%d oops %d" % (i, i))
            bad.append(i + 1)  # +1: the header is line 1
        elif i % 11 == 0:
            lines.append("%d %d" % (i, i))
            bad.append(i + 1)
        else:
            lines.append("%d %d %d" % (i, i, i))
    path = write(tmp_path, "p.txt", "# x y z\n" + "\n".join(lines) + "\n")
    # Strict: the first bad line fails the read.
    r, out, msgs = read(path)
    assert out.GetNumberOfPoints() == 0
    assert "p.txt:%d:" % bad[0] in r.GetErrorMessage()
    # Lenient: bad lines skipped, counted, reported.
    r, out, msgs = read(path, Lenient=True, MaximumReportedLines=5)
    assert not msgs.errors
    assert r.GetNumberOfSkippedLines() == len(bad) == 14 + 9 - 1  # 77 is both
    assert out.GetNumberOfPoints() == 100 - len(bad)
    good = [i for i in range(1, 101) if i % 7 and i % 11]
    np.testing.assert_array_equal(points(out)[:, 0], good)
    fd = out.GetFieldData()
    assert fd.GetArray("SkippedLineCount").GetValue(0) == len(bad)
    numbers = fd.GetArray("SkippedLineNumbers")
    assert [numbers.GetValue(i) for i in range(numbers.GetNumberOfTuples())] == bad[:5]
    assert len(msgs.warnings) == 1
    assert "skipped %d bad line(s) of 100" % len(bad) in msgs.warnings[0]
    assert "first at line(s) %s, ..." % ", ".join(map(str, bad[:5])) in msgs.warnings[0]


def test_lenient_everything_bad(tmp_path):
    r, out, msgs = read(write(tmp_path, "p.txt", "1 2 3\n1 2 x\n"), Lenient=True)
    assert out.GetNumberOfPoints() == 1
    r, out, msgs = read(write(tmp_path, "q.txt", "# x y z\na b c\n"), Lenient=True)
    assert out.GetNumberOfPoints() == 0
    assert "every particle line was bad" in r.GetErrorMessage()


def big_file(tmp_path, n=400000, seed=3):
    rng = np.random.default_rng(seed)
    xyz = rng.uniform(-1e3, 1e3, size=(n, 3)).round(4)
    rgb = rng.integers(0, 256, size=(n, 3))
    refl = rng.uniform(0, 1, size=n).round(3)
    refr = rng.choice([0.0, 1.33, 1.5], size=n)
    path = os.path.join(str(tmp_path), "big.txt")
    with open(path, "w") as f:
        for p, c, a, b in zip(xyz, rgb, refl, refr):
            f.write("%r %r %r %d %d %d %r %r\n" % (p[0], p[1], p[2], c[0], c[1], c[2], a, b))
    return path, xyz, rgb, refl, refr


def test_parallel_matches_numpy_and_serial(tmp_path):
    path, xyz, rgb, refl, refr = big_file(tmp_path)
    assert os.path.getsize(path) > 8 << 20  # several chunks
    results = []
    for threads in (1, 4):
        progress = []
        r = octoray.vtkParticleReader()
        r.SetFileName(path)
        r.SetNumberOfThreads(threads)
        r.SetOutputPointsPrecision(vtk.vtkAlgorithm.DOUBLE_PRECISION)
        r.AddObserver("ProgressEvent", lambda o, e: progress.append(o.GetProgress()))
        r.Update()
        out = r.GetOutput()
        # Both parse with correctly rounded conversions: exact equality.
        np.testing.assert_array_equal(points(out), xyz)
        np.testing.assert_array_equal(array(out, "Colors"), rgb)
        np.testing.assert_array_equal(array(out, "Reflectivity"), refl)
        np.testing.assert_array_equal(array(out, "Refraction"), refr)
        assert len(progress) >= 3 and progress[-1] == 1.0
        assert progress == sorted(progress)
        results.append(points(out).copy())
    np.testing.assert_array_equal(results[0], results[1])


def test_parallel_strict_reports_first_bad_line(tmp_path):
    n = 300000
    lines = ["%d.5 1 2" % i for i in range(n)]
    lines[250000] = "1 2 late"
    lines[120000] = "1 2 early"
    path = write(tmp_path, "p.txt", "\n".join(lines) + "\n")
    r, out, msgs = read(path, NumberOfThreads=4)
    assert out.GetNumberOfPoints() == 0
    assert "p.txt:120001:5: expected a number for column 3 (z), found 'early'" in r.GetErrorMessage()
    r, out, msgs = read(path, NumberOfThreads=4, Lenient=True)
    assert r.GetNumberOfSkippedLines() == 2
    assert out.GetNumberOfPoints() == n - 2
    fd = out.GetFieldData().GetArray("SkippedLineNumbers")
    assert [fd.GetValue(0), fd.GetValue(1)] == [120001, 250001]


def test_round_trip(tmp_path, data_dir):
    """particle file -> polydata -> written -> read: the same data."""
    src = os.path.join(data_dir, "Particles", "lidar_simple.particles")
    r1, out1, msgs = read(src, OutputPointsPrecision=vtk.vtkAlgorithm.DOUBLE_PRECISION)
    assert not msgs.errors
    assert out1.GetNumberOfPoints() == 1065
    dst = os.path.join(str(tmp_path), "copy.particles")
    w = octoray.vtkParticleTextWriter()
    w.SetInputData(out1)
    w.SetFileName(dst)
    assert w.Write() == 1
    r2, out2, msgs = read(dst, OutputPointsPrecision=vtk.vtkAlgorithm.DOUBLE_PRECISION)
    assert not msgs.errors
    assert r2.GetColumnNames() == "x y z r g b reflectivity refraction"
    for name in ("Colors", "Reflectivity", "Refraction"):
        np.testing.assert_array_equal(array(out2, name), array(out1, name))
    np.testing.assert_array_equal(points(out2), points(out1))
    # And against the text itself, read independently.
    ref = np.loadtxt(src)
    np.testing.assert_array_equal(points(out2), ref[:, :3])
    np.testing.assert_array_equal(array(out2, "Colors"), ref[:, 3:6])


def test_writer_says_when_it_cannot_write(tmp_path):
    """A file the writer cannot open (its folder does not exist): Write()
    returns 0, the error code says why and the message names the file, as
    VTK's own writers do; the next good write clears it."""
    r, out, _ = read(write(tmp_path, "p.txt", "1 2 3\n4 5 6\n"))
    w = octoray.vtkParticleTextWriter()
    msgs = Messages(w)
    w.SetInputData(out)
    missing = os.path.join(str(tmp_path), "no-such-folder", "copy.txt")
    w.SetFileName(missing)
    assert w.Write() == 0
    assert w.GetErrorCode() == vtk.vtkErrorCode.CannotOpenFileError
    assert len(msgs.errors) == 1 and missing + ": cannot open for writing" in msgs.errors[0]
    w.SetFileName(os.path.join(str(tmp_path), "copy.txt"))
    assert w.Write() == 1 and w.GetErrorCode() == vtk.vtkErrorCode.NoError


def test_round_trip_float_and_extras(tmp_path):
    rng = np.random.default_rng(5)
    vals = rng.normal(size=(50, 5)).astype(np.float32)
    path = os.path.join(str(tmp_path), "a.txt")
    np.savetxt(path, vals, header="x y z scalar weight", fmt="%.9g")
    r1, out1, _ = read(path)
    dst = os.path.join(str(tmp_path), "b.txt")
    w = octoray.vtkParticleTextWriter()
    w.SetInputData(out1)
    w.SetFileName(dst)
    w.Write()
    r2, out2, _ = read(dst)
    np.testing.assert_array_equal(points(out2), vals[:, :3])
    np.testing.assert_array_equal(array(out2, "Scalars"), vals[:, 3])
    np.testing.assert_array_equal(array(out2, "weight"), vals[:, 4])


def test_real_lidar_scan(data_dir):
    r, out, msgs = read(os.path.join(data_dir, "PointClouds", "simple_las.xyzrgbi"),
                        OutputPointsPrecision=vtk.vtkAlgorithm.DOUBLE_PRECISION)
    assert not msgs.errors
    assert out.GetNumberOfPoints() == 1065
    assert r.GetColumnNames() == "x y z r g b intensity"
    ref = np.loadtxt(os.path.join(data_dir, "PointClouds", "simple_las.xyzrgbi"))
    np.testing.assert_array_equal(array(out, "intensity"), ref[:, 6])
