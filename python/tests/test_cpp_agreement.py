"""A Python call and the C++ call on the same data give the same n.

The C++ side is the `rcm` executable (`rcm estimate --calib RIG --matches
CSV --json`), found through RCM_EXECUTABLE or on PATH. Its JSON prints
doubles in their shortest round-trip form (nlohmann::json), so the n read
back is the C++ double exactly; the two must agree to 1e-12 (in practice
bit for bit: the same library code on the same doubles).
"""
import json
import os
import shutil
import subprocess

import numpy as np
import pytest

import rcm


def rcm_executable():
    path = os.environ.get("RCM_EXECUTABLE") or shutil.which("rcm")
    if not path or not os.access(path, os.X_OK):
        pytest.skip("the rcm executable was not found (set RCM_EXECUTABLE, "
                    "e.g. build/bin/rcm, or put rcm on PATH)")
    return path


def run_estimate(rig_path, csv_path, *flags):
    completed = subprocess.run(
        [rcm_executable(), "estimate", "--calib", str(rig_path), "--matches",
         str(csv_path), "--json", *flags],
        capture_output=True, text=True, timeout=60, check=False)
    assert completed.returncode == 0, completed.stderr
    return json.loads(completed.stdout)


def test_demo_data_gives_the_same_n(demo_rig_path, demo_matches_path):
    cpp = run_estimate(demo_rig_path, demo_matches_path)
    rig = rcm.read_stereo_rig(demo_rig_path)
    matches = rcm.read_correspondences(demo_matches_path)
    py = rcm.refine_refractive_index(rig, matches)
    assert abs(py.n - cpp["n"]) <= 1e-12
    assert py.sigma_n == pytest.approx(cpp["sigma_n"], rel=1e-12, abs=1e-15)
    assert py.crlb == pytest.approx(cpp["crlb"], rel=1e-12, abs=1e-15)
    assert py.num_inliers == cpp["inliers"]


def test_noisy_unrectified_data_with_options(tmp_path):
    # The CLI's --loss/--loss-scale/--inlier-threshold are the options'
    # loss, loss_scale_px and inlier_threshold_px.
    rig = rcm.reference_rig("alphasense-unrectified")
    rig_path = tmp_path / "rig.yaml"
    rig.write(rig_path)
    exact = rcm.sample_correspondences(rig, n=1.34, num_frames=3,
                                       per_frame=300, seed=17)
    matches = rcm.add_pixel_noise(exact, 0.4, seed=18)
    csv_path = tmp_path / "m.csv"
    rcm.write_correspondences(csv_path, matches)
    cpp = run_estimate(rig_path, csv_path, "--loss", "huber", "--loss-scale",
                       "0.8", "--inlier-threshold", "1.5")
    # The file's rig (with its default drift prior), read as the CLI does.
    file_rig = rcm.read_stereo_rig(rig_path)
    py = rcm.refine_refractive_index(
        file_rig, rcm.read_correspondences(csv_path), loss="huber",
        loss_scale_px=0.8, inlier_threshold_px=1.5)
    assert abs(py.n - cpp["n"]) <= 1e-12
    assert py.sigma_n == pytest.approx(cpp["sigma_n"], rel=1e-12, abs=1e-15)
    assert py.num_inliers == cpp["inliers"]
    assert np.isfinite(py.n)


def test_same_n_to_seventeen_digits(tmp_path):
    # rcm_refine_timing (benchmarks/python/refine_timing.cc, built with the
    # package next to rcm) prints n with %.17g: the exact double.
    path = os.environ.get("RCM_REFINE_TIMING")
    if not path and os.environ.get("RCM_EXECUTABLE"):
        path = os.path.join(os.path.dirname(os.environ["RCM_EXECUTABLE"]),
                            "rcm_refine_timing")
    path = path or shutil.which("rcm_refine_timing")
    if not path or not os.access(path, os.X_OK):
        pytest.skip("rcm_refine_timing was not found (set RCM_REFINE_TIMING "
                    "or RCM_EXECUTABLE=build/bin/rcm)")
    rig = rcm.reference_rig("alphasense-unrectified")
    rig_path = tmp_path / "rig.yaml"
    rig.write(rig_path)
    exact = rcm.sample_correspondences(rig, n=1.29, num_frames=4,
                                       per_frame=250, seed=31)
    csv_path = tmp_path / "m.csv"
    rcm.write_correspondences(csv_path, rcm.add_pixel_noise(exact, 0.6,
                                                            seed=32))
    completed = subprocess.run([path, str(rig_path), str(csv_path)],
                               capture_output=True, text=True, timeout=60,
                               check=True)
    cpp = json.loads(completed.stdout)
    py = rcm.refine_refractive_index(rcm.read_stereo_rig(rig_path),
                                     rcm.read_correspondences(csv_path))
    assert abs(py.n - cpp["n"]) <= 1e-12
    assert py.sigma_n == pytest.approx(cpp["sigma_n"], rel=1e-12)


def same_value(py, cpp, where):
    """py and cpp equal: numbers to 1e-12 relative, containers key by key."""
    if isinstance(py, dict):
        assert isinstance(cpp, dict) and set(py) == set(cpp), where
        for key in py:
            same_value(py[key], cpp[key], where + "." + key)
    elif isinstance(py, list):
        assert isinstance(cpp, list) and len(py) == len(cpp), where
        for i, (a, b) in enumerate(zip(py, cpp)):
            same_value(a, b, f"{where}[{i}]")
    elif isinstance(py, float) or isinstance(cpp, float):
        assert py == pytest.approx(cpp, rel=1e-12, abs=1e-15), where
    else:
        assert py == cpp, where


@pytest.mark.parametrize("estimator", ["refine", "online", "window",
                                       "closed-form"])
def test_estimate_json_keys_mean_the_same(tmp_path, estimator):
    # One estimate type and one JSON writer: rcm.Estimate.to_dict() and
    # `rcm estimate --json` on the same matches with the same options have
    # the same keys with the same values; the CLI adds only what it knows
    # of its run (the rig file, the input, the medium).
    rig = rcm.reference_rig("alphasense-unrectified")
    rig_path = tmp_path / "rig.yaml"
    rig.write(rig_path)
    exact = rcm.sample_correspondences(rig, n=1.34, num_frames=4,
                                       per_frame=200, seed=41)
    csv_path = tmp_path / "m.csv"
    rcm.write_correspondences(csv_path, rcm.add_pixel_noise(exact, 0.5,
                                                            seed=42))
    cpp = run_estimate(rig_path, csv_path, "--estimator", estimator,
                       "--window", "3")
    py = rcm.estimate_refractive_index(
        rcm.read_stereo_rig(rig_path), rcm.read_correspondences(csv_path),
        estimator=estimator, window_frames=3, detect_systematic=True)
    as_dict = py.to_dict()
    assert set(cpp) - set(as_dict) == {"medium", "rig", "matches"}
    for key, value in as_dict.items():
        same_value(value, cpp[key], key)
    assert abs(py.n - cpp["n"]) <= 1e-12
    # The attributes are the keys.
    assert py.sigma_n == as_dict["sigma_n"]
    assert py.warnings == as_dict["warnings"]
    assert py.calibration == as_dict["calibration"]
    assert py.estimator == estimator
