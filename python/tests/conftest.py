"""pytest configuration of the rcm Python tests.

The package is found on PYTHONPATH (PYTHONPATH=build/python). RCM_PYTHON_PATH,
when set, is put in front of sys.path instead (a build tree elsewhere).
"""
import os
import pathlib
import sys

if os.environ.get("RCM_PYTHON_PATH"):
    sys.path.insert(0, os.environ["RCM_PYTHON_PATH"])

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import rcm  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[2]
DATA = REPO / "examples" / "data"


@pytest.fixture(scope="session")
def demo_rig_path():
    return DATA / "alphasense_front_rectified.yaml"


@pytest.fixture(scope="session")
def demo_matches_path():
    return DATA / "demo_matches.csv"


@pytest.fixture(scope="session")
def ideal_rig():
    """The dataset's lenses on ideal rectified extrinsics, made in code (no
    calibration uncertainty)."""
    return rcm.reference_rig("alphasense-rectified")


@pytest.fixture(scope="session")
def realistic_rig():
    """cam1 turned 0.5 degrees, baseline off axis: not rectified."""
    return rcm.reference_rig("alphasense-unrectified")


def thick_port():
    """8 mm of air behind 6 mm of acrylic (the thick port of
    docs/thick_ports.md)."""
    return rcm.FlatPort(air_gap=0.008, glass_thickness=0.006, glass_index=1.49)


@pytest.fixture(scope="session")
def thick_rig(realistic_rig):
    port = thick_port()
    return realistic_rig.with_ports(port, port)


def one_line(error):
    """The exception's message, asserted to be one non-empty line."""
    message = str(error.value)
    assert message, "empty message"
    assert "\n" not in message, repr(message)
    return message


def image_grid(camera, step):
    """Pixel centers every `step` pixels over the whole image (N, 2)."""
    xs = np.arange(0.0, camera.width, step)
    ys = np.arange(0.0, camera.height, step)
    grid = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    return grid
