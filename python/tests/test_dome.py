"""Dome ports: rcm.DomePort, rcm.DomePortCamera (round trip, a centred dome
is the air camera), the error of ignoring a dome (rcm dome-check), and the
underwater calibration through a dome on noise-free corners. Mirrors
tests/camera/dome_port_test.cc, tests/estimation/dome_port_error_test.cc
and tests/calib/dome_calibration_test.cc."""
import numpy as np
import pytest

import rcm
from conftest import image_grid, one_line
from test_calibration import rotation

# As the C++ tests: a dome that does not refract is the air camera to
# 1e-12 px; the forward solve converges to 1e-9 px; noise-free corners give
# the decentering to 1e-9 m.
AIR = 1e-12
ROUND_TRIP = 1e-9
EXACT = 1e-9


def acrylic_dome(decentering=(0.0, 0.0, 0.0)):
    """The 4-inch acrylic dome of the issue: 43.55 mm inside, 47.30 mm
    outside."""
    return rcm.DomePort(inner_radius=0.04355, outer_radius=0.0473,
                        glass_index=1.495, decentering=decentering)


@pytest.fixture(scope="module")
def lens(ideal_rig):
    return ideal_rig.cam0.lens


def test_dome_port_fields():
    dome = acrylic_dome((0.0, 0.0, 0.0072))
    assert dome.inner_radius == 0.04355
    assert dome.thickness == pytest.approx(0.00375, abs=1e-15)
    assert dome.outer_radius == pytest.approx(0.0473, abs=1e-15)
    assert dome.glass_index == 1.495
    assert dome.decentering.shape == (3,)
    np.testing.assert_array_equal(dome.decentering, [0.0, 0.0, 0.0072])
    assert not dome.is_centred and acrylic_dome().is_centred
    dome.check()
    same = rcm.DomePort(0.04355, thickness=dome.thickness, glass_index=1.495,
                        decentering=[0, 0, 0.0072])
    assert same == dome
    assert "DomePort(inner_radius=0.04355" in repr(dome)
    # Set, then checked.
    dome.decentering = (0.0, 0.0, 0.05)
    with pytest.raises(ValueError) as error:
        dome.check()
    assert "outside the inner sphere" in one_line(error)


def test_round_trip_through_a_decentered_dome(lens):
    camera = rcm.DomePortCamera(lens, acrylic_dome((0.002, -0.001, 0.006)),
                                1.333)
    assert camera.n == 1.333 and camera.camera == lens
    pixels = image_grid(lens, 60.0)
    origins, directions = camera.ray_from_image(pixels)
    assert origins.shape == directions.shape == (len(pixels), 3)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0,
                               atol=1e-15)
    # Origins on the outer surface.
    np.testing.assert_allclose(
        np.linalg.norm(origins - camera.dome.decentering, axis=1), 0.0473,
        atol=1e-15)
    points = origins + 1.5 * directions
    back = camera.image_from_point(points)
    np.testing.assert_allclose(back, pixels, rtol=0, atol=ROUND_TRIP)
    # One pixel gives (3,) arrays; a point inside the dome is NaN.
    origin, direction = camera.ray_from_image(pixels[0])
    assert origin.shape == direction.shape == (3,)
    assert np.all(np.isnan(camera.image_from_point([[0.0, 0.0, 0.02]])))
    assert "DomePortCamera(Camera(" in repr(camera)


def test_centred_dome_is_the_air_camera(lens):
    camera = rcm.DomePortCamera(lens, acrylic_dome(), 1.333)
    pixels = image_grid(lens, 40.0)
    origins, directions = camera.ray_from_image(pixels)
    normalized = lens.normalized_from_image(pixels)
    expected = np.column_stack([normalized, np.ones(len(normalized))])
    expected /= np.linalg.norm(expected, axis=1, keepdims=True)
    np.testing.assert_allclose(directions, expected, rtol=0, atol=1e-15)
    points = 2.0 * expected
    np.testing.assert_allclose(
        camera.image_from_point(points),
        lens.image_from_normalized(points[:, :2] / points[:, 2:]), rtol=0,
        atol=AIR)
    # Ignoring a centred dome costs nothing.
    error = rcm.ignored_dome_error(camera, pixels, 0.5)
    assert np.max(np.abs(error)) <= AIR
    result = rcm.evaluate_dome_port_error(camera, grid_step=24.0)
    assert result.max_px <= AIR


def test_dome_check(lens):
    camera = rcm.DomePortCamera(lens, acrylic_dome((0.0, 0.0, 0.0072)), 1.333)
    result = rcm.evaluate_dome_port_error(camera, min_depth=0.5, max_depth=5.0,
                                          num_depths=6, grid_step=16.0,
                                          reference_depth=1.0)
    assert result.depths.shape == (6,)
    assert result.depths[0] == 0.5 and result.depths[-1] == 5.0
    assert result.max_px == result.max_px_per_depth.max()
    assert result.worst_depth == result.depths[result.worst_index]
    assert result.max_px > 5.0
    assert np.all(result.rms_px_per_depth <= result.max_px_per_depth)
    assert np.all(result.num_unusable == 0)
    field = result.worst_field
    assert field.shape == result.worst_field_pixels.shape
    assert np.nanmax(np.linalg.norm(field, axis=2)) == result.max_px
    # The field is the per-pixel function's.
    pixels = result.worst_field_pixels.reshape(-1, 2)[::97]
    np.testing.assert_allclose(
        rcm.ignored_dome_error(camera, pixels, result.worst_depth),
        field.reshape(-1, 2)[::97], rtol=0, atol=1e-12)
    # The central camera exact at 1 m.
    assert result.reference_depth == 1.0
    assert result.reference_max_px > 5.0
    assert 0.01 < result.central_max_px < result.max_px
    assert result.central_max_px_per_depth.shape == (6,)
    at_reference = rcm.central_dome_error(camera, pixels, 1.0, 1.0)
    assert np.max(np.abs(at_reference)) < 1e-9
    assert "DomePortError(max_px=" in repr(result)
    plain = rcm.evaluate_dome_port_error(camera, grid_step=32.0)
    assert plain.reference_depth is None and plain.central_max_px is None
    assert plain.central_max_px_per_depth is None


def dome_views(camera, target, count, seed):
    """Noise-free corners of `count` board poses in the water, the board's
    centre on the dome rays of a jittered 3x3 pixel grid at 0.45-0.9 m,
    tilted up to 35 degrees; with the poses."""
    rng = np.random.default_rng(seed)
    lens = camera.camera
    center = target.points.mean(axis=0)
    views, poses = [], []
    for i in range(count):
        cell = i % 9
        u = 0.5 + 0.3 * (cell % 3 - 1) + 0.04 * rng.uniform(-1, 1)
        v = 0.5 + 0.3 * (cell // 3 - 1) + 0.04 * rng.uniform(-1, 1)
        origin, direction = camera.ray_from_image([u * lens.width,
                                                   v * lens.height])
        depth = rng.uniform(0.45, 0.9)
        tilt = np.deg2rad(35.0)
        r = (rotation([0, 0, np.deg2rad(30) * rng.uniform(-1, 1)])
             @ rotation([0, tilt * rng.uniform(-1, 1), 0])
             @ rotation([tilt * rng.uniform(-1, 1), 0, 0]))
        pose = np.eye(4)
        pose[:3, :3] = r
        pose[:3, 3] = (origin + (depth - origin[2]) / direction[2] * direction
                       - r @ center)
        points = target.points @ r.T + pose[:3, 3]
        pixels = camera.image_from_point(points)
        ok = np.all(np.isfinite(pixels), axis=1)
        ok[ok] = lens.in_image(pixels[ok])
        views.append((np.flatnonzero(ok), pixels[ok]))
        poses.append(pose)
    return views, poses


def test_calibration_recovers_the_decentering(lens):
    target = rcm.CalibrationTarget.checkerboard(9, 6, 0.04)
    truth = (0.002, -0.001, 0.006)
    camera = rcm.DomePortCamera(lens, acrylic_dome(truth), 1.333)
    views, poses = dome_views(camera, target, 12, seed=3)
    result = rcm.calibrate_dome_from_corners(target, views, lens,
                                             acrylic_dome(), n=1.333)
    assert result.decentering.shape == (1, 3)
    np.testing.assert_allclose(result.decentering[0], truth, rtol=0,
                               atol=EXACT)
    assert result.decentering_sigma.shape == (1, 3)
    assert result.decentering_covariance.shape == (1, 3, 3)
    assert result.n == 1.333 and result.sigma_n == 0.0
    assert not result.n_estimated
    assert result.rms_px < EXACT
    assert result.num_views_used == 12
    assert result.view_weights.shape == (12,)
    assert np.all((result.view_weights >= 1 / 16)
                  & (result.view_weights <= 16))
    assert result.conventional_rms_px is None or result.conventional_rms_px > 0
    assert result.conventional["ok"] == (result.conventional_rms_px
                                         is not None)
    assert len(result.candidates) >= 1
    names = [c["name"] for c in result.candidates]
    assert names[result.chosen] in ("flat board", "bowed board")
    assert result.candidates[result.chosen]["decentering"].shape == (1, 3)
    assert result.rule
    for estimate, pose in zip(result.cam0_from_target, poses):
        np.testing.assert_allclose(estimate, pose, atol=EXACT)
    assert "DomeCalibrationResult(decentering_mm=[[" in repr(result)


def test_bad_input(lens):
    with pytest.raises(ValueError) as error:
        acrylic_dome((0.0, 0.0, 0.05))
    assert "outside the inner sphere" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.DomePort(0.04355, thickness=0.005, outer_radius=0.0473)
    assert "not the 0.005 m given" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.DomePort(0.04355)
    assert "thickness or outer_radius" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.DomePort(43.55, thickness=0.004)
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.DomePortCamera(lens, acrylic_dome(), 2.5)
    assert "n = 2.5" in one_line(error)
    camera = rcm.DomePortCamera(lens, acrylic_dome((0, 0, 0.007)), 1.333)
    with pytest.raises(ValueError) as error:
        rcm.evaluate_dome_port_error(camera, min_depth=0.02)
    assert "not beyond the dome" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.evaluate_dome_port_error(camera, min_depth=5.0, max_depth=1.0)
    assert "below min_depth" in one_line(error)
    target = rcm.CalibrationTarget.checkerboard(9, 6, 0.04)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_dome_from_corners(target, [None] * 3, lens,
                                        acrylic_dome())
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_dome_from_corners(target, [None] * 3, [lens, lens],
                                        [acrylic_dome()])
    assert "differ in length" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_dome_from_corners(target, [(None, None)] * 3,
                                        [lens, lens],
                                        [acrylic_dome(), acrylic_dome()])
    assert "cam1_from_cam0" in one_line(error)
    with pytest.raises(TypeError) as error:
        rcm.calibrate_dome_from_corners(target, [None] * 3, lens,
                                        acrylic_dome(), n_estimate=True)
    assert "unexpected keyword argument 'n_estimate'" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.calibrate_dome_from_corners(target, [None] * 3, lens,
                                        acrylic_dome(), n=3.0)
    one_line(error)


def test_calibration_options_weigh_views_and_folds(lens):
    target = rcm.CalibrationTarget.checkerboard(9, 6, 0.04)
    truth = (-0.001, 0.002, 0.008)
    camera = rcm.DomePortCamera(lens, acrylic_dome(truth), 1.333)
    views, _ = dome_views(camera, target, 8, seed=5)
    # Unweighted views and no leave-out: the same exact answer.
    result = rcm.calibrate_dome_from_corners(target, views, lens,
                                             acrylic_dome(), n=1.333,
                                             weigh_views=False, folds=0)
    np.testing.assert_allclose(result.decentering[0], truth, rtol=0,
                               atol=EXACT)
    np.testing.assert_array_equal(result.view_weights, np.ones(8))
    with pytest.raises(ValueError) as error:
        rcm.calibrate_dome_from_corners(target, views, lens, acrylic_dome(),
                                        folds=1)
    assert "folds" in one_line(error)
