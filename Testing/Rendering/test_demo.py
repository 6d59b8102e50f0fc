"""`make demo`'s program, python3 -m octoray.demo, at a quarter of its picture
size (label python, vtk): the real data of Data/External (make data), every
step's timing line, and pictures that show something.

The full-size demo (make demo) takes about a minute on 2 busy cores, most
of it vtkSmartVolumeMapper in Mesa's llvmpipe; this run, its quarter-size
version, takes about a third of that.
"""
import os
import subprocess
import sys

import numpy as np
from octoray.png import read_png

DATA = os.environ.get("OCTORAY_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "Data"))


def read_rgb(path):
    """width, height and the (height, width, 3) colours as int."""
    rgb = read_png(path)[:, :, :3].astype(int)
    return rgb.shape[1], rgb.shape[0], rgb


def test_demo_quarter_size(tmp_path):
    r = subprocess.run([sys.executable, "-m", "octoray.demo", "--data", DATA, "--out", str(tmp_path),
                        "--backend", "cpu", "--scale", "0.25"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    out = r.stdout
    for line in ("[1/3] head CT", "108 slices, 256 x 256 x 108 voxels", "-1024..2986 HU",
                 "ct-bone  threshold 306 HU", "ct-skin  threshold -750 HU", "depth 8, leaf 0.957",
                 "vtkSmartVolumeMapper", "cut      CT-Bone cropped to the back 55 % of the head", "1 build:",
                 "[2/3] laser scan", "460,400 points", "s: fitted to the voxels, in the first frame",
                 "Intensity through viridis over 0..52 (percentiles 1..99 of 0..246)",
                 "[3/3] thesis LiDAR", "1,065 points", "colours: the points' own RGB", "backend CPU",
                 "demo                               total"):
        assert line in out, line
    # The progress lines (stderr): reading, building.
    for label in ("reading", "building"):
        assert label in r.stderr
    expected = {"ct-bone.png": (240, 240), "ct-skin.png": (240, 240), "ct-compare.png": (400, 200),
                "ct-bone-cut.png": (240, 240),
                "scan.png": (300, 225), "lidar.png": (300, 225)}
    for name, size in expected.items():
        path = tmp_path / name
        assert path.exists(), name
        w, h, rgb = read_rgb(str(path))
        assert (w, h) == size, (name, w, h)
        # Something drawn over the gradient background: pixels far from
        # their row's first pixel (the background is constant along a row).
        drawn = (np.abs(rgb - rgb[:, :1, :]).max(axis=2) > 40).mean()
        assert drawn > 0.05, (name, drawn)
    # The comparison's two halves both show the skull.
    w, h, rgb = read_rgb(str(tmp_path / "ct-compare.png"))
    for half in (rgb[:, : w // 2], rgb[:, w // 2:]):
        assert (np.abs(half - half[:, :1, :]).max(axis=2) > 40).mean() > 0.05
