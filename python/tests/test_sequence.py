"""rcm.SequenceEstimator: the pair loop `rcm estimate` runs on images (and
`rcm demo` and the live node), the same engine from Python. On the same
pairs with the same options the two give the same n (1e-12) and the same
estimate JSON.
"""
import numpy as np
import pytest

import rcm
from conftest import one_line
from test_cpp_agreement import rcm_executable, same_value

cv2 = pytest.importorskip("cv2")

FRAMES = 4


@pytest.fixture(scope="module")
def rendered(tmp_path_factory, realistic_rig):
    """Four rendered water frames of the unrectified rig, written as the
    folders `rcm estimate --left --right` reads (PNG: lossless)."""
    folder = tmp_path_factory.mktemp("pairs")
    simulator = rcm.SequenceSimulator(realistic_rig, n=1.34, frames=FRAMES,
                                      matches_per_frame=10, supersampling=1,
                                      seed=5)
    frames = [simulator.frame(i) for i in range(FRAMES)]
    for side in ("left", "right"):
        (folder / side).mkdir()
        for i, frame in enumerate(frames):
            assert cv2.imwrite(str(folder / side / f"pair{i:02d}.png"),
                               frame[side])
    rig_path = folder / "rig.yaml"
    realistic_rig.write(rig_path)
    return folder, rig_path, frames


def run_cli_on_images(folder, rig_path, *flags):
    import json
    import subprocess
    completed = subprocess.run(
        [rcm_executable(), "estimate", "--calib", str(rig_path), "--left",
         str(folder / "left"), "--right", str(folder / "right"), "--json",
         *flags],
        capture_output=True, text=True, timeout=120, check=False)
    assert completed.returncode == 0, completed.stderr
    return json.loads(completed.stdout)


@pytest.mark.parametrize("estimator", ["refine", "window"])
def test_python_runs_what_the_cli_runs(rendered, estimator):
    folder, rig_path, frames = rendered
    cpp = run_cli_on_images(folder, rig_path, "--estimator", estimator,
                            "--window", "3")
    assert cpp["images"]["pairs"] == FRAMES
    assert cpp["images"]["rematched"] == 0  # one pass: the same pairs
    # The CLI's defaults: the rig read from its file (the default drift
    # prior), the residuals' field test on.
    sequence = rcm.SequenceEstimator(
        rcm.read_stereo_rig(rig_path), estimator=estimator, window_frames=3,
        refinement={"detect_systematic": True})
    for i, frame in enumerate(frames):
        pair = sequence.add_pair(frame["left"], frame["right"], i)
        assert pair.frame == i and len(pair.matches) > 100
    estimate = sequence.estimate()
    assert abs(estimate.n - cpp["n"]) <= 1e-12
    assert abs(estimate.n - 1.34) < 5 * estimate.sigma_n
    for key, value in estimate.to_dict().items():
        same_value(value, cpp[key], key)
    assert sequence.num_frames == FRAMES


def test_per_pair_results(rendered):
    _, _, frames = rendered
    sequence = rcm.SequenceEstimator("alphasense-unrectified",
                                     estimator="window", window_frames=3)
    pairs = [sequence.add_pair(f["left"], f["right"], i)
             for i, f in enumerate(frames)]
    # Each pair has its own estimate; the window's exists from the first.
    for pair in pairs:
        d = pair.to_dict()
        assert d["n"] == pytest.approx(1.34, abs=0.02)
        assert d["window_n"] is not None and not d["medium_switch"]
        assert d["num_estimated"] <= 200
    estimate = sequence.estimate()
    assert estimate.estimator == "window"
    assert estimate.per_frame["n"].shape == (FRAMES,)
    assert np.isfinite(estimate.per_frame["n"]).all()


def test_bad_input_is_one_line(rendered):
    _, _, frames = rendered
    with pytest.raises(ValueError) as error:
        rcm.SequenceEstimator("alphasense-unrectified", estimator="kalman")
    assert "unknown estimator" in one_line(error)
    # The bundle is the engine's too (docs/bundle.md).
    rcm.SequenceEstimator("alphasense-unrectified", estimator="bundle")
    with pytest.raises(TypeError) as error:
        rcm.SequenceEstimator("alphasense-unrectified",
                              refinement={"no_such_option": 1})
    one_line(error)
    sequence = rcm.SequenceEstimator("alphasense-unrectified")
    with pytest.raises(ValueError) as error:
        sequence.add_pair(frames[0]["left"][:100], frames[0]["right"], 0)
    one_line(error)
    with pytest.raises(ValueError) as error:
        sequence.estimate()  # no pair yet
    one_line(error)


def test_demo_runs_the_same_engine(tmp_path):
    # `rcm demo` renders its dive and runs the sequence engine on it; the
    # same renders (the simulator is deterministic) through
    # rcm.SequenceEstimator with the demo's options give the same n.
    import json
    import subprocess
    frames = 3
    completed = subprocess.run(
        [rcm_executable(), "demo", "--frames", str(frames), "--out",
         str(tmp_path / "demo"), "--json"],
        capture_output=True, text=True, timeout=300, check=False)
    assert completed.returncode == 0, completed.stderr
    demo = json.loads(completed.stdout)
    # The demo's rig as rcm reads a camchain without a sidecar (the default
    # drift prior), its simulation flags' defaults.
    rig_path = tmp_path / "rig.yaml"
    rcm.reference_rig("alphasense-rectified").write(rig_path)
    simulator = rcm.SequenceSimulator(
        rcm.reference_rig("alphasense-rectified"), n=1.333, frames=frames,
        supersampling=2, image_noise=1.5, frame_rate=20.0, seed=1)
    sequence = rcm.SequenceEstimator(rcm.read_stereo_rig(rig_path))
    for i in range(frames):
        frame = simulator.frame(i)
        sequence.add_pair(frame["left"], frame["right"], i, frame["t"])
    estimate = sequence.estimate()
    assert abs(estimate.n - demo["n"]) <= 1e-12
    assert abs(estimate.n - demo["estimate"]["n"]) <= 1e-12
    for key, value in estimate.to_dict().items():
        same_value(value, demo["estimate"][key], key)


def test_options_classes(rendered):
    # rcm.FrontEndOptions and rcm.RefinementOptions: the C++ structs with
    # their defaults; an object and the same keywords as a dict are one.
    _, _, frames = rendered
    front_end = rcm.FrontEndOptions(max_features=1500)
    assert front_end.max_features == 1500 and front_end.features == "orb"
    assert front_end.to_dict()["search_range"] == (1.0, 1.6)
    assert "band" in rcm.FrontEndOptions.tolerance_px.__doc__
    refinement = rcm.RefinementOptions(
        systematic_px=rcm.FRONT_END_SYSTEMATIC_PX)
    by_objects = rcm.SequenceEstimator("alphasense-unrectified",
                                       front_end=front_end,
                                       refinement=refinement)
    by_dicts = rcm.SequenceEstimator("alphasense-unrectified",
                                     front_end={"max_features": 1500})
    for i, frame in enumerate(frames[:2]):
        a = by_objects.add_pair(frame["left"], frame["right"], i)
        b = by_dicts.add_pair(frame["left"], frame["right"], i)
        assert len(a.matches) == len(b.matches) and a.n == b.n
    assert by_objects.estimate().n == by_dicts.estimate().n
    with pytest.raises(TypeError) as error:
        rcm.SequenceEstimator("alphasense-unrectified", front_end=3)
    one_line(error)
    bad = rcm.FrontEndOptions(ratio=2.0)
    with pytest.raises(ValueError) as error:
        bad.check()
    one_line(error)
