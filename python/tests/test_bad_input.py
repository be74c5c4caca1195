"""A table of bad input across the package: each call raises the stated
Python exception with a one-line message, never aborts the interpreter (a
library CHECK) or leaks a C++ cast error. Mirrors tests/cli/bad_input_table_test.cc."""
import numpy as np
import pytest

import rcm
from conftest import one_line

RIG = rcm.reference_rig("alphasense-unrectified")
TARGET = rcm.CalibrationTarget.checkerboard(9, 6, 0.04)
IMAGE = np.zeros((540, 720), np.uint8)

CASES = [
    ("camera zero width", lambda: rcm.Camera("none", 0, 10, [1, 1, 1, 1]),
     ValueError),
    ("camera nan focal", lambda: rcm.Camera("none", 10, 10, [np.nan, 1, 1, 1]),
     ValueError),
    ("camera 3 intrinsics", lambda: rcm.Camera("none", 10, 10, [1, 1, 1]),
     ValueError),
    ("not a rotation", lambda: rcm.StereoRig(RIG.cam0.lens, RIG.cam1.lens,
                                             np.ones((4, 4))), ValueError),
    ("rig is None", lambda: rcm.refine_refractive_index(None, np.ones((20, 4))),
     TypeError),
    ("rig is a path", lambda: rcm.OnlineEstimator("rig.yaml"), ValueError),
    ("path is an int", lambda: rcm.read_stereo_rig(123), TypeError),
    ("path with a comma", lambda: rcm.read_stereo_rig("a,b"), ValueError),
    ("negative drift prior", lambda: rcm.read_stereo_rig(
        "x.yaml", drift_prior=(-1.0, 0.0)), ValueError),
    ("empty output size", lambda: rcm.virtual_pinhole_maps(
        RIG, 1.33, output_size=(0, 0)), ValueError),
    ("zero threads", lambda: rcm.virtual_pinhole_maps(RIG, 1.33,
                                                      num_threads=0),
     ValueError),
    ("n outside [1, 2]", lambda: rcm.virtual_pinhole_maps(RIG, 3.0),
     ValueError),
    ("no matches per frame", lambda: rcm.sample_correspondences(
        RIG, per_frame=0), ValueError),
    ("negative seed", lambda: rcm.sample_correspondences(RIG, seed=-1),
     ValueError),
    ("zero frames", lambda: rcm.SequenceSimulator(RIG, frames=0), ValueError),
    ("port is an int", lambda: rcm.SequenceSimulator(RIG, port=3), TypeError),
    ("media frames a str", lambda: rcm.SequenceSimulator(
        RIG, media=[(1.3, "a")]), TypeError),
    ("supersampling 100", lambda: rcm.SequenceSimulator(
        RIG, supersampling=100, frames=1), ValueError),
    ("zero port normal", lambda: rcm.FlatPort(normal=(0, 0, 0)), ValueError),
    ("not a rigid pose", lambda: rcm.render_target(RIG.cam0.lens, TARGET,
                                                   2 * np.eye(4)), ValueError),
    ("render seed -1", lambda: rcm.render_target(RIG.cam0.lens, TARGET,
                                                 np.eye(4), seed=-1),
     ValueError),
    ("texture too large", lambda: rcm.render_target(
        RIG.cam0.lens, TARGET, np.eye(4), pixels_per_metre=1e7), ValueError),
    ("no views", lambda: rcm.calibrate_stereo_from_corners(
        TARGET, [], (720, 540), (720, 540)), ValueError),
    ("zero image size", lambda: rcm.calibrate_stereo_from_corners(
        TARGET, [(None, None)] * 3, (0, 0), (720, 540)), ValueError),
    ("nan corner", lambda: rcm.calibrate_stereo_from_corners(
        TARGET, [((np.array([0]), np.array([[np.nan, 1.0]])), None)] * 3,
        (720, 540), (720, 540)), ValueError),
    ("images not the air rig's", lambda: rcm.calibrate_underwater(
        TARGET, [IMAGE[:10, :10]] * 3, [IMAGE[:10, :10]] * 3, RIG, folds=0),
     ValueError),
    ("initial n 5", lambda: rcm.calibrate_underwater(
        TARGET, [IMAGE], [IMAGE], RIG, initial_n=5.0), ValueError),
    ("nan matches online", lambda: rcm.OnlineEstimator(RIG).add_frame(
        np.full((20, 4), np.nan)), ValueError),
    ("window of 0 frames", lambda: rcm.SlidingWindowEstimator(
        RIG, window_frames=0), ValueError),
    ("images of two sizes", lambda: rcm.match_stereo(RIG, IMAGE,
                                                     IMAGE[:, :700]),
     ValueError),
    ("images not the rig's size", lambda: rcm.match_stereo(
        RIG, IMAGE[:480, :640], IMAGE[:480, :640]), ValueError),
    ("guide outside [1, 2]", lambda: rcm.StereoFrontEnd(RIG).match(
        IMAGE, IMAGE, guide=(3.0, 4.0)), ValueError),
    ("negative frame", lambda: rcm.StereoFrontEnd(RIG).match(
        IMAGE, IMAGE, frame=-1), ValueError),
    ("negative noise", lambda: rcm.add_pixel_noise(np.ones((3, 4)), -1.0),
     ValueError),
    ("outlier fraction 1.5", lambda: rcm.add_outliers(RIG, np.ones((3, 4)),
                                                      1.5), ValueError),
    ("n nan", lambda: RIG.cam0.pixel_to_ray(np.ones((3, 2)), float("nan")),
     ValueError),
    ("drift overflows", lambda: RIG.with_cam1_moved([1e308, 0, 0]),
     ValueError),
    ("huge frame number", lambda: rcm.refine_refractive_index(
        RIG, np.array([[1e300, 1, 2, 3, 4]] * 20)), ValueError),
    ("checkerboard of 1e5", lambda: rcm.CalibrationTarget.checkerboard(
        100000, 6, 0.04), ValueError),
    ("target is a folder", lambda: rcm.read_calibration_target("/"),
     IsADirectoryError),
    ("image with 2 channels", lambda: rcm.virtual_pinhole_maps(
        RIG, 1.3).left.correct(np.zeros((540, 720, 2), np.uint8)),
     ValueError),
]


@pytest.mark.parametrize("name, call, error_type", CASES,
                         ids=[case[0] for case in CASES])
def test_bad_input_raises_one_line(name, call, error_type):
    with pytest.raises(error_type) as error:
        call()
    one_line(error)
