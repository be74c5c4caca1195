#!/usr/bin/env python3
"""Fails when an include of the libraries runs back up their layers.

    scripts/check_layers.py [ROOT]

The libraries' areas (rcm/include/rcm/AREA and rcm/src/AREA: rcm::rcm's,
rcm::rosbag's rosbag, rcm::sim's sim and rcm::viz's viz; and rcm::calib's
calib/) stand in layers, lowest first:

    util < plot < geometry < camera < stereo < io < frontend
         < estimation, calib < live < sim, viz, rosbag

The top layer's areas are the libraries built on rcm::rcm (rcm::sim,
rcm::viz, rcm::rosbag), so that no area of rcm::rcm or rcm::calib
reaches into them.
A file of an area may include its own area's headers and those of the
areas below it; areas of one layer (estimation and calib; sim, viz and
rosbag) do not include each other. The tools above them all (examples/, python/,
ros/, tests/, benchmarks/, fuzz/) include what they need. Every include
that breaks the rule is one line `FILE:LINE: AREA includes rcm/OTHER/...
(a layer above or beside it)`, and the exit status is 1; 0 when there is
none. ROOT is the repository (default: this script's parent folder).
"""

import re
import sys
from pathlib import Path

# Areas and their layers, lowest first; the layer's index is its rank.
LAYERS = [
    ["util"],
    ["plot"],
    ["geometry"],
    ["camera"],
    ["stereo"],
    ["io"],
    ["frontend"],
    ["estimation", "calib"],
    ["live"],
    ["sim", "viz", "rosbag"],
]
RANK = {area: rank for rank, areas in enumerate(LAYERS) for area in areas}
INCLUDE = re.compile(r'^\s*#\s*include\s+[<"]rcm/([a-z_0-9]+)/')


def area_files(root):
    """(area, path) of every header and source of the libraries."""
    folders = []
    for base in ("rcm/include/rcm", "rcm/src"):
        for folder in sorted((root / base).iterdir()):
            if folder.is_dir():
                folders.append((folder.name, folder))
    folders.append(("calib", root / "calib/include/rcm/calib"))
    folders.append(("calib", root / "calib/src"))
    for area, folder in folders:
        for path in sorted(folder.rglob("*")):
            if path.suffix in (".h", ".cc", ".in") and path.is_file():
                yield area, path


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else
                Path(__file__).resolve().parent.parent)
    errors = []
    for area, path in area_files(root):
        if area not in RANK:
            errors.append(f"{path.relative_to(root)}: area {area} has no "
                          "layer (scripts/check_layers.py LAYERS)")
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            match = INCLUDE.match(line)
            if not match:
                continue
            other = match.group(1)
            if other == area:
                continue
            if other not in RANK:
                errors.append(f"{path.relative_to(root)}:{number}: includes "
                              f"rcm/{other}/, an area with no layer")
            elif RANK[other] >= RANK[area]:
                errors.append(f"{path.relative_to(root)}:{number}: {area} "
                              f"includes rcm/{other}/... (a layer above or "
                              "beside it)")
    for error in errors:
        print(f"check_layers: {error}", file=sys.stderr)
    if errors:
        print(f"check_layers: {len(errors)} include(s) run back up the "
              "layers", file=sys.stderr)
        return 1
    print("check_layers: every include of the libraries points down")
    return 0


if __name__ == "__main__":
    sys.exit(main())
