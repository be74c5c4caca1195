"""Long calls release the GIL (other Python threads keep running), and the
stateful objects can be shared between threads."""
import threading
import time

import numpy as np

import rcm


def longest_stall(function):
    """Runs `function` in a thread; returns (its duration, the longest gap
    between two iterations of a busy loop in this thread meanwhile)."""
    done = threading.Event()
    result = {}

    def work():
        start = time.perf_counter()
        result["value"] = function()
        result["duration"] = time.perf_counter() - start
        done.set()

    worker = threading.Thread(target=work)
    worker.start()
    last = time.perf_counter()
    longest = 0.0
    while not done.is_set():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    worker.join()
    return result["duration"], longest


def test_refinement_releases_the_gil(realistic_rig):
    matches = rcm.add_pixel_noise(
        rcm.sample_correspondences(realistic_rig, n=1.333, num_frames=10,
                                   per_frame=2000, seed=1), 0.5, seed=2)
    duration, stall = longest_stall(
        lambda: rcm.refine_refractive_index(realistic_rig, matches))
    # Holding the GIL, the call would stall this thread for its whole
    # duration; released, only for Python's switch interval (5 ms) or so.
    assert duration > 0.1
    assert stall < 0.5 * duration, (stall, duration)


def test_online_estimator_shared_by_threads(realistic_rig):
    frames = rcm.sample_correspondences(realistic_rig, n=1.333, num_frames=8,
                                        per_frame=200, seed=4).split_frames()
    online = rcm.OnlineEstimator(realistic_rig)
    threads = [threading.Thread(target=lambda part=part: [
        online.add_frame(frame) for frame in part])
        for part in (frames[:4], frames[4:])]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    estimate = online.current()
    assert estimate.frames == 8 and online.num_frames == 8
    assert abs(estimate.n - 1.333) < 1e-9
