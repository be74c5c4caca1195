"""Cameras: pixel <-> water ray round trips (thin and thick ports), the lens
maps, and the virtual pinhole maps."""
import numpy as np
import pytest

import rcm
from conftest import image_grid, one_line

# The C++ camera tests' tolerance for a round trip (refractive_camera_test).
ROUND_TRIP_PX = 1e-9


@pytest.mark.parametrize("n", [1.0, 1.333, 1.6])
def test_thin_port_round_trip(ideal_rig, n):
    camera = ideal_rig.cam0
    pixels = image_grid(camera, 16.0)
    origins, directions = camera.pixel_to_ray(pixels, n)
    assert origins.shape == directions.shape == (len(pixels), 3)
    assert np.all(np.isfinite(directions))
    np.testing.assert_array_equal(origins, 0.0)  # central: the camera center
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0,
                               atol=1e-15)
    for distance in (0.3, 2.0, 50.0):
        back = camera.point_to_pixel(origins + distance * directions, n)
        assert np.max(np.abs(back - pixels)) < ROUND_TRIP_PX


@pytest.mark.parametrize("n", [1.0, 1.335])
def test_thick_port_round_trip(thick_rig, n):
    for camera in (thick_rig.cam0, thick_rig.cam1):
        assert not camera.is_thin_port
        pixels = image_grid(camera, 24.0)
        origins, directions = camera.pixel_to_ray(pixels, n)
        ok = np.all(np.isfinite(directions), axis=1)
        assert ok.mean() > 0.95  # the corners of the fisheye may miss
        # Non-central: origins on the outer glass face, 14 mm out.
        np.testing.assert_allclose(origins[ok, 2], 0.014, atol=1e-12)
        for distance in (0.3, 2.0, 20.0):
            points = origins[ok] + distance * directions[ok]
            back = camera.point_to_pixel(points, n)
            assert np.max(np.abs(back - pixels[ok])) < ROUND_TRIP_PX


def test_thick_port_at_n_one_and_no_glass_is_the_pinhole_ray():
    lens = rcm.Camera("none", 640, 480, [500.0, 500.0, 320.0, 240.0])
    pose = np.eye(4)
    pose[0, 3] = -0.1
    port = rcm.FlatPort(air_gap=0.01)
    rig = rcm.StereoRig(lens, lens, pose).with_ports(port, port)
    pixel = np.array([[420.0, 140.0]])
    origin, direction = rig.cam0.pixel_to_ray(pixel, 1.0)
    expected = np.array([0.2, -0.2, 1.0]) / np.linalg.norm([0.2, -0.2, 1.0])
    np.testing.assert_allclose(direction[0], expected, atol=1e-15)
    np.testing.assert_allclose(origin[0], 0.01 * np.array([0.2, -0.2, 1.0]),
                               atol=1e-15)


def test_single_pixel_and_failures(ideal_rig):
    camera = ideal_rig.cam0
    origin, direction = camera.pixel_to_ray([360.0, 270.0], 1.333)
    assert origin.shape == direction.shape == (3,)
    # Behind the camera and past the critical angle: NaN, not an error.
    pixels = camera.point_to_pixel([[0.0, 0.0, -1.0], [1.0, 0.0, 1e-3],
                                    [0.1, 0.2, 2.0]], 1.333)
    assert np.all(np.isnan(pixels[:2])) and np.all(np.isfinite(pixels[2]))
    empty = camera.point_to_pixel(np.zeros((0, 3)), 1.333)
    assert empty.shape == (0, 2)


def test_bad_camera_inputs(ideal_rig):
    camera = ideal_rig.cam0
    with pytest.raises(ValueError) as error:
        camera.pixel_to_ray(np.zeros((4, 3)), 1.333)
    assert "(N, 2)" in one_line(error)
    with pytest.raises(ValueError) as error:
        camera.pixel_to_ray(np.zeros((4, 2)), 2.5)
    one_line(error)
    with pytest.raises(TypeError) as error:
        camera.point_to_pixel(np.array([["a", "b", "c"]]), 1.333)
    one_line(error)
    # float32 and non-contiguous input are converted.
    pixels = image_grid(camera, 40.0)
    strided = np.asfortranarray(pixels)[::2]
    reference = camera.pixel_to_ray(np.ascontiguousarray(strided), 1.2)[1]
    np.testing.assert_array_equal(camera.pixel_to_ray(strided, 1.2)[1], reference)
    as32 = pixels.astype(np.float32)
    np.testing.assert_array_equal(
        camera.pixel_to_ray(as32, 1.2)[1],
        camera.pixel_to_ray(as32.astype(np.float64), 1.2)[1])


def test_lens_maps_invert_each_other(realistic_rig):
    lens = realistic_rig.cam1.lens
    pixels = image_grid(lens, 30.0)
    normalized = lens.normalized_from_image(pixels)
    back = lens.image_from_normalized(normalized)
    assert np.max(np.abs(back - pixels)) < ROUND_TRIP_PX
    assert lens.in_image(pixels).all()
    assert not lens.in_image([[-1.0, 0.0]])[0]


def test_virtual_pinhole_maps_are_the_exact_model(ideal_rig):
    n = 1.333
    corrected = rcm.virtual_pinhole_maps(ideal_rig, n, fit="virtual-pinhole")
    left = corrected.left
    assert left.map_x.dtype == np.float32 and left.map_x.shape == (540, 720)
    # K' = K_n = diag(n fx, n fy, 1) with the camera's principal point.
    k_n = ideal_rig.cam0.virtual_pinhole_matrix(n)
    np.testing.assert_allclose(left.K, k_n, rtol=1e-15)
    assert left.pinhole.model == "none"
    # Every valid map entry is the exact raw pixel of its output pixel,
    # to float32 rounding (a few 1e-5 px at 720 px).
    ys, xs = np.mgrid[0:540:37, 0:720:41]
    out = np.stack([xs.ravel(), ys.ravel()], axis=1).astype(np.float64)
    raw = left.raw_from_corrected(out)
    mx = left.map_x[ys.ravel(), xs.ravel()]
    my = left.map_y[ys.ravel(), xs.ravel()]
    valid = mx >= 0
    assert valid.mean() > 0.5
    np.testing.assert_allclose(mx[valid], raw[valid, 0], atol=1e-4)
    np.testing.assert_allclose(my[valid], raw[valid, 1], atol=1e-4)
    # corrected_from_raw inverts raw_from_corrected.
    again = left.corrected_from_raw(raw[valid])
    assert np.max(np.abs(again - out[valid])) < ROUND_TRIP_PX


def test_virtual_pinhole_correct_and_remap_agree(ideal_rig):
    corrected = rcm.virtual_pinhole_maps(ideal_rig, 1.333)
    rng = np.random.default_rng(5)
    image = rng.integers(0, 256, size=(540, 720), dtype=np.uint8)
    mine = corrected.left.correct(image)
    theirs = rcm.remap(image, corrected.left.maps)
    assert mine.shape == (540, 720) and mine.dtype == np.uint8
    # cv2.remap rounds sampling positions to 1/32 px either way.
    assert np.max(np.abs(mine.astype(int) - theirs.astype(int))) <= 1
    with pytest.raises(ValueError) as error:
        corrected.left.correct(image.astype(np.float32))
    assert "uint8" in one_line(error)
    with pytest.raises(ValueError) as error:
        corrected.left.correct(image[:100])
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.virtual_pinhole_maps(ideal_rig, 1.333, fit="widest")
    assert "widest" in one_line(error)


def test_rectified_virtual_pinhole_rig_writes_its_camchain(tmp_path,
                                                           realistic_rig):
    corrected = rcm.virtual_pinhole_maps(realistic_rig, 1.333, rectify=True)
    rig = corrected.corrected_rig
    # The ideal rectified pair: R = I, t = (-b, 0, 0), one K' for both.
    np.testing.assert_allclose(rig.rotation, np.eye(3), atol=1e-15)
    np.testing.assert_allclose(rig.translation[1:], 0.0, atol=1e-15)
    assert rig.translation[0] == pytest.approx(-realistic_rig.baseline,
                                               rel=1e-12)
    np.testing.assert_array_equal(corrected.left.K, corrected.right.K)
    assert corrected.left.pinhole.model == "none"
    path = tmp_path / "corrected.yaml"
    corrected.write(path)
    back = rcm.read_stereo_rig(path)
    np.testing.assert_array_equal(back.cam1_from_cam0, rig.cam1_from_cam0)
    assert back.cam0.lens == corrected.left.pinhole


# The lens models added with issue 21: each round-trips over its image
# and names itself; out-of-range coefficients raise one line.
@pytest.mark.parametrize("model, distortion", [
    ("rational", [0.5, 0.1, 9.0e-4, -6.0e-4, 0.001, 0.75, 0.2, 0.001]),
    ("ds", [-0.18, 0.59]),
    ("eucm", [0.63, 1.04]),
])
def test_new_lens_models_round_trip(model, distortion):
    lens = rcm.Camera(model, 640, 480, [300.0, 299.0, 319.5, 239.5],
                      distortion)
    assert lens.model == model
    assert lens.distortion.shape == (len(distortion),)
    pixels = image_grid(lens, 8.0)
    normalized = lens.normalized_from_image(pixels)
    assert np.isfinite(normalized).all()
    back = lens.image_from_normalized(normalized)
    assert np.max(np.abs(back - pixels)) < ROUND_TRIP_PX


def test_new_lens_models_refuse_bad_coefficients():
    with pytest.raises(ValueError) as error:
        rcm.Camera("ds", 640, 480, [300.0, 300.0, 320.0, 240.0], [1.5, 0.5])
    assert "ds xi = 1.5 is outside (-1, 1]" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.Camera("eucm", 640, 480, [300.0, 300.0, 320.0, 240.0], [0.5, 0.0])
    assert "eucm beta = 0" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.Camera("fov", 640, 480, [300.0, 300.0, 320.0, 240.0], [0.5])
    assert "rational, ds, eucm" in one_line(error)
