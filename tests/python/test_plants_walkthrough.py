# SPDX-License-Identifier: Apache-2.0
"""docs/plants.md's walkthrough, done as a newcomer does it: a copy of the checkout's C sources
gets the page's plant file and its registry line (its two ``c`` code blocks), nothing else; the
library built from it runs the page's plant through `grid` (its whole grid), `ceiling`, `figures`
and Gymnasium's check_env, each in a fresh process on that library (ICOAC_SIM_LIBRARY) with this
checkout's harness.

Slow (a C build): marked `slow`, deselect with `-m "not slow"`."""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DOC = REPO / "docs" / "plants.md"
COPIED = ("CMakeLists.txt", "CMakePresets.json", "cmake", "firmware", "sim_host")

pytestmark = pytest.mark.slow


def walkthrough_blocks() -> tuple[str, str, str]:
    """(plant name, its C file, the registry line) from the page's ``c`` code blocks."""
    blocks = re.findall(r"^```c\n(.*?)^```", DOC.read_text(), re.S | re.M)
    files = [b for b in blocks if "const icoac_sim_plant_desc_t sim_" in b]
    lines = [b.strip() for b in blocks if b.startswith("#define SIM_PLANTS(X)")]
    assert len(files) == 1 and len(lines) == 1, "plants.md: one plant file and one registry line"
    name = re.search(r"const icoac_sim_plant_desc_t sim_(\w+) = \{", files[0]).group(1)
    assert f"X(sim_{name})" in lines[0]
    return name, files[0], lines[0]


def run(args, env, timeout=900, cwd=None):
    res = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=timeout, env=env, cwd=cwd)
    assert res.returncode == 0, f"{args[:4]} failed ({res.returncode}):\n{res.stdout[-3000:]}\n{res.stderr[-3000:]}"
    return res.stdout


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """(plant name, the library built with the page's plant added)."""
    name, source, registry_line = walkthrough_blocks()
    src = tmp_path_factory.mktemp("walkthrough") / "src"
    src.mkdir()
    for item in COPIED:
        (shutil.copytree if (REPO / item).is_dir() else shutil.copy2)(REPO / item, src / item)
    (src / "sim_host" / "src" / "plants" / f"{name}.c").write_text(source)
    registry = src / "sim_host" / "src" / "plant_registry.c"
    text, n = re.subn(r"^#define SIM_PLANTS\(X\).*$", registry_line, registry.read_text(), flags=re.M)
    assert n == 1
    registry.write_text(text)
    build = src / "build"
    env = {**os.environ, "CMAKE_BUILD_PARALLEL_LEVEL": "2"}
    run(["cmake", "-S", src, "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release", "-DICOAC_BUILD_HOST=ON",
         "-DICOAC_BUILD_TESTS=OFF", "-DICOAC_WARNINGS_AS_ERRORS=ON"], env)
    run(["cmake", "--build", build, "--target", "icoac_sim"], env, timeout=1800)
    return name, build / "sim_host" / "libicoac_sim.so"


def test_the_page_plant_runs_every_command(library, tmp_path):
    name, lib = library
    env = {**os.environ, "ICOAC_SIM_LIBRARY": str(lib), "PYTHONPATH": str(REPO / "harness")}
    harness = [sys.executable, "-m", "icoac"]
    out = run([*harness, "grid", "--plant", name, "--out", tmp_path / "grid", "--max-trials", "20",
               "--success-steps", "300", "--quiet"], env)
    assert "cells" in out
    check = ("import json, sys; from icoac.core import geometry, results; cells, rec = results.load(sys.argv[1]); "
             "g = geometry.of(sys.argv[2]); assert rec['config']['plant']['name'] == sys.argv[2]; "
             "assert cells.size == g.cells and g.on_grid(cells).all(); print(g.rows, g.cols)")
    shape = run([sys.executable, "-c", check, tmp_path / "grid", name], env).split()
    run([*harness, "ceiling", "--plant", name, "--out", tmp_path / "ceiling", "--max-trials", "5",
         "--success-steps", "300", "--screen-steps", "100", "--cells", "0-9", "--quiet"], env)
    assert (tmp_path / "ceiling" / "ceiling.json").is_file()
    printed = run([*harness, "figures", "--results", tmp_path / "grid", "--out", tmp_path / "fig"], env)
    assert sorted(Path(p).name for p in printed.split()) == ["fig1b_success_map.png", "fig1cf_weights.png"]
    env_name = "".join(word.capitalize() for word in name.split("_"))
    gym = ("import sys, gymnasium, icoac.gym; from gymnasium.utils.env_checker import check_env; "
           f"env = gymnasium.make('icoac/{env_name}-v0'); check_env(env.unwrapped); "
           "o, i = env.reset(options={'cell': int(sys.argv[1]) - 1}); "
           f"print(len(o) == len(icoac.core.binding.plant_info('{name}')['state']), i['cell'])")
    cells = int(shape[0]) * int(shape[1])
    assert run([sys.executable, "-W", "ignore", "-c", gym, cells], env).split() == ["True", str(cells - 1)]
