# SPDX-License-Identifier: Apache-2.0
"""The harness as a package (pyproject.toml, scikit-build-core): a wheel built from a clean copy of
the checkout (its tracked and new, not ignored, files: no build/, no .venv), installed into a fresh
venv, gives a working `icoac` that runs a grid on the library inside the package - not
ICOAC_SIM_LIBRARY, not a build/ tree - with the cells of the development build, bit for bit.

Slow (a fresh venv, numpy and matplotlib installed into it, the C library compiled): marked
`slow`, deselect with `-m "not slow"`. It needs PyPI (or pip's find-links) for scikit-build-core
and the dependencies; without them it is skipped, with the reason, and never passes silently."""
import json
import os
import re
import shutil
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
GRID = ["grid", "--condition", "ico", "--cells", "0-3,610-611", "--max-trials", "50", "--success-steps", "200",
        "--seed", "3", "--threads", "2", "--quiet"]
LIBRARY = "icoac/lib/libicoac_sim.so"

pytestmark = pytest.mark.slow


def _env(**extra) -> dict:
    """The environment without ICOAC_SIM_LIBRARY or a PYTHONPATH that could lead to the checkout."""
    env = {k: v for k, v in os.environ.items() if k not in ("ICOAC_SIM_LIBRARY", "PYTHONPATH", "PYTHONHOME")}
    env.update(CMAKE_BUILD_PARALLEL_LEVEL="2", PIP_NO_INPUT="1", **extra)
    return env


def _run(args, timeout, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=timeout, **kw)


def _check(res: subprocess.CompletedProcess, what: str) -> None:
    assert res.returncode == 0, f"{what} failed ({res.returncode}):\n{res.stdout[-3000:]}\n{res.stderr[-3000:]}"


def _clean_copy(dest: Path) -> None:
    """The files of the checkout that git would commit (tracked ones as they are now, new ones
    not ignored); a plain copy without build outputs where there is no git."""
    try:
        res = _run(["git", "-C", REPO, "ls-files", "-z", "--cached", "--others", "--exclude-standard"], 60)
    except OSError:
        res = None
    if res is not None and res.returncode == 0:
        for name in res.stdout.split("\0"):
            src = REPO / name
            if name and src.is_file():  # a tracked file deleted in the working tree is left out
                (dest / name).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(src, dest / name)
    else:
        shutil.copytree(REPO, dest, dirs_exist_ok=True, ignore=shutil.ignore_patterns(
            ".git", ".venv", "build", "results", "dist", "__pycache__", "*.egg-info", ".pytest_cache"))
    assert (dest / "pyproject.toml").is_file() and not (dest / "build").exists()


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(venv, wheel, seconds to build it) of a wheel of a clean copy, installed in a fresh venv."""
    try:
        import ensurepip  # noqa: F401  (python3-venv on Debian)
    except ImportError:
        pytest.skip("the Python running the tests has no ensurepip (Debian: python3-venv), so no venv")
    tmp = tmp_path_factory.mktemp("wheel")
    src, dist, venv = tmp / "src", tmp / "dist", tmp / "venv"
    _clean_copy(src)
    _check(_run([sys.executable, "-m", "venv", venv], 300, env=_env()), "python -m venv")
    py = venv / "bin" / "python"
    # A prerequisite, not the test: the build backend from the package index (or find-links).
    probe = _run([py, "-m", "pip", "download", "--no-deps", "-q", "-d", tmp / "probe", "scikit-build-core"], 300,
                 env=_env())
    if probe.returncode != 0:
        last = (probe.stderr.strip().splitlines() or ["no output"])[-1]
        pytest.skip(f"pip cannot fetch scikit-build-core (package index unreachable?): {last}")
    start = time.perf_counter()
    _check(_run([py, "-m", "pip", "wheel", "--no-deps", "-w", dist, src], 900, env=_env(), cwd=tmp), "pip wheel")
    seconds = time.perf_counter() - start
    wheels = list(dist.glob("*.whl"))
    assert len(wheels) == 1, wheels
    _check(_run([py, "-m", "pip", "install", wheels[0]], 900, env=_env(), cwd=tmp), "pip install of the wheel")
    return venv, wheels[0], seconds


def test_wheel_holds_the_package_and_its_library(installed):
    _, wheel, seconds = installed
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
        entry_points = next(zf.read(n).decode() for n in names if n.endswith(".dist-info/entry_points.txt"))
        tag = next(zf.read(n).decode() for n in names if n.endswith(".dist-info/WHEEL"))
    assert LIBRARY in names and "icoac/lib/build_info.json" in names
    assert {"icoac/__init__.py", "icoac/cli.py", "icoac/core/binding.py", "icoac/tools/imports.py"} <= names
    # Only the package: no tests, C sources, firmware or compiled Python files.
    assert all(n.startswith(("icoac/", "icoac-")) for n in names), sorted(names)
    assert not any(n.endswith((".pyc", ".c", ".h")) for n in names)
    assert "icoac = icoac.cli:main" in entry_points
    assert "Tag: py3-none-" in tag
    print(f"\nwheel {wheel.name}: {wheel.stat().st_size} bytes, built in {seconds:.1f} s")


def test_installed_command_runs_a_grid_on_the_installed_library(installed, tmp_path):
    venv, _, _ = installed
    cwd = tmp_path / "elsewhere"   # no harness/ or build/ here: neither can be picked up
    cwd.mkdir()
    res = _run([venv / "bin" / "icoac", *GRID, "--out", "out"], 600, env=_env(), cwd=cwd)
    _check(res, "icoac grid")
    out = cwd / "out"
    assert (out / "cells.npz").is_file() and (out / "run.json").is_file()
    record = json.loads((out / "run.json").read_text())
    site = Path(_run([venv / "bin" / "python", "-c", "import sysconfig; print(sysconfig.get_path('platlib'))"], 60,
                     env=_env(), cwd=cwd).stdout.strip())
    assert Path(record["abi"]["library"]).resolve() == (site / LIBRARY).resolve(), record["abi"]
    assert record["abi"]["library_source"] == "package"
    assert record["complete"] is True
    # Built from a copy outside any git work tree: the commit is unknown, not some other repository's.
    assert record["git"] == {"commit": None, "dirty": None}

    # The same grid on the development library (the tests' one): the wheel is the reference build.
    dev = _run([sys.executable, "-m", "icoac", *GRID, "--out", tmp_path / "dev"], 600, cwd=REPO)
    _check(dev, "python -m icoac grid (development library)")
    with np.load(out / "cells.npz") as a, np.load(tmp_path / "dev" / "cells.npz") as b:
        wheel_cells, dev_cells = a["cells"], b["cells"]
    from icoac.core import binding as B
    assert len(wheel_cells) == 6 and (wheel_cells["outcome"] != B.PENDING).all()
    for field in wheel_cells.dtype.names:
        if field != "elapsed_time":
            assert np.array_equal(wheel_cells[field], dev_cells[field]), field


def test_installed_package_ignores_a_checkout_and_honours_the_variable(installed, tmp_path):
    """Run from a folder of the checkout (which has a build/ tree), the installed package still loads
    its own library; ICOAC_SIM_LIBRARY, when set, comes first; a missing one is a one-line error."""
    venv, _, _ = installed
    code = "import icoac.core.binding as B; print(B.LIBRARY_SOURCE, B.LIBRARY_PATH)"
    res = _run([venv / "bin" / "python", "-c", code], 60, env=_env(), cwd=REPO / "tests")
    _check(res, "import from the checkout")
    source, path = res.stdout.split()
    assert source == "package" and Path(path).resolve().is_relative_to(venv.resolve()), res.stdout
    dev_library = os.environ.get("ICOAC_SIM_LIBRARY", str(REPO / "build/release/sim_host/libicoac_sim.so"))
    res = _run([venv / "bin" / "python", "-c", code], 60, env=_env(ICOAC_SIM_LIBRARY=dev_library), cwd=tmp_path)
    _check(res, "import with ICOAC_SIM_LIBRARY")
    assert res.stdout.split() == ["env", dev_library]
    res = _run([venv / "bin" / "icoac", *GRID, "--out", "x"], 60,
               env=_env(ICOAC_SIM_LIBRARY=str(tmp_path / "libnone.so")), cwd=tmp_path)
    lines = res.stderr.strip().splitlines()
    assert res.returncode == 2 and len(lines) == 1 and "ICOAC_SIM_LIBRARY=" in lines[0], res.stderr


def test_installed_version_is_the_cmake_project_version(installed, tmp_path):
    """The wheel's metadata and icoac/_version.py (generated by the build) carry the version of
    CMakeLists.txt's project() line, and so does the library inside it (icoac_version)."""
    venv, wheel, _ = installed
    version = re.search(r"^project\(icoac VERSION ([0-9.]+)", (REPO / "CMakeLists.txt").read_text(), re.M).group(1)
    with zipfile.ZipFile(wheel) as zf:
        metadata = next(zf.read(n).decode() for n in zf.namelist() if n.endswith(".dist-info/METADATA"))
        generated = zf.read("icoac/_version.py").decode()
    assert f"\nVersion: {version}\n" in metadata and f'__version__ = "{version}"' in generated
    res = _run([venv / "bin" / "icoac", "--version"], 60, env=_env(), cwd=tmp_path)
    _check(res, "icoac --version")
    lines = res.stdout.splitlines()
    assert lines[0] == f"icoac {version}" and lines[1].startswith(f"icoac library {version} (ABI "), lines
    assert lines[1].endswith(LIBRARY), lines
