"""The engine's command-line tool, `octoray`, as a user runs it.

usage: test_octoray_tool.py OCTORAY DATA_DIR WORK_DIR

- bad arguments: exit status 2, a message naming the option, what it
  expects and what it got (or the missing value, or the missing -o), and
  no picture written;
- a depth the engine refuses, and a file that does not exist: exit status 1
  and the engine's or the loader's message;
- `stats`: the points counted as the file holds them, one root node, and
  the nodes per level adding up to the node count;
- `render` to a PPM file: the picture has the requested size, every pixel a
  primary ray, and the points drawn (pixels off the background).
Plain python3 (no VTK, no pytest): the tool builds without VTK.
"""
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
        (["render", LIDAR, "-o", STRAY, "--size", "0x10"], "--size expects a size WxH such as 1920x1080, not '0x10'"),
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
        self.assertIn("usage: octoray", err)


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


if __name__ == "__main__":
    os.makedirs(WORK, exist_ok=True)
    unittest.main(argv=sys.argv[:1], verbosity=2)
