#!/usr/bin/python3
"""Speed of rcm.refine_refractive_index called from Python versus the same
C++ call (rcm::RefineRefractiveIndex) on the same data.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/python/refine_benchmark.py \
        [--timing build/bin/rcm_refine_timing] [--matches 100000] [--repeats 5]

Writes a rig (the dataset's unrectified reference rig) and a CSV of noisy
simulated matches (0.5 px, 10 frames) into a temporary folder; the C++
program rcm_refine_timing (benchmarks/python/refine_timing.cc, built with the
Python package) reads both and times the refinement alone; this script times
the Python call on the same file's contents, given as an (N, 5) NumPy array
(converted in C++ on every call, so the conversion is timed) and as an
rcm.Correspondences (no conversion). Prints the medians and the ratios; the
goal is Python within 1.1x of C++. Not a test: the machine's load moves the
figures.
"""
import argparse
import json
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import rcm


def find_timing_program(given):
    candidates = [given, os.environ.get("RCM_REFINE_TIMING"),
                  shutil.which("rcm_refine_timing")]
    here = pathlib.Path(__file__).resolve().parents[2]
    candidates += [str(here / d / "bin" / "rcm_refine_timing")
                   for d in ("build", "build-py")]
    for candidate in candidates:
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    sys.exit("rcm_refine_timing not found: build the Python package "
             "(it builds build/bin/rcm_refine_timing) or pass --timing")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timing", help="path of rcm_refine_timing")
    parser.add_argument("--matches", type=int, default=100_000)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    timing = find_timing_program(args.timing)

    with tempfile.TemporaryDirectory(prefix="rcm_bench_") as folder:
        folder = pathlib.Path(folder)
        rig = rcm.reference_rig("alphasense-unrectified")
        rig_path = folder / "rig.yaml"
        rig.write(rig_path)
        frames = 10
        exact = rcm.sample_correspondences(
            rig, n=1.333, num_frames=frames, per_frame=args.matches // frames,
            seed=7)
        csv_path = folder / "matches.csv"
        rcm.write_correspondences(csv_path, rcm.add_pixel_noise(exact, 0.5,
                                                                seed=8))

        # Both sides use what the files say: the rig as read (with its
        # default drift prior) and the matches as parsed.
        file_rig = rcm.read_stereo_rig(rig_path)
        held = rcm.read_correspondences(csv_path)
        array = held.to_array()

        cpp_seconds = []
        array_seconds = []
        held_seconds = []
        for _ in range(args.repeats):
            # Interleaved, so that a change of the machine's load hits both.
            completed = subprocess.run(
                [timing, str(rig_path), str(csv_path), "1"], check=True,
                capture_output=True, text=True)
            cpp = json.loads(completed.stdout)
            cpp_seconds += cpp["seconds"]
            start = time.perf_counter()
            from_array = rcm.refine_refractive_index(file_rig, array)
            array_seconds.append(time.perf_counter() - start)
            start = time.perf_counter()
            from_held = rcm.refine_refractive_index(file_rig, held)
            held_seconds.append(time.perf_counter() - start)

        print(f"{len(held)} matches in {frames} frames, {args.repeats} "
              "interleaved repeats; min and median wall time (the minimum is "
              "the least disturbed by other load on the machine)")
        cpp_min = min(cpp_seconds)
        cpp_median = statistics.median(cpp_seconds)
        print(f"  {'C++ RefineRefractiveIndex':28s} min {1e3 * cpp_min:8.1f} ms"
              f"  median {1e3 * cpp_median:8.1f} ms  n = {cpp['n']!r}")
        for label, seconds, result in (
                ("Python, (N, 5) array", array_seconds, from_array),
                ("Python, Correspondences", held_seconds, from_held)):
            low = min(seconds)
            median = statistics.median(seconds)
            print(f"  {label:28s} min {1e3 * low:8.1f} ms  median "
                  f"{1e3 * median:8.1f} ms  n = {result.n!r}  ratio "
                  f"{low / cpp_min:.3f} (min) {median / cpp_median:.3f} "
                  "(median)")
        print(f"  |n_python - n_cpp| = {abs(from_array.n - cpp['n']):.3g}")
        start = time.perf_counter()
        rcm.Correspondences(array)
        print(f"  conversion of the (N, 5) array alone: "
              f"{1e3 * (time.perf_counter() - start):.2f} ms")


if __name__ == "__main__":
    main()
