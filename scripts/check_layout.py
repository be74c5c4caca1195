#!/usr/bin/env python3
"""Fails when docs/layout.md is not true to the tree.

    scripts/check_layout.py [ROOT]

Checks, in docs/layout.md of the repository ROOT (default: this script's
parent folder):
  - Folders: every top-level folder that holds a tracked file is listed at
    the start of a line of the page's first code block (`NAME/`);
  - Areas: every folder of rcm/include/rcm/ has its row (| `AREA` |);
  - The pieces: every header a table cell names exists, and every public
    header of the libraries is named. A cell names headers by include path
    (`rcm/AREA/x.h`) or by name alone (`x.h`: in the area of the path
    before it in the cell).
Every mismatch is one line; the exit status is 1 when there is one.
"""

import re
import subprocess
import sys
from pathlib import Path

PATH = re.compile(r"`(rcm/([a-z_0-9]+)/)?([a-z_0-9]+\.h)`")


def public_headers(root):
    """{"rcm/AREA/x.h"} of rcm/include and calib/include."""
    headers = set()
    for base in (root / "rcm/include", root / "calib/include"):
        for path in base.rglob("*.h"):
            headers.add(str(path.relative_to(base)))
    return headers


def top_level_folders(root):
    """The top-level folders that hold a tracked file (git), or, outside a
    git checkout, every top-level folder but the outputs the page names."""
    try:
        tracked = subprocess.run(["git", "-C", str(root), "ls-files"],
                                 capture_output=True, text=True,
                                 check=True).stdout.split()
        return sorted({f.split("/")[0] for f in tracked if "/" in f})
    except (OSError, subprocess.CalledProcessError):
        outputs = re.compile(r"^(build.*|rcm_demo|fuzz-findings|\.git)$")
        return sorted(p.name for p in root.iterdir()
                      if p.is_dir() and not outputs.match(p.name))


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else
                Path(__file__).resolve().parent.parent)
    page = (root / "docs/layout.md").read_text()
    errors = []

    folders = top_level_folders(root)
    block = page.split("```")[1] if page.count("```") >= 2 else ""
    listed = {line.split()[0].rstrip("/") for line in block.splitlines()
              if line and not line[0].isspace()}
    listed |= {name.split("/")[0] for name in listed}
    for folder in folders:
        if folder not in listed:
            errors.append(f"folder {folder}/ is not in the Folders block")

    for area in sorted(p.name for p in (root / "rcm/include/rcm").iterdir()
                       if p.is_dir()):
        if f"| `{area}` |" not in page:
            errors.append(f"area {area} has no row in the Areas table")

    headers = public_headers(root)
    named = set()
    for line in page.splitlines():
        if not line.startswith("|"):
            continue
        for cell in line.split("|"):
            area = None
            for match in PATH.finditer(cell):
                if match.group(2):
                    area = match.group(2)
                if area is None:
                    continue
                header = f"rcm/{area}/{match.group(3)}"
                if header not in headers:
                    errors.append(f"{header} is named but does not exist")
                named.add(header)
    for header in sorted(headers - named):
        errors.append(f"{header} exists but is not named")

    for error in errors:
        print(f"check_layout: docs/layout.md: {error}", file=sys.stderr)
    if errors:
        return 1
    print(f"check_layout: docs/layout.md names the {len(folders)} folders, "
          f"the areas and all {len(headers)} public headers")
    return 0


if __name__ == "__main__":
    sys.exit(main())
