# SPDX-License-Identifier: Apache-2.0
"""One version: project(icoac VERSION x.y.z) in CMakeLists.txt is the harness's __version__, the
wheel's metadata (pyproject.toml's regex provider) and the C library's icoac_version();
`python -m icoac --version` prints them, and the harness's without the library."""
import os
import re
import subprocess
import sys
from pathlib import Path

import icoac
from icoac.core import binding as B

REPO = Path(__file__).resolve().parents[2]


def _cmake_version() -> str:
    text = (REPO / "CMakeLists.txt").read_text(encoding="utf-8")
    versions = re.findall(r"^project\(icoac VERSION ([0-9]+\.[0-9]+\.[0-9]+)[ )]", text, re.MULTILINE)
    assert len(versions) == 1, versions
    return versions[0]


def _pyproject() -> dict:
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib
    with open(REPO / "pyproject.toml", "rb") as f:
        return tomllib.load(f)


def test_package_version_is_the_cmake_project_version():
    assert icoac.__version__ == _cmake_version()


def test_wheel_metadata_reads_the_same_line():
    pyproject = _pyproject()
    assert "version" not in pyproject["project"] and "version" in pyproject["project"]["dynamic"]
    provider = pyproject["tool"]["scikit-build"]["metadata"]["version"]
    assert provider["provider"] == "scikit_build_core.metadata.regex"
    match = re.search(provider["regex"], (REPO / provider["input"]).read_text(encoding="utf-8"), re.MULTILINE)
    assert match is not None and match.group("value") == _cmake_version()
    generated = {g["path"]: g["template"] for g in pyproject["tool"]["scikit-build"]["generate"]}
    assert '__version__ = "${version}"' in generated["icoac/_version.py"]


def test_library_version_is_the_package_version():
    assert B.library_version() == icoac.__version__ == _cmake_version()


def _version_output(env) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "icoac", "--version"], cwd=REPO, capture_output=True, text=True,
                          timeout=60, env=env)


def test_cli_version_prints_both():
    res = _version_output(os.environ.copy())
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert lines[0] == f"icoac {_cmake_version()}"
    assert lines[1].startswith(f"icoac library {_cmake_version()} (ABI {B.ABI_VERSION}): "), lines


def test_cli_version_without_the_library(tmp_path):
    res = _version_output({**os.environ, "ICOAC_SIM_LIBRARY": str(tmp_path / "missing.so")})
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert lines[0] == f"icoac {_cmake_version()}"
    assert lines[1].startswith("icoac library not loaded: ") and "missing.so" in lines[1], lines
