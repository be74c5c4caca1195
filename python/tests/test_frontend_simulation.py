"""The simulator (images, matches, truth) and the image front end on its
images. Mirrors tests/sim/sequence_simulator_test.cc and
tests/frontend/stereo_front_end_test.cc."""
import numpy as np
import pytest

import rcm
from conftest import one_line


@pytest.fixture(scope="module")
def rendered(realistic_rig):
    """Two rendered water frames (supersampling 1 to keep the test fast)."""
    simulator = rcm.SequenceSimulator(realistic_rig, n=1.333, frames=2,
                                      matches_per_frame=200, supersampling=1,
                                      seed=3)
    return simulator, [simulator.frame(i) for i in range(len(simulator))]


def test_simulated_frames_carry_images_matches_and_truth(rendered,
                                                         realistic_rig):
    simulator, frames = rendered
    assert len(simulator) == 2 and simulator.n_of_frame == [1.333, 1.333]
    for index, frame in enumerate(frames):
        assert frame["index"] == index and frame["n_true"] == 1.333
        assert frame["left"].dtype == np.uint8
        assert frame["left"].shape == frame["right"].shape == (540, 720)
        assert len(frame["matches"]) == 200
        assert set(frame["matches"].frame) == {index}
        assert frame["world_from_cam0"].shape == (4, 4)
    # The simulator's matches are exact: the refinement recovers n.
    both = rcm.Correspondences(np.vstack([f["matches"].to_array()
                                          for f in frames]))
    result = rcm.refine_refractive_index(realistic_rig, both)
    assert abs(result.n - 1.333) < 1e-9


def test_simulation_is_deterministic(realistic_rig):
    kwargs = dict(n=1.2, frames=1, matches_per_frame=50, render_images=False,
                  seed=9)
    first = rcm.simulate(realistic_rig, **kwargs)[0]
    second = rcm.simulate(realistic_rig, **kwargs)[0]
    assert first["left"] is None
    np.testing.assert_array_equal(first["matches"].pixels,
                                  second["matches"].pixels)
    other = rcm.simulate(realistic_rig, **dict(kwargs, seed=10))[0]
    assert not np.array_equal(first["matches"].pixels, other["matches"].pixels)


def test_media_schedule_and_noise(realistic_rig):
    frames = rcm.simulate(realistic_rig, media=[(1.0, 2), (1.333, 2)],
                          matches_per_frame=100, render_images=False,
                          match_noise_px=0.5, outlier_fraction=0.1,
                          match_min_depth=0.6, match_max_depth=6.0, seed=4)
    assert [f["n_true"] for f in frames] == [1.0, 1.0, 1.333, 1.333]
    assert all(len(f["outlier_indices"]) == 10 for f in frames)


def test_bad_simulation_options(realistic_rig):
    with pytest.raises(TypeError) as error:
        rcm.SequenceSimulator(realistic_rig, n_frames=3)
    assert "n_frames" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.SequenceSimulator(realistic_rig, n=2.5)
    one_line(error)
    with pytest.raises(ValueError) as error:
        # Points at sampled depths are not in the images.
        rcm.SequenceSimulator(realistic_rig, match_min_depth=1.0,
                              match_max_depth=2.0, matches_per_frame=10)
    one_line(error)
    simulator = rcm.SequenceSimulator(realistic_rig, frames=1,
                                      render_images=False)
    with pytest.raises(IndexError):
        simulator.frame(1)


def test_front_end_matches_give_n(rendered, realistic_rig):
    _, frames = rendered
    front_end = rcm.StereoFrontEnd(realistic_rig)
    matches = []
    for frame in frames:
        result = front_end.match(frame["left"], frame["right"],
                                 frame=frame["index"])
        assert len(result) > 300, result
        assert result.pixels.shape == (len(result), 4)
        assert result.band == (1.0, 1.6)
        matches.append(result.matches.to_array())
    # The front end's systematic floor, as rcm estimate gives it
    # (kFrontEndSystematicPx = 0.03 px): sigma_n is then honest, and the
    # truth lies within 4 sigma_n.
    estimate = rcm.refine_refractive_index(
        realistic_rig, np.vstack(matches), systematic_px=0.03)
    assert abs(estimate.n - 1.333) < 4.0 * estimate.sigma_n
    # Subpixel matching on the renders: residuals well below a pixel.
    assert estimate.sigma_px < 0.2


def test_front_end_accepts_color_and_strided_images(rendered, realistic_rig):
    _, frames = rendered
    left, right = frames[0]["left"], frames[0]["right"]
    gray = rcm.match_stereo(realistic_rig, left, right, max_features=500)
    color = rcm.match_stereo(realistic_rig, np.dstack([left] * 3),
                             np.dstack([right] * 3), max_features=500)
    np.testing.assert_array_equal(gray.pixels, color.pixels)
    # A non-contiguous view of the same pixels gives the same matches.
    padded = np.zeros((540, 1440), np.uint8)
    padded[:, ::2] = left
    strided = rcm.match_stereo(realistic_rig, padded[:, ::2], right,
                               max_features=500)
    np.testing.assert_array_equal(strided.pixels, gray.pixels)


def test_front_end_bad_images_and_options(rendered, realistic_rig):
    _, frames = rendered
    left, right = frames[0]["left"], frames[0]["right"]
    cases = [
        ((left.astype(np.float32), right), ValueError, "uint8"),
        ((left, right.astype(np.uint16)), ValueError, "uint8"),
        ((left[:100], right[:100]), ValueError, "540"),
        ((left[:, :, None, None], right), ValueError, "shape"),
        ((left.tolist(), right), TypeError, "NumPy"),
        ((np.zeros((0, 720), np.uint8), right), ValueError, "empty"),
    ]
    for images, error_type, text in cases:
        with pytest.raises(error_type) as error:
            rcm.match_stereo(realistic_rig, *images)
        assert text in one_line(error), (text, str(error.value))
    with pytest.raises(TypeError) as error:
        rcm.StereoFrontEnd(realistic_rig, max_feature=10)
    assert "max_feature" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.StereoFrontEnd(realistic_rig, features="surf")
    assert "surf" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.StereoFrontEnd(realistic_rig, search_range=(1.5, 1.2))
    one_line(error)


def test_rig_presets_by_name():
    frames = rcm.simulate("alphasense-rectified", frames=2,
                          matches_per_frame=100, render_images=False, seed=2)
    assert [len(f["matches"]) for f in frames] == [100, 100]
    result = rcm.refine_refractive_index(
        rcm.reference_rig("alphasense-rectified"),
        rcm.Correspondences(np.vstack([f["matches"].to_array()
                                       for f in frames])))
    assert abs(result.n - 1.333) < 1e-9
    with pytest.raises(ValueError) as error:
        rcm.simulate("alphasense", frames=1)
    assert "alphasense-rectified" in one_line(error)
    with pytest.raises(TypeError) as error:
        rcm.SequenceSimulator(3)
    one_line(error)
