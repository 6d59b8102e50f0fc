"""octoray_bench_quality's image metrics (Benchmarks/Engine/ImageMetrics.h)
against scikit-image on real rendered pictures: the program renders the CT
series (written by Benchmarks/Report/scenes.py), the LiDAR tile and the sphere
field at a small size, dumps every compared pair as PFM, and each record's
RMSE, PSNR and SSIM must equal what scikit-image computes from the same
floats (SSIM per Wang et al. 2004: 11x11 Gaussian window, sigma 1.5,
population statistics, K1 0.01, K2 0.03, data range 1, RGB channels
averaged)."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "Benchmarks", "Report"))
import scenes  # noqa: E402

PROGRAM = os.environ.get("OCTORAY_BENCH_QUALITY")


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        data = np.fromfile(f, dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3)[::-1]  # PFM rows run from the bottom


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    if not PROGRAM:
        pytest.skip("OCTORAY_BENCH_QUALITY not set (run through ctest)")
    folder = str(tmp_path_factory.mktemp("quality"))
    scenes.write_ct5n(os.path.join(folder, "ct5n.particles"))
    out = os.path.join(folder, "q.json")
    subprocess.run([PROGRAM, "--backend", "cpu", "--scenes", folder, "--size", "96x64", "--repeats", "1",
                    "--sphere-points", "30000", "--json", out, "--dump", folder],
                   check=True, stdout=subprocess.DEVNULL)
    with open(out) as f:
        return folder, json.load(f)


def test_every_knob_of_every_scene_is_recorded(run):
    _, records = run
    assert {r["scene"] for r in records} == {"ct5n", "lidar", "spheres"}
    for scene in ("ct5n", "lidar", "spheres"):
        knobs = {r["knob"] for r in records if r["scene"] == scene}
        assert knobs == {"depth", "lod", "bounces", "shadows", "size", "reference-check"}
        # One reference row per knob, identical to its reference.
        refs = [r for r in records if r["scene"] == scene and r["is_reference"]]
        assert sorted(r["knob"] for r in refs) == ["bounces", "depth", "lod", "shadows", "size"]
        for r in refs:
            assert r["rmse"] == 0 and r["psnr"] is None and r["ssim"] == 1
    assert all(r["seconds"] > 0 for r in records)


def test_metrics_equal_scikit_image(run):
    folder, records = run
    compared = 0
    for r in records:
        a = read_pfm(os.path.join(folder, r["image"])).astype(np.float64)
        b = read_pfm(os.path.join(folder, r["reference_image"])).astype(np.float64)
        where = f"{r['scene']} {r['knob']} {r['value']}"
        ssim = structural_similarity(a, b, channel_axis=-1, data_range=1.0, gaussian_weights=True,
                                     sigma=1.5, use_sample_covariance=False, K1=0.01, K2=0.03)
        assert r["ssim"] == pytest.approx(ssim, abs=1e-7), where
        rmse = np.sqrt(np.mean((a - b) ** 2))
        assert r["rmse"] == pytest.approx(rmse, rel=1e-6, abs=1e-12), where
        if rmse > 0:
            psnr = peak_signal_noise_ratio(b, a, data_range=1.0)
            assert r["psnr"] == pytest.approx(psnr, rel=1e-7), where
            compared += 1
    # The comparison means something only if pictures differ, and by a
    # range of amounts.
    ssims = [r["ssim"] for r in records if r["rmse"] > 0]
    assert compared >= 20
    assert min(ssims) < 0.8 and max(ssims) > 0.95


def test_lower_sizes_are_repeated_pixels(run):
    """size 0.25: each rendered pixel fills a 4x4 block of the compared
    picture (nearest upsampling), and the picture is not blank."""
    folder, records = run
    for r in records:
        if r["knob"] == "size" and r["value"] == "0.25":
            a = read_pfm(os.path.join(folder, r["image"]))
            blocks = a.reshape(a.shape[0] // 4, 4, a.shape[1] // 4, 4, 3)
            assert np.array_equal(blocks, np.broadcast_to(blocks[:, :1, :, :1], blocks.shape)), r["scene"]
            assert a.max() > 0.1, r["scene"]
