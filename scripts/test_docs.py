#!/usr/bin/env python3
"""Builds and runs every snippet of docs/api.md against an installed rcm.

    RCM_PREFIX=P scripts/test_docs.py [docs/api.md]

P is the prefix of `cmake --install build --prefix P` (scripts/test_install.sh
calls this). A snippet is the fenced block after a line
`<!-- snippet: NAME -->`; each NAME has a C++ block (a whole program, built
with find_package(rcm 0.2) against P alone) and a Python block (run with
/usr/bin/python3, the package imported from P). Each runs in a folder of
its own holding the data the page names (camchain.yaml, matches.csv: the
bundled demo data; dive/: `rcm simulate --out dive --frames 3 --n 1.34`).
A job passes when both programs exit 0, print the same lines and write the
same calibration files (*.yaml, *.csv) byte for byte. Any failure is one
line naming the snippet, and the exit status is 1.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SNIPPET = re.compile(r"^<!-- snippet: ([a-z_]+) -->\s*$")
FENCE = re.compile(r"^```(\w+)\s*$")
PYTHON = "/usr/bin/python3"


def fail(message):
    print(f"test_docs: {message}", file=sys.stderr)
    sys.exit(1)


def snippets(page):
    """{name: {"cpp": text, "python": text}} in page order."""
    found = {}
    lines = page.read_text().splitlines()
    i = 0
    while i < len(lines):
        match = SNIPPET.match(lines[i])
        i += 1
        if not match:
            continue
        name = match.group(1)
        if i >= len(lines) or not FENCE.match(lines[i]):
            fail(f"{page.name}:{i}: snippet {name}: no fenced block follows")
        language = FENCE.match(lines[i]).group(1)
        if language not in ("cpp", "python"):
            fail(f"{page.name}:{i + 1}: snippet {name}: language {language}, expected cpp or python")
        body = []
        i += 1
        while i < len(lines) and lines[i].strip() != "```":
            body.append(lines[i])
            i += 1
        if language in found.setdefault(name, {}):
            fail(f"{page.name}: snippet {name} has two {language} blocks")
        found[name][language] = "\n".join(body) + "\n"
    for name, blocks in found.items():
        missing = {"cpp", "python"} - blocks.keys()
        if missing:
            fail(f"{page.name}: snippet {name} has no {' or '.join(sorted(missing))} block")
    if not found:
        fail(f"{page.name}: no snippets")
    return found


def run(command, cwd, env=None, what=""):
    result = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True,
                            timeout=600)
    if result.returncode != 0:
        tail = (result.stderr or result.stdout).strip().splitlines()[-15:]
        fail(f"{what}: exit {result.returncode}\n" + "\n".join(tail))
    return result.stdout


def calibration_files(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and not p.is_symlink() and p.suffix in (".yaml", ".csv")
            and "dive" not in p.relative_to(folder).parts}


def main():
    page = (Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "api.md").resolve()
    prefix = os.environ.get("RCM_PREFIX")
    if not prefix:
        fail("RCM_PREFIX (the install prefix) is not set")
    prefix = Path(prefix)
    jobs = snippets(page)
    work = Path(tempfile.mkdtemp(prefix="rcm-docs."))
    try:
        # The data the snippets name.
        data = work / "data"
        data.mkdir()
        shutil.copy(ROOT / "examples/data/alphasense_front_rectified.yaml", data / "camchain.yaml")
        shutil.copy(ROOT / "examples/data/demo_matches.csv", data / "matches.csv")
        run([str(prefix / "bin/rcm"), "simulate", "--out", "dive", "--frames", "3",
             "--n", "1.34", "--seed", "1"], cwd=data, what="rcm simulate")

        # All C++ snippets: one project against the install tree.
        source = work / "cpp"
        source.mkdir()
        cmake = ["cmake_minimum_required(VERSION 3.16)", "project(api_snippets LANGUAGES CXX)",
                 "find_package(rcm 0.2 REQUIRED)"]
        for name, blocks in jobs.items():
            (source / f"{name}.cc").write_text(blocks["cpp"])
            cmake += [f"add_executable({name} {name}.cc)",
                      f"target_compile_features({name} PRIVATE cxx_std_17)",
                      f"target_link_libraries({name} PRIVATE rcm::rcm)"]
        (source / "CMakeLists.txt").write_text("\n".join(cmake) + "\n")
        build = work / "cpp-build"
        run(["cmake", "-S", str(source), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
             f"-DCMAKE_PREFIX_PATH={prefix}"], cwd=work, what="configuring the C++ snippets")
        run(["cmake", "--build", str(build), "-j2"], cwd=work, what="building the C++ snippets")

        python_dirs = sorted(prefix.glob("lib/python3*/*-packages/rcm/__init__.py"))
        if not python_dirs:
            fail(f"no Python package rcm under {prefix}")
        env = dict(os.environ, PYTHONPATH=str(python_dirs[0].parent.parent))

        for name, blocks in jobs.items():
            outputs = {}
            for language in ("cpp", "python"):
                folder = work / "run" / f"{name}-{language}"
                folder.mkdir(parents=True)
                for item in data.iterdir():
                    (folder / item.name).symlink_to(item)
                if language == "cpp":
                    command = [str(build / name)]
                else:
                    (folder / "snippet.py").write_text(blocks["python"])
                    command = [PYTHON, "snippet.py"]
                stdout = run(command, cwd=folder, env=env, what=f"snippet {name} ({language})")
                files = calibration_files(folder)
                if language == "python":
                    files.pop(Path("snippet.py"), None)
                outputs[language] = (stdout, files)
            (cpp_out, cpp_files), (py_out, py_files) = outputs["cpp"], outputs["python"]
            if cpp_out != py_out:
                fail(f"snippet {name}: C++ and Python print differently:\n"
                     f"--- C++\n{cpp_out}--- Python\n{py_out}")
            if cpp_files.keys() != py_files.keys():
                fail(f"snippet {name}: C++ wrote {sorted(map(str, cpp_files))}, "
                     f"Python {sorted(map(str, py_files))}")
            for path in cpp_files:
                if cpp_files[path] != py_files[path]:
                    fail(f"snippet {name}: {path} differs between C++ and Python")
            lines = cpp_out.strip().splitlines()
            print(f"snippet {name}: C++ and Python agree ({len(lines)} lines"
                  f"{', ' + str(len(cpp_files)) + ' files' if cpp_files else ''}): {lines[0]}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"test_docs: {len(jobs)} snippets of {page.relative_to(ROOT)} built, run and in agreement")


if __name__ == "__main__":
    main()
