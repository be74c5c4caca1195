"""rcm.SequenceBundleAdjustment: n, cam1's turn and the trajectory from
tracked landmarks (C++ SequenceBundleAdjustment), and
rcm.compare_trajectories. Synthetic tracks made here with the cameras'
exact projection (point_to_pixel): the bundle recovers them to 1e-9, as
the C++ noise-free test asks.
"""
import numpy as np
import pytest

import rcm
from conftest import one_line

N_TRUE = 1.333
# Noise-free tracks: the least squares converge to rounding (the C++ test's
# 1e-9 on every unknown).
EXACT = 1e-9


def rotation(axis_angle):
    """Rodrigues: angle-axis (radians) -> 3x3."""
    w = np.asarray(axis_angle, dtype=float)
    angle = np.linalg.norm(w)
    if angle == 0.0:
        return np.eye(3)
    k = w / angle
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx


def quaternion(r):
    """3x3 rotation -> (qx, qy, qz, qw), for rotations under 180 degrees."""
    qw = 0.5 * np.sqrt(max(1.0 + np.trace(r), 0.0))
    return np.array([(r[2, 1] - r[1, 2]) / (4 * qw),
                     (r[0, 2] - r[2, 0]) / (4 * qw),
                     (r[1, 0] - r[0, 1]) / (4 * qw), qw])


def synthetic_dive(rig, turn, frames=8, landmarks=400, seed=3, moving=True):
    """Tracks of landmarks 3-8 m ahead seen by a rig that moves sideways and
    turns 1.5 degrees per keyframe (static when not moving), cam1 turned by
    `turn` since the calibration. Returns the (M, 5) observations and the
    true trajectory (N, 7)."""
    rng = np.random.default_rng(seed)
    points = np.column_stack([rng.uniform(-4, 4, landmarks),
                              rng.uniform(-3, 3, landmarks),
                              rng.uniform(3, 8, landmarks)])
    r10 = rotation(turn) @ rig.rotation
    t10 = rotation(turn) @ rig.translation
    width, height = rig.cam0.width, rig.cam0.height
    rows, truth = [], []
    for f in range(frames):
        step = f if moving else 0
        world_from_cam = (rotation([0, np.radians(1.5) * step, 0]),
                          np.array([0.08 * step, 0.01 * step, 0.02 * step]))
        r, t = world_from_cam
        truth.append(np.concatenate([t, quaternion(r)]))
        in_cam0 = (points - t) @ r  # R^T (X - t), row by row
        in_cam1 = in_cam0 @ r10.T + t10
        pixels = [rig.cam0.point_to_pixel(in_cam0, N_TRUE),
                  rig.cam1.point_to_pixel(in_cam1, N_TRUE)]
        seen = np.ones(landmarks, dtype=bool)
        for p in pixels:
            seen &= (np.isfinite(p).all(axis=1) & (p[:, 0] > 0) &
                     (p[:, 0] < width) & (p[:, 1] > 0) & (p[:, 1] < height))
        for camera, p in enumerate(pixels):
            for landmark in np.flatnonzero(seen):
                rows.append([f, camera, landmark, *p[landmark]])
    return np.array(rows), np.array(truth)


@pytest.fixture(scope="module")
def rig():
    return rcm.reference_rig("alphasense-rectified")


def test_noise_free_tracks_give_n_turn_and_trajectory_exactly(rig):
    turn = np.radians(0.5) * np.array([0.3, 1.0, 0.2]) / np.linalg.norm(
        [0.3, 1.0, 0.2])
    observations, truth = synthetic_dive(rig, turn)
    result = rcm.SequenceBundleAdjustment(rig).solve(observations)
    assert abs(result.n - N_TRUE) < EXACT
    assert np.abs(result.cam1_rotation - turn).max() < EXACT
    assert result.trajectory.shape == (8, 7)
    # Keyframe 0 is the world: the truth's own frame here too.
    assert np.abs(result.trajectory - truth).max() < EXACT
    error = rcm.compare_trajectories(result.trajectory, truth)
    assert error["ate_m"] < EXACT and error["end_drift_m"] < EXACT
    assert error["frames"] == 8
    assert result.motion_kind == "moving"
    assert result.landmarks.shape[1] == 3
    assert result.sigma_n > 0.0 and result.rotation_covariance.shape == (3, 3)
    # A rig made in code has no focal drift prior: the lenses are held.
    assert result.focal_scales is None and result.sigma_n_systematic == 0.0


def test_held_n_is_odometry(rig):
    observations, truth = synthetic_dive(rig, np.zeros(3))
    result = rcm.SequenceBundleAdjustment(
        rig, refine_n=False, initial_n=N_TRUE).solve(observations)
    assert result.n == N_TRUE and result.sigma_n == 0.0
    assert np.abs(result.trajectory - truth).max() < EXACT
    # Water ignored: the trajectory is off (depths shrink by ~n).
    ignored = rcm.SequenceBundleAdjustment(
        rig, refine_n=False, initial_n=1.0).solve(observations)
    assert rcm.compare_trajectories(ignored.trajectory, truth)["ate_m"] > 1e-3


def test_static_rig_refused_in_one_line(rig):
    observations, _ = synthetic_dive(rig, np.zeros(3), moving=False)
    with pytest.raises(ValueError) as error:
        rcm.SequenceBundleAdjustment(rig).solve(observations)
    assert "does not move" in one_line(error)


def test_options_and_bad_input(rig):
    options = rcm.SequenceBundleOptions(refine_n=False, initial_n=1.34)
    assert options.refine_n is False and options.initial_n == 1.34
    assert options.to_dict()["min_landmark_keyframes"] == 2
    assert options.to_dict()["self_calibrate_focal"] is True
    assert options.to_dict()["systematic_px"] == 0.0
    ba = rcm.SequenceBundleAdjustment(rig, options=options)
    assert ba.options.initial_n == 1.34
    with pytest.raises(TypeError) as error:
        rcm.SequenceBundleAdjustment(rig, refine_m=True)
    assert "refine_m" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.SequenceBundleAdjustment(rig, initial_n=3.0)
    assert "initial n" in one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.SequenceBundleOptions(max_iterations=0).check()
    one_line(error)
    solver = rcm.SequenceBundleAdjustment(rig)
    with pytest.raises(ValueError) as error:
        solver.solve(np.zeros((4, 4)))
    assert "(N, 5)" in one_line(error)
    with pytest.raises(ValueError) as error:
        solver.solve(np.array([[0, 0, 0.5, 10.0, 10.0]] * 4))
    assert "whole numbers" in one_line(error)
    with pytest.raises(ValueError) as error:
        solver.solve(np.array([[0, 2, 0, 10.0, 10.0], [1, 0, 0, 10.0, 10.0]]))
    one_line(error)
    with pytest.raises(ValueError) as error:
        solver.solve(np.array([[0, 0, 0, np.nan, 10.0]]))
    one_line(error)
    with pytest.raises(ValueError) as error:
        rcm.compare_trajectories(np.zeros((3, 7)), np.zeros((3, 7)))
    assert "norm 1" in one_line(error)
    poses = np.tile([0, 0, 0, 0, 0, 0, 1.0], (3, 1))
    with pytest.raises(ValueError) as error:
        rcm.compare_trajectories(poses, poses[:2])
    assert "3 poses" in one_line(error)
