"""Correspondence files and the Correspondences container."""
import numpy as np
import pytest

import rcm
from conftest import one_line


def test_reads_the_demo_matches(demo_matches_path):
    matches = rcm.read_correspondences(demo_matches_path)
    assert len(matches) == 2000
    assert matches.frame_ids == list(range(10))
    data = matches.to_dict()
    assert set(data) == {"frame", "xl", "yl", "xr", "yr", "t"}
    assert data["frame"].dtype == np.int64 and data["xl"].dtype == np.float64
    # The first row of the file, bit for bit.
    assert data["xl"][0] == 97.65391817160673
    assert data["yr"][0] == 65.30464884384337
    assert matches.has_timestamps and data["t"][0] == 0.0
    assert [len(f) for f in matches.split_frames()] == [200] * 10


def test_select_and_round_trip(tmp_path):
    array = np.array([[0, 1.0, 2.0, 3.0, 4.0], [0, 5.0, 6.0, 7.0, 8.0],
                      [2, 9.0, 10.0, 11.0, 12.0]])
    matches = rcm.Correspondences(array)
    assert not matches.has_timestamps and matches.t is None
    np.testing.assert_array_equal(matches.select([0, 2]).to_array(),
                                  array[[0, 2]])
    np.testing.assert_array_equal(
        matches.select(np.array([False, True, True])).to_array(), array[1:])
    with pytest.raises(IndexError):
        matches.select([3])
    path = tmp_path / "m.csv"
    rcm.write_correspondences(path, matches)
    assert path.read_text().splitlines()[0] == "frame,xl,yl,xr,yr"
    np.testing.assert_array_equal(rcm.read_correspondences(path).to_array(),
                                  array)


def test_file_errors(tmp_path):
    with pytest.raises(FileNotFoundError) as error:
        rcm.read_correspondences(tmp_path / "none.csv")
    assert "none.csv" in one_line(error)
    bad = tmp_path / "bad.csv"
    bad.write_text("frame,xl,yl,xr\n0,1,2,3\n")
    with pytest.raises(ValueError) as error:
        rcm.read_correspondences(bad)
    assert "yr" in one_line(error)
    short = tmp_path / "short.csv"
    short.write_text("xl,yl,xr,yr\n1,2,3,4\n5,6,7\n")
    with pytest.raises(ValueError) as error:
        rcm.read_correspondences(short)
    assert "short.csv:3" in one_line(error)
    with pytest.raises(OSError) as error:
        rcm.write_correspondences(tmp_path / "no" / "dir" / "m.csv",
                                  np.ones((3, 4)))
    one_line(error)
    with pytest.raises(IsADirectoryError):
        rcm.read_correspondences(tmp_path)


def test_thin_port_only_estimators_refuse_a_thick_port(thick_rig):
    matches = rcm.sample_correspondences(thick_rig, n=1.333, per_frame=100)
    for call in (lambda: rcm.closed_form_refractive_index(thick_rig, matches),
                 lambda: rcm.SlidingWindowEstimator(thick_rig)):
        with pytest.raises(ValueError) as error:
            call()
        assert "thick port" in one_line(error)
