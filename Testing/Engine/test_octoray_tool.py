"""The engine's command-line tool, `octoray`, as a user runs it.

- bad arguments: exit status 2, a message naming the option, what it
  expects and what it got (or the missing value, or the missing -o), and
  no picture written;
- a depth the engine refuses, a file that does not exist, a folder, an
  empty file, a PCD file and a gzip-compressed one: exit status 1 and the
  engine's or the loader's message;
- `stats`: the points counted as the file holds them, one root node, and
  the nodes per level adding up to the node count; a header line naming
  the columns, and a bad value named as vtkParticleTextReader names it;
- `render` to a PPM file: the picture has the requested size, every pixel a
  primary ray, and the points drawn (pixels off the background); points
  all at one place show their voxel whole, inside the frame;
- `--help`: the usage on stdout, exit status 0;
- OnCuda (run alone as engine.tool.cuda, skipped where CUDA is not
  available): `stats` gives the CPU's octree level for level, and `render`
  the CPU's pictures within the engine's tolerance between backends.
Plain python3 (no VTK, no pytest): the tool builds without VTK.

usage: test_octoray_tool.py OCTORAY DATA_DIR WORK_DIR [unittest arguments]
"""
import gzip
import os
import re
import subprocess
import sys
import unittest

TOOL, DATA, WORK = sys.argv[1:4]
LIDAR = os.path.join(DATA, "Particles", "lidar_simple.particles")
# Where a bad-argument case would write, were its argument taken.
STRAY = os.path.join(WORK, "stray.ppm")
# The tool composites over this background (octoray.cpp's Composite).
BACKGROUND = (round(255 * 0.08), round(255 * 0.08), round(255 * 0.1))


def run(*args):
    done = subprocess.run([TOOL, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=120)
    return done.returncode, done.stdout, done.stderr


def read_ppm(path):
    """(width, height, [(r, g, b)]) of a binary PPM with maxval 255."""
    with open(path, "rb") as f:
        data = f.read()
    fields = re.match(rb"P6\s+(\d+)\s+(\d+)\s+255\s", data)
    width, height = int(fields.group(1)), int(fields.group(2))
    body = data[fields.end():]
    return width, height, [tuple(body[i:i + 3]) for i in range(0, len(body), 3)]


class BadArguments(unittest.TestCase):
    CASES = [
        (["render", LIDAR, "-o", STRAY, "--depth", "x"], "--depth expects a whole number, not 'x'"),
        (["render", LIDAR, "-o", STRAY, "--mode", "fancy"],
         "--mode expects one of surface, depthcue, phong, composite, mip, minip, average, additive, not 'fancy'"),
        (["render", LIDAR, "-o", STRAY, "--size", "0x10"],
         "--size expects a size WxH such as 1920x1080, at most 16384 a side, not '0x10'"),
        (["render", LIDAR, "-o", STRAY, "--size", "100000x10"],
         "--size expects a size WxH such as 1920x1080, at most 16384 a side, not '100000x10'"),
        (["render", LIDAR, "-o", STRAY, "--zoom", "0"], "--zoom expects a number above 0, not '0'"),
        (["render", LIDAR, "-o", STRAY, "--lod", "2px"], "--lod expects a number, not '2px'"),
        (["render", LIDAR, "-o", STRAY, "--bounces", "-1"], "--bounces expects a whole number of at least 0, not '-1'"),
        (["render", LIDAR, "-o", STRAY, "--bogus", "1"], "unknown option '--bogus'"),
        (["render", LIDAR, "-o"], "-o expects a value, and no value follows it"),
        (["render", LIDAR, "--mode", "phong"], "render needs -o OUT.png, the picture to write"),
        (["stats", LIDAR, "--backend", "gpu"], "--backend expects one of auto, cpu, cuda, not 'gpu'"),
        (["stats", LIDAR, "--threads", "2.5"], "--threads expects a whole number of at least 0, not '2.5'"),
    ]

    def test_each_is_named(self):
        if os.path.exists(STRAY):
            os.remove(STRAY)
        for args, message in self.CASES:
            with self.subTest(args=args):
                status, _, err = run(*args)
                self.assertEqual(status, 2)
                self.assertIn("octoray: " + message + "\n", err)
                self.assertIn("usage: octoray", err)
                self.assertFalse(os.path.exists(STRAY), "a picture was written")

    def test_unknown_command(self):
        status, _, err = run("draw", LIDAR)
        self.assertEqual(status, 2)
        self.assertIn("octoray: unknown command 'draw'\n", err)
        self.assertIn("usage: octoray", err)

    def test_missing_file_argument(self):
        status, _, err = run("render")
        self.assertEqual(status, 2)
        self.assertIn("octoray: render needs a FILE, the particle file to read\n", err)


class Help(unittest.TestCase):
    def test_usage_on_stdout(self):
        for args in (["--help"], ["-h"], ["help"], ["render", LIDAR, "--help"]):
            with self.subTest(args=args):
                status, out, err = run(*args)
                self.assertEqual((status, err), (0, ""))
                self.assertTrue(out.startswith("usage: octoray stats FILE"), out)
                self.assertIn("MODE: surface", out)


class Failures(unittest.TestCase):
    def test_depth_the_engine_refuses(self):
        status, _, err = run("stats", LIDAR, "--backend", "cpu", "--depth", "30")
        self.assertEqual(status, 1)
        self.assertIn("depth must be 0 (automatic) or 1..21, got 30", err)

    def test_missing_file(self):
        missing = os.path.join(WORK, "no-such.particles")
        status, _, err = run("stats", missing, "--backend", "cpu")
        self.assertEqual(status, 1)
        self.assertIn(missing + ": cannot open the file", err)

    def test_folder_and_empty_file(self):
        """A folder is named as one; an empty file gets the reader's message,
        not a line 0."""
        status, _, err = run("stats", WORK, "--backend", "cpu")
        self.assertEqual(status, 1)
        self.assertIn(WORK + ": a folder, not a particle file", err)
        empty = os.path.join(WORK, "empty.txt")
        open(empty, "w").close()
        status, _, err = run("stats", empty, "--backend", "cpu")
        self.assertEqual(status, 1)
        self.assertIn(empty + ": the file is empty (0 bytes); expected one particle a line", err)

    def test_bad_line_as_the_reader_says(self):
        """A bad value is named by line, column and layout in
        vtkParticleTextReader's words (the same format core reads both);
        blank and comment lines count in the line number."""
        bad = os.path.join(WORK, "bad-colour.txt")
        with open(bad, "w") as f:
            f.write("0 0 0 10 20 30\n\n# between\n1 1 1 10 272 30\n")
        status, _, err = run("stats", bad, "--backend", "cpu")
        self.assertEqual(status, 1)
        self.assertIn(bad + ":4:10: expected a whole colour value 0-255 (scale 0-1 colours by 255) for column 5 (g), found '272'", err)

    def test_formats_it_does_not_read(self):
        """A PCD file and a gzip-compressed particle file are named for what
        they are, not as a column that is not a number."""
        pcd = os.path.join(WORK, "cloud.pcd")
        with open(pcd, "w") as f:
            f.write("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\n"
                    "SIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
                    "POINTS 3\nDATA ascii\n0 0 0 1\n1 0 0 2\n0 1 0 3\n")
        packed = os.path.join(WORK, "lidar.particles.gz")
        with open(LIDAR, "rb") as source, gzip.open(packed, "wb") as f:
            f.write(source.read())
        for path, message in ((pcd, pcd + ": a PCD file; the octoray tool reads particle text files (vtkPCDReader reads PCD"),
                              (packed, packed + ": gzip-compressed; the octoray tool reads plain text")):
            with self.subTest(path=path):
                status, _, err = run("stats", path, "--backend", "cpu")
                self.assertEqual(status, 1)
                self.assertIn(message, err)


class Commands(unittest.TestCase):
    def test_stats(self):
        status, out, err = run("stats", LIDAR, "--backend", "cpu", "--depth", "6")
        self.assertEqual(status, 0, err)
        with open(LIDAR) as f:
            points = sum(1 for line in f if line.strip() and not line.startswith("#"))
        self.assertIn("(%d points," % points, out)
        per_level = [int(v) for v in re.search(r"^nodes per level ([\d ]+)$", out, re.M).group(1).split()]
        self.assertEqual(len(per_level), 7)
        self.assertEqual(per_level[0], 1)
        self.assertEqual(sum(per_level), int(re.search(r"^nodes +(\d+)$", out, re.M).group(1)))

    def test_header_names_the_columns(self):
        """A header line names the columns, other columns read and left
        out, as vtkParticleTextReader reads the file."""
        named = os.path.join(WORK, "named.csv")
        with open(named, "w") as f:
            f.write("intensity,z,y,x,return\n0.5,3,2,1,1\n0.7,6,5,4,2\n0.9,9,8,7,1\n")
        status, out, err = run("stats", named, "--backend", "cpu")
        self.assertEqual(status, 0, err)
        self.assertIn("(3 points,", out)

    def test_render(self):
        picture = os.path.join(WORK, "lidar.ppm")
        if os.path.exists(picture):
            os.remove(picture)
        status, out, err = run("render", LIDAR, "-o", picture, "--backend", "cpu", "--size", "160x90",
                               "--mode", "phong", "--shadows")
        self.assertEqual(status, 0, err)
        self.assertIn("wrote           " + picture, out)
        self.assertIn("160x90, mode phong + shadows, %d primary" % (160 * 90), out)
        width, height, pixels = read_ppm(picture)
        self.assertEqual((width, height, len(pixels)), (160, 90, 160 * 90))
        drawn = sum(1 for p in pixels if p != BACKGROUND)
        self.assertGreater(drawn, 0.05 * len(pixels))  # the tile fills about a third of the frame
        self.assertLess(drawn, len(pixels))

    def test_points_at_one_place_show_their_voxel_whole(self):
        """Points all at one place make a leaf with a corner at them: the
        camera frames that voxel, seen whole from outside, not from inside
        it or cut off by the frame."""
        same = os.path.join(WORK, "same.txt")
        with open(same, "w") as f:
            f.write("1 2 3\n1 2 3\n1 2 3\n")
        picture = os.path.join(WORK, "same.ppm")
        status, _, err = run("render", same, "-o", picture, "--backend", "cpu", "--size", "80x60")
        self.assertEqual(status, 0, err)
        width, height, pixels = read_ppm(picture)
        drawn = [i for i, p in enumerate(pixels) if p != BACKGROUND]
        border = [i for i in drawn if i % width in (0, width - 1) or i // width in (0, height - 1)]
        self.assertGreater(len(drawn), 0.1 * len(pixels))
        self.assertLess(len(drawn), 0.6 * len(pixels))
        self.assertEqual(border, [])


def stats_lines(out):
    """The lines of `stats` that describe the octree (not the backend, the
    times or the memory, which differ between backends)."""
    return [line for line in out.splitlines() if line.startswith(("file ", "depth ", "nodes "))]


def without_times(out):
    """The output with its times taken out: they differ from run to run."""
    return re.sub(r" \(\d+\.\d+ s\)| read in \d+\.\d+ s", "", out)


class OnCuda(unittest.TestCase):
    # CUDA pictures against the CPU's: at least 99.9 % of the pixels equal,
    # none off by more than 2 in any 8-bit channel (the engine tests' bound).
    SAME_FRACTION = 0.999
    MOST_OFF = 2
    RENDERS = [
        ["--mode", "phong", "--shadows", "--bounces", "1"],
        ["--mode", "depthcue", "--depth", "5", "--lod", "2"],
        ["--mode", "composite", "--azimuth", "120", "--elevation", "60"],
        ["--mode", "mip", "--zoom", "2"],
    ]

    @classmethod
    def setUpClass(cls):
        status, _, err = run("stats", LIDAR, "--backend", "cuda")
        if status != 0 and "the CUDA backend is not available" in err:
            raise unittest.SkipTest(err.strip())

    def test_stats_same_octree(self):
        for depth in ("0", "6", "12"):
            with self.subTest(depth=depth):
                outs = []
                for backend in ("cpu", "cuda"):
                    status, out, err = run("stats", LIDAR, "--backend", backend, "--depth", depth)
                    self.assertEqual(status, 0, err)
                    outs.append(without_times(out))
                self.assertIn("CUDA", re.search(r"^backend .*$", outs[1], re.M).group(0))
                self.assertEqual(len(stats_lines(outs[0])), 4, outs[0])
                self.assertEqual(stats_lines(outs[1]), stats_lines(outs[0]))

    def test_render_same_pictures(self):
        for options in self.RENDERS:
            with self.subTest(options=options):
                pictures = []
                for backend in ("cpu", "cuda"):
                    picture = os.path.join(WORK, "lidar-%s.ppm" % backend)
                    if os.path.exists(picture):
                        os.remove(picture)
                    status, _, err = run("render", LIDAR, "-o", picture, "--backend", backend, "--size", "320x180",
                                         *options)
                    self.assertEqual(status, 0, err)
                    pictures.append(read_ppm(picture))
                (w, h, cpu), cuda = pictures[0], pictures[1]
                self.assertEqual(cuda[:2], (w, h))
                drawn = sum(1 for p in cpu if p != BACKGROUND)
                self.assertGreater(drawn, 0.02 * len(cpu), "too little drawn to compare")
                off = [max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(cpu, cuda[2])]
                self.assertLessEqual(max(off), self.MOST_OFF)
                self.assertGreaterEqual(off.count(0), self.SAME_FRACTION * len(off))


def load_tests(loader, tests, pattern):
    """Every class but OnCuda, which engine.tool.cuda names."""
    return unittest.TestSuite(suite for suite in tests if not any(isinstance(t, OnCuda) for t in suite))


if __name__ == "__main__":
    os.makedirs(WORK, exist_ok=True)
    unittest.main(argv=sys.argv[:1] + sys.argv[4:], verbosity=2)
