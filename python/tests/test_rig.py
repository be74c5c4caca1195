"""Rig files: reading camchains and camera_info pairs, writing, properties."""
import numpy as np
import pytest

import rcm
from conftest import one_line, thick_port

# docs/design.md, "The reference rig": the published calibration of the
# dataset's front pair.
CAM0_INTRINSICS = [346.68681661781403, 346.7780959214622, 360.53325988648163,
                   271.0179819820658]
CAM0_DISTORTION = [-0.037934508908317364, -0.0009855550912794707,
                   -0.0009622185860956224, 2.365797666527927e-05]


def test_version_is_the_projects():
    assert rcm.__version__.count(".") == 2


def test_reads_the_demo_camchain(demo_rig_path):
    rig = rcm.read_stereo_rig(demo_rig_path)
    assert rig.cam0.model == "equidistant"
    assert rig.cam0.image_size == (720, 540)
    np.testing.assert_array_equal(rig.cam0.intrinsics, CAM0_INTRINSICS)
    np.testing.assert_array_equal(rig.cam0.distortion, CAM0_DISTORTION)
    expected = np.eye(4)
    expected[0, 3] = -0.11
    np.testing.assert_array_equal(rig.cam1_from_cam0, expected)
    np.testing.assert_array_equal(rig.rotation, np.eye(3))
    np.testing.assert_array_equal(rig.translation, [-0.11, 0.0, 0.0])
    assert rig.baseline == pytest.approx(0.11, abs=1e-15)
    assert rig.ports is None and not rig.has_thick_port
    assert rig.camera(1).fx == rig.cam1.fx == rig.right.fx
    # A rig read from a file carries the default drift prior.
    uncertainty = rig.calibration_uncertainty
    assert uncertainty is not None and "drift prior" in uncertainty["source"]
    sigma = np.deg2rad(0.1)
    np.testing.assert_allclose(
        np.diag(uncertainty["extrinsics_covariance"])[:3], sigma**2, rtol=1e-12)
    # The lenses carry the default focal drift prior (0.3 %: fx and fy of
    # each camera scale together), without a correlation with the
    # extrinsics or between the cameras.
    assert "focal drift prior 0.3 %" in uncertainty["source"]
    lens = uncertainty["left_lens_covariance"]
    fx, fy = rig.cam0.intrinsics[:2]
    np.testing.assert_allclose(lens[:2, :2],
                               0.003**2 * np.outer([fx, fy], [fx, fy]),
                               rtol=1e-12)
    assert not lens[2:, :].any() and not lens[:, 2:].any()
    assert uncertainty["extrinsics_lens_covariance"].size == 0
    assert uncertainty["port_covariance"].size == 0
    assert uncertainty["lens_cross_covariance"].size == 0
    # focal_drift=0: the lenses as calibrated.
    exact = rcm.read_stereo_rig(demo_rig_path, focal_drift=0.0)
    assert exact.calibration_uncertainty["left_lens_covariance"].size == 0
    with pytest.raises(ValueError, match="focal_drift must be"):
        rcm.read_stereo_rig(demo_rig_path, focal_drift=-1.0)
    # with_drift_prior: the focal sigma is its third argument.
    prior = rig.with_drift_prior(0.0, 0.0, focal_sigma=0.01)
    np.testing.assert_allclose(
        prior.calibration_uncertainty["right_lens_covariance"][0, 0],
        (0.01 * rig.cam1.fx)**2, rtol=1e-12)
    assert rig.with_drift_prior(0.0, 0.0).calibration_uncertainty[
        "right_lens_covariance"].size == 0


def test_write_reads_back_identical(tmp_path, demo_rig_path):
    rig = rcm.read_stereo_rig(str(demo_rig_path))
    path = tmp_path / "rig.yaml"
    rig.write(path)
    back = rcm.read_stereo_rig(path)
    assert back.cam0.lens == rig.cam0.lens and back.cam1.lens == rig.cam1.lens
    np.testing.assert_array_equal(back.cam1_from_cam0, rig.cam1_from_cam0)
    # Written again, the file is byte-identical.
    again = tmp_path / "again.yaml"
    rcm.write_stereo_rig(again, back)
    assert again.read_bytes() == path.read_bytes()


def test_ports_round_trip_through_the_camchain(tmp_path, thick_rig):
    path = tmp_path / "thick.yaml"
    thick_rig.write(path)
    back = rcm.read_stereo_rig(path)
    assert back.has_thick_port
    left, right = back.ports
    assert left == thick_port() and right == thick_port()
    assert left.air_gap == 0.008 and left.glass_thickness == 0.006
    np.testing.assert_array_equal(left.normal, [0.0, 0.0, 1.0])
    assert back.cam0.port == thick_port()
    np.testing.assert_array_equal(back.cam1_from_cam0, thick_rig.cam1_from_cam0)


def _camera_info(name, fx, cx, cy, tx):
    k = [fx, 0.0, cx, 0.0, fx, cy, 0.0, 0.0, 1.0]
    p = [fx, 0.0, cx, tx, 0.0, fx, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    flow = lambda values: "[" + ", ".join(repr(float(v)) for v in values) + "]"
    return (f"image_width: 720\nimage_height: 540\ncamera_name: {name}\n"
            f"camera_matrix:\n  rows: 3\n  cols: 3\n  data: {flow(k)}\n"
            "distortion_model: plumb_bob\n"
            "distortion_coefficients:\n  rows: 1\n  cols: 5\n"
            "  data: [-0.28, 0.07, 0.0002, 1.8e-05, 0.0]\n"
            "rectification_matrix:\n  rows: 3\n  cols: 3\n"
            "  data: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
            f"projection_matrix:\n  rows: 3\n  cols: 4\n  data: {flow(p)}\n")


def test_reads_a_camera_info_pair(tmp_path):
    left = tmp_path / "left.yaml"
    right = tmp_path / "right.yaml"
    left.write_text(_camera_info("left", 458.0, 367.0, 248.0, 0.0))
    # Tx = -fx' * B for a baseline of 0.11 m.
    right.write_text(_camera_info("right", 458.0, 367.0, 248.0, -458.0 * 0.11))
    rig = rcm.read_stereo_rig(left, right)
    assert rig.cam0.model == "radtan"
    np.testing.assert_allclose(rig.translation, [-0.11, 0.0, 0.0], atol=1e-15)
    np.testing.assert_array_equal(rig.rotation, np.eye(3))


def test_missing_file_is_an_oserror(tmp_path):
    with pytest.raises(FileNotFoundError) as error:
        rcm.read_stereo_rig(tmp_path / "missing.yaml")
    assert "missing.yaml" in one_line(error)
    with pytest.raises(OSError):
        rcm.read_stereo_rig(tmp_path / "missing_left.yaml", tmp_path / "r.yaml")


def test_bad_contents_are_a_valueerror(tmp_path, demo_rig_path):
    path = tmp_path / "bad.yaml"
    text = demo_rig_path.read_text().replace(
        "intrinsics: [346.68681661781403, 346.7780959214622, "
        "360.53325988648163, 271.0179819820658]",
        "intrinsics: [346.68681661781403, 346.7780959214622, 360.5]")
    path.write_text(text)
    with pytest.raises(ValueError) as error:
        rcm.read_stereo_rig(path)
    message = one_line(error)
    assert "bad.yaml" in message and "intrinsics" in message


def test_unknown_camera_name_is_a_valueerror(demo_rig_path):
    with pytest.raises(ValueError) as error:
        rcm.read_stereo_rig(demo_rig_path, right_camera="cam7")
    assert "cam7" in one_line(error)


def test_rig_from_code_and_its_checks():
    lens = rcm.Camera("radtan", 752, 480, [458.0, 457.0, 367.0, 248.0],
                      [-0.28, 0.07, 0.0002, 1.8e-05])
    pose = np.eye(4)
    pose[0, 3] = -0.1
    rig = rcm.StereoRig(lens, lens, pose)
    assert rig.calibration_uncertainty is None
    assert rig.baseline == pytest.approx(0.1)
    with pytest.raises(ValueError) as error:
        rcm.StereoRig(lens, lens, np.eye(4))  # zero baseline
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.StereoRig(lens, lens, np.eye(3))
    assert "(4, 4)" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.Camera("radtan", 752, 480, [458.0, 457.0, 367.0, 248.0], [0.1])
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.Camera("fisheye", 752, 480, [458.0, 457.0, 367.0, 248.0])
    assert "fisheye" in one_line(error)


def test_invalid_port_is_a_valueerror():
    with pytest.raises(ValueError) as error:
        rcm.FlatPort(air_gap=8.0)
    assert "air_gap" in one_line(error)
