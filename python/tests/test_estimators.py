"""The estimators: exact recovery, noise within derived bounds, outliers, the
closed form, online and sliding-window estimation, options and bad input.
Mirrors tests/estimation/*_test.cc."""
import numpy as np
import pytest

import rcm
from conftest import one_line, thick_port

# As batch_refinement_test.cc: exact matches have residuals below 1e-12 px
# and the solver's tolerances carry that to n.
EXACT = 1e-9


def sample(rig, n, frames=2, per_frame=150, seed=3, **kwargs):
    return rcm.sample_correspondences(rig, n=n, num_frames=frames,
                                      per_frame=per_frame, seed=seed, **kwargs)


def ideal_rig_of(lens):
    """Two copies of a lens on the ideal rectified extrinsics, 0.11 m."""
    pose = np.eye(4)
    pose[0, 3] = -0.11
    return rcm.StereoRig(lens, lens, pose)


# batch_refinement_test.cc's rigs: the dataset's (rectified and not), a
# strongly distorted radtan lens (EuRoC cam0) and a pinhole.
RIGS = {
    "alphasense-rectified": lambda: rcm.reference_rig("alphasense-rectified"),
    "alphasense-unrectified":
        lambda: rcm.reference_rig("alphasense-unrectified"),
    "euroc-radtan": lambda: ideal_rig_of(rcm.Camera(
        "radtan", 752, 480, [458.654, 457.296, 367.215, 248.375],
        [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05])),
    "pinhole": lambda: ideal_rig_of(
        rcm.Camera("none", 640, 480, [400.0, 400.0, 319.5, 239.5])),
}


@pytest.mark.parametrize("rig_name", sorted(RIGS))
@pytest.mark.parametrize("n", [1.0, 1.2, 1.333, 1.6])
def test_exact_on_every_rig_and_index(rig_name, n):
    rig = RIGS[rig_name]()
    matches = sample(rig, n)
    result = rcm.refine_refractive_index(rig, matches)
    assert abs(result.n - n) < EXACT
    assert result.inliers.dtype == np.bool_ and result.inliers.all()
    assert result.num_inliers == result.num_correspondences == 300
    assert result.sigma_px < 1e-9
    assert result.calibration is None  # a rig made in code is exact


def test_exact_from_points_projected_through_the_bound_cameras(realistic_rig):
    # Matches made without the simulator: scene points in cam0 projected
    # by the bindings' cameras, cam1's through cam1_from_cam0.
    n = 1.34
    rng = np.random.default_rng(11)
    pixels = rng.uniform([20, 20], [700, 520], size=(600, 2))
    origins, directions = realistic_rig.cam0.pixel_to_ray(pixels, n)
    depth = rng.uniform(0.6, 6.0, size=(600, 1))
    points0 = origins + directions * (depth / directions[:, 2:3])
    pose = realistic_rig.cam1_from_cam0
    points1 = points0 @ pose[:3, :3].T + pose[:3, 3]
    right = realistic_rig.cam1.point_to_pixel(points1, n)
    keep = realistic_rig.cam1.lens.in_image(np.nan_to_num(right, nan=-9))
    matches = np.hstack([pixels, right])[keep]
    assert len(matches) > 300
    result = rcm.refine_refractive_index(realistic_rig, matches)
    assert abs(result.n - n) < EXACT


def test_exact_with_a_thick_port(thick_rig):
    # thick_port_refinement_test.cc: exact for every gap and glass.
    n = 1.335
    matches = sample(thick_rig, n)  # through the exact ports
    result = rcm.refine_refractive_index(thick_rig, matches)
    assert abs(result.n - n) < EXACT
    # The thin-port model on the same matches is biased (docs/thick_ports.md:
    # -0.019).
    thin = rcm.refine_refractive_index(
        rcm.reference_rig("alphasense-unrectified"), matches)
    assert thin.n < n - 0.005


def test_noise_within_four_crlb(realistic_rig):
    # 3000 matches at 0.5 px: the estimate's error is N(0, crlb^2) to first
    # order (the stage-2 least squares is efficient), so |error| < 4 crlb
    # fails for 1 draw in 16000. The fixed seed makes it deterministic.
    n = 1.333
    exact = sample(realistic_rig, n, frames=10, per_frame=300, seed=21)
    noisy = rcm.add_pixel_noise(exact, 0.5, seed=22)
    result = rcm.refine_refractive_index(realistic_rig, noisy)
    assert abs(result.n - n) < 4.0 * result.crlb
    # n alone with the calibration exact: sigma_n is the bound.
    assert result.sigma_n == pytest.approx(result.crlb, rel=1e-6)
    # The pixel noise is estimated from ~3000 residuals: within 5 %.
    assert result.sigma_px == pytest.approx(0.5, rel=0.05)
    assert "RefinementResult(n=1.33" in repr(result)


def test_outliers_are_not_inliers(realistic_rig):
    n = 1.333
    exact = sample(realistic_rig, n, frames=4, per_frame=250, seed=5)
    noisy = rcm.add_pixel_noise(exact, 0.3, seed=6)
    corrupted, replaced = rcm.add_outliers(realistic_rig, noisy, 0.2, seed=7)
    assert len(replaced) == 200
    result = rcm.refine_refractive_index(realistic_rig, corrupted)
    assert abs(result.n - n) < 4.0 * result.crlb
    # A replaced right pixel lands within 2 px of its locus rarely.
    assert result.inliers[replaced].mean() < 0.05
    assert result.inliers.sum() >= 780
    np.testing.assert_array_equal(np.flatnonzero(result.inliers),
                                  result.inlier_indices)


def test_closed_form_exact_on_the_ideal_rig(ideal_rig):
    matches = sample(ideal_rig, 1.333, frames=1, per_frame=400, seed=2)
    result = rcm.closed_form_refractive_index(ideal_rig, matches)
    assert abs(result.n - 1.333) < EXACT
    assert result.used + result.masked + result.invalid == 400
    assert result.masked > 0
    per_match = rcm.closed_form_n(ideal_rig, matches)
    assert per_match.shape == (400,)
    finite = np.isfinite(per_match)
    np.testing.assert_allclose(per_match[finite], 1.333, atol=1e-6)
    with pytest.raises(ValueError) as error:
        rcm.closed_form_refractive_index(ideal_rig, matches, mask_eta=-1.0)
    one_line(error)


def test_online_matches_the_batch(realistic_rig):
    n = 1.333
    exact = sample(realistic_rig, n, frames=6, per_frame=200, seed=8)
    noisy = rcm.add_pixel_noise(exact, 0.5, seed=9)
    online = rcm.OnlineEstimator(realistic_rig)
    with pytest.raises(ValueError) as error:
        online.current()
    one_line(error)
    for frame in noisy.split_frames():
        estimate = online.add_frame(frame)
    assert estimate is not None and estimate.frames == 6
    assert online.last_update.frame_estimate is not None
    batch = rcm.refine_refractive_index(realistic_rig, noisy)
    # online_estimator_test.cc: equal inlier sets give the batch's n to the
    # batch solver's tolerance (tested to 1e-6 there).
    assert estimate.n == pytest.approx(batch.n, abs=1e-6)
    assert online.current().n == estimate.n
    # Exact frames: exact n.
    exact_online = rcm.OnlineEstimator(realistic_rig)
    for frame in exact.split_frames():
        exact_online.add_frame(frame)
    assert abs(exact_online.current().n - n) < EXACT


def test_online_refuses_rotation_and_thick_ports(realistic_rig, thick_rig):
    with pytest.raises(ValueError) as error:
        rcm.OnlineEstimator(realistic_rig, refine_rotation=True)
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.OnlineEstimator(thick_rig)
    one_line(error)


def test_sliding_window_detects_air_to_water(realistic_rig):
    # sliding_window_estimator_test.cc, shortened: air then water, 200
    # matches per frame at 0.5 px; z ~ 35 at the step, so the switch is
    # declared at the confirm_frames-th water frame.
    window = rcm.SlidingWindowEstimator(realistic_rig, window_frames=10)
    truth = [1.0] * 8 + [1.333] * 8
    for frame, n in enumerate(truth):
        exact = rcm.sample_correspondences(
            realistic_rig, n=n, per_frame=200, seed=100 + frame,
            min_depth=0.5, max_depth=3.0)
        estimate = window.add_frame(rcm.add_pixel_noise(exact, 0.5,
                                                        seed=200 + frame))
    assert len(window.switches) == 1
    switch = window.switches[0]
    assert switch.first_frame == 8
    assert 8 <= switch.detected_at_frame <= 9
    assert switch.n_before == pytest.approx(1.0, abs=0.01)
    assert estimate is not None
    # 6 water frames of 200 matches at 0.5 px: sigma ~ 0.004.
    assert abs(estimate.n - 1.333) < 4 * estimate.sigma_n
    assert window.last_update.decision == "accepted"


def test_option_keywords():
    defaults = rcm.default_refinement_options()
    assert defaults == {
        "loss": "cauchy", "loss_scale_px": 1.0, "inlier_threshold_px": 2.0,
        "num_scan_points": 51, "min_inliers": 10, "max_crlb_per_px": 0.1,
        "refine_rotation": False, "self_calibrate_rotation": True,
        "self_calibrate_focal": True, "systematic_px": 0.0,
        "detect_systematic": False, "max_num_iterations": 100, "num_threads": 2,
        "n_prior": None, "rows_at_rotation": None}


def test_n_prior_of_the_medium(realistic_rig):
    # Exact matches at the medium's own n: the prior costs nothing at the
    # truth, so n and cam1's (zero) rotation stay exact (EXACT), and the
    # medium's share of sigma_n is reported.
    matches = sample(realistic_rig, 1.3415, frames=2, per_frame=200)
    for prior in ["1.3415:0.003", (1.3415, 0.003)]:
        result = rcm.refine_refractive_index(realistic_rig, matches,
                                             n_prior=prior,
                                             refine_rotation=True)
        assert abs(result.n - 1.3415) < EXACT
        assert np.abs(result.rotation["angle_axis"]).max() < EXACT
        assert result.calibration["variance_medium"] >= 0.0
    sea = rcm.refine_refractive_index(realistic_rig, matches, n_prior="sea")
    assert abs(sea.n - 1.3415) < 1e-6


def test_focal_scales_self_calibrated(realistic_rig):
    # Exact matches of the calibrated lenses on a rig with a focal drift
    # prior (0.3 %): both focal scales come back zero (EXACT) with a sigma
    # below the prior's, and are not estimated when switched off.
    rig = realistic_rig.with_drift_prior(1e-3, 1e-4, focal_sigma=0.003)
    matches = sample(realistic_rig, 1.333, frames=2, per_frame=200)
    result = rcm.refine_refractive_index(rig, matches)
    assert abs(result.n - 1.333) < EXACT
    assert result.focal["scale"].shape == (2,)
    assert np.abs(result.focal["scale"]).max() < EXACT
    assert (result.focal["sigma"] > 0.0).all()
    assert (result.focal["sigma"] <= 0.003).all()
    held = rcm.refine_refractive_index(rig, matches,
                                       self_calibrate_focal=False)
    assert held.focal is None


def test_online_self_calibrates_the_focal_scales(realistic_rig):
    # The online estimator estimates the focal scales with n and cam1's
    # rotation on the frames' quadratic models: exact frames of the
    # calibrated lenses give zero scales (EXACT); without a focal drift
    # prior there are none.
    rig = realistic_rig.with_drift_prior(1e-3, 1e-4, focal_sigma=0.003)
    exact = sample(realistic_rig, 1.333, frames=3, per_frame=200, seed=8)
    online = rcm.OnlineEstimator(rig)
    for frame in exact.split_frames():
        estimate = online.add_frame(frame)
    assert abs(estimate.n - 1.333) < EXACT
    assert estimate.focal_scale.shape == (2,)
    assert np.abs(estimate.focal_scale).max() < EXACT
    no_prior = rcm.OnlineEstimator(realistic_rig.with_drift_prior(1e-3, 1e-4))
    for frame in exact.split_frames():
        estimate = no_prior.add_frame(frame)
    assert estimate.focal_scale is None


def test_options_change_the_estimate(realistic_rig):
    exact = sample(realistic_rig, 1.333, frames=2, per_frame=200, seed=4)
    noisy = rcm.add_pixel_noise(exact, 0.5, seed=3)
    default = rcm.refine_refractive_index(realistic_rig, noisy)
    huber = rcm.refine_refractive_index(realistic_rig, noisy, loss="huber",
                                        inlier_threshold_px=0.5)
    assert huber.num_inliers < default.num_inliers
    everything = rcm.refine_refractive_index(realistic_rig, noisy,
                                             inlier_threshold_px=np.inf)
    assert everything.num_inliers == 400


@pytest.mark.parametrize("kwargs, error_type, text", [
    ({"loss_scale": 1.0}, TypeError, "loss_scale"),
    ({"loss": "tukey"}, ValueError, "tukey"),
    ({"loss": 3}, TypeError, "loss"),
    ({"loss_scale_px": -1.0}, ValueError, "loss"),
    ({"loss_scale_px": float("nan")}, ValueError, "loss_scale_px"),
    ({"min_inliers": 2.5}, TypeError, "min_inliers"),
    ({"min_inliers": 1}, ValueError, "min_inliers"),
    ({"refine_rotation": 1}, TypeError, "refine_rotation"),
    ({"num_threads": 0}, ValueError, "thread"),
    ({"n_prior": "salty"}, ValueError, "expected fresh, sea or N:SIGMA"),
    ({"n_prior": (1.34,)}, TypeError, "n_prior"),
    ({"n_prior": ("a", 0.1)}, TypeError, "n_prior"),
    ({"n_prior": (1.34, 0.0)}, ValueError, "prior on n"),
])
def test_bad_options(realistic_rig, kwargs, error_type, text):
    matches = sample(realistic_rig, 1.333, frames=1, per_frame=50)
    with pytest.raises(error_type) as error:
        rcm.refine_refractive_index(realistic_rig, matches, **kwargs)
    assert text in one_line(error)


def test_every_matches_form_gives_the_same_n(realistic_rig, tmp_path):
    matches = rcm.add_pixel_noise(
        sample(realistic_rig, 1.333, frames=2, per_frame=100), 0.3, seed=1)
    reference = rcm.refine_refractive_index(realistic_rig, matches).n
    as_dict = matches.to_dict()
    as_array5 = matches.to_array()
    forms = [
        as_dict,
        {k: as_dict[k] for k in ("frame", "xl", "yl", "xr", "yr")},
        as_array5,
        rcm.Correspondences(as_array5),
        np.asfortranarray(as_array5),              # non-contiguous rows
        np.repeat(as_array5, 2, axis=0)[::2],      # strided
        as_array5.tolist(),
    ]
    for form in forms:
        assert rcm.refine_refractive_index(realistic_rig, form).n == reference
    path = tmp_path / "m.csv"
    rcm.write_correspondences(path, matches)
    back = rcm.read_correspondences(path)
    np.testing.assert_array_equal(back.to_array(), as_array5)
    np.testing.assert_array_equal(back.t, matches.t)
    assert rcm.refine_refractive_index(realistic_rig, back).n == reference
    # (N, 4) puts everything in frame 0: another consistency test, but the
    # same matches.
    single = rcm.refine_refractive_index(realistic_rig, matches.pixels)
    assert single.n == pytest.approx(reference, abs=1e-3)
    # float32 coordinates are converted (rounded to float32 first).
    as32 = rcm.refine_refractive_index(realistic_rig,
                                       matches.pixels.astype(np.float32))
    assert as32.n == pytest.approx(reference, abs=1e-3)


def test_bad_matches(realistic_rig):
    good = sample(realistic_rig, 1.333, frames=1, per_frame=50).pixels
    cases = [
        (good[:, :3], ValueError, "(N, 4)"),
        (good[:, 0], ValueError, "(N, 4)"),
        (np.zeros((0, 4)), ValueError, "empty"),
        (np.where(np.arange(50)[:, None] == 7, np.nan, good), ValueError,
         "non-finite"),
        (np.where(np.arange(50)[:, None] == 3, np.inf, good), ValueError,
         "non-finite"),
        (good.astype(np.complex128), TypeError, "real numbers"),
        (good > 100, TypeError, "real numbers"),
        ("matches.csv", TypeError, "real numbers"),
        ({"xl": good[:, 0]}, ValueError, "yl"),
        (np.hstack([[[1.5]] * 50, good]), ValueError, "integer"),
        (np.hstack([np.arange(50)[::-1, None], good]), ValueError, "decrease"),
    ]
    for matches, error_type, text in cases:
        with pytest.raises(error_type) as error:
            rcm.refine_refractive_index(realistic_rig, matches)
        assert text in one_line(error), (text, str(error.value))


def test_too_few_matches_and_unobservable_data(realistic_rig):
    few = sample(realistic_rig, 1.333, frames=1, per_frame=5)
    with pytest.raises(ValueError) as error:
        rcm.refine_refractive_index(realistic_rig, few)
    one_line(error)
    # On the image axes the loci do not depend on n (refused, not a number).
    rig = rcm.reference_rig("alphasense-rectified")
    cx, cy = rig.cam0.cx, rig.cam0.cy
    axis = np.array([[cx + dx, cy, cx + dx - 30.0, cy] for dx in
                     np.linspace(-200, 200, 40)])
    with pytest.raises(ValueError) as error:
        rcm.refine_refractive_index(rig, axis)
    one_line(error)


def test_water_refractive_index_and_medium_prior():
    # Pure water at 20 C and the sodium line: 1.33299 (CRC Handbook), as
    # medium_prior_test.cc.
    assert abs(rcm.water_refractive_index(0.0, 20.0, 589.3) - 1.33299) < 1e-4
    with pytest.raises(ValueError) as error:
        rcm.water_refractive_index(40.0, 20.0, 589.3)
    assert "0-35 g/kg" in one_line(error)
    sea = rcm.medium_prior("sea")
    assert sea["name"] == "sea water"
    assert sea["range"][0] < sea["n"] < sea["range"][1]
    assert abs(sea["sigma"] - (sea["range"][1] - sea["range"][0]) / 12 ** 0.5) < 1e-15
    assert rcm.medium_prior("1.338:0.002")["n"] == 1.338
    with pytest.raises(ValueError) as error:
        rcm.medium_prior("brine")
    assert "expected fresh, sea or N:SIGMA" in one_line(error)



def test_a_field_off_the_rigid_scene_widens_sigma(realistic_rig):
    # The right pixels of the top third moved down by 0.5 px in every
    # frame (a surface's mirror image): the residuals' test finds the field
    # (p < 1 %) and sigma_n grows by its share; with detect_systematic=False
    # the same matches give the pixel noise's sigma alone. Clean matches
    # show no field (the test's false alarm rate is 1 %; this seed passes).
    n = 1.333
    exact = sample(realistic_rig, n, frames=10, per_frame=300, seed=21)
    noisy = rcm.add_pixel_noise(exact, 0.3, seed=22)
    clean = rcm.refine_refractive_index(realistic_rig, noisy,
                                        detect_systematic=True)
    assert clean.calibration is None or \
        clean.calibration["systematic_detected_px"] == 0.0
    moved = noisy.to_array()  # (N, 5): frame, xl, yl, xr, yr
    top = moved[:, 2] < 540 / 3.0
    moved[top, 4] += 0.5
    found = rcm.refine_refractive_index(realistic_rig, moved,
                                        detect_systematic=True)
    blind = rcm.refine_refractive_index(realistic_rig, moved)
    assert found.calibration["systematic_p_value"] < 0.01
    assert found.calibration["systematic_detected_px"] > 0.05
    assert found.sigma_n_systematic > 3.0 * blind.sigma_n
    assert abs(found.n - n) < 3.0 * found.sigma_n


def test_refinement_options_class(ideal_rig):
    # rcm.RefinementOptions: the C++ struct with its defaults, its fields
    # as properties, accepted as options= by every estimator.
    options = rcm.RefinementOptions(loss="huber", inlier_threshold_px=1.5)
    assert options.loss == "huber" and options.inlier_threshold_px == 1.5
    options.min_inliers = 12
    assert options.to_dict() == dict(rcm.default_refinement_options(),
                                     loss="huber", inlier_threshold_px=1.5,
                                     min_inliers=12)
    assert "pixels" in rcm.RefinementOptions.loss_scale_px.__doc__
    matches = rcm.add_pixel_noise(sample(ideal_rig, 1.34), 0.3, seed=8)
    by_object = rcm.refine_refractive_index(ideal_rig, matches,
                                            options=options)
    by_keywords = rcm.refine_refractive_index(
        ideal_rig, matches, loss="huber", inlier_threshold_px=1.5,
        min_inliers=12)
    assert by_object.n == by_keywords.n
    # A keyword beside options= overrides its field.
    assert rcm.refine_refractive_index(
        ideal_rig, matches, options=options, loss="cauchy").n == \
        rcm.refine_refractive_index(ideal_rig, matches,
                                    inlier_threshold_px=1.5,
                                    min_inliers=12).n
    assert set(by_object.to_dict()) >= {"n", "sigma_n", "calibration"}
    # Where the rows are taken: None (the default) or 3 numbers.
    assert rcm.RefinementOptions().rows_at_rotation is None
    options.rows_at_rotation = [0.0, 1e-3, 0.0]
    assert options.rows_at_rotation == (0.0, 1e-3, 0.0)
    with pytest.raises(TypeError) as error:
        rcm.RefinementOptions(rows_at_rotation=(1.0, 2.0))
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.RefinementOptions(rows_at_rotation=(0.0, float("nan"), 0.0)).check()
    one_line(error)
    with pytest.raises(TypeError) as error:
        rcm.RefinementOptions(no_such_option=1)
    one_line(error)
    bad = rcm.RefinementOptions(loss_scale_px=-1.0)
    with pytest.raises(ValueError) as error:
        bad.check()
    one_line(error)
    with pytest.raises(ValueError):
        rcm.refine_refractive_index(ideal_rig, matches, options=bad)
    with pytest.raises(TypeError):
        rcm.refine_refractive_index(ideal_rig, matches, options={"loss": 1})
