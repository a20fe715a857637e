# SPDX-License-Identifier: Apache-2.0
"""Parameter names, and the import graph."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from icoac.core import binding as B
from icoac.core import config, results, store
from icoac.studies import figures
from icoac.studies import prior as P
from icoac.core.config import ALL_FIELDS, build_config, config_from_dict, parse_sets
from icoac.core.errors import UsageError
from icoac.tools import imports

REPO = Path(__file__).resolve().parents[2]
FIXTURES = Path(__file__).resolve().parent / "fixtures"

def test_flat_names_of_earlier_versions_are_refused():
    """Before 1.0 the flat names of earlier versions (gain, noise_std, zone_x, ...) went: a name is
    its C member designator."""
    for name in ("gain", "noise_std", "zone_x", "policy.zone_theta", "rl_reflex"):
        with pytest.raises(B.ConfigError, match=rf"unknown parameter '{name}'"):
            build_config({name: 1})
        with pytest.raises((B.ConfigError, UsageError), match=rf"unknown parameter .{name}."):
            parse_sets([f"{name}=1"])


def test_a_field_given_twice():
    for items in (["policy.gain=3", "policy.gain=4"], ["policy.gain=3", "policy.gain=3"]):
        with pytest.raises(UsageError, match=f"--set {items[0]} and --set {items[1]} both set policy.gain"):
            parse_sets(items)


def test_canonical_record_nested_and_flat_names():
    d = build_config({"policy.gain": 5}).to_dict()
    assert d["controller"]["policy"]["gain"] == 5.0 and "gain" not in d["controller"]
    flat = build_config({"policy.gain": 5}).flat()
    assert list(flat) == list(ALL_FIELDS) and flat["policy.gain"] == 5.0 and flat["ico.timing"] == "code"
    # the same configuration from dotted names in the controller group
    dotted = {"controller": {k: v for k, v in flat.items() if config.group_of(k) == "controller"}}
    assert config_from_dict(dotted).to_dict()["controller"] == d["controller"]


def test_unknown_names_and_wrong_groups():
    with pytest.raises(B.ConfigError, match=r"unknown parameter 'policy.gian' \(did you mean policy.gain\?\)"):
        build_config({"policy.gian": 1})
    with pytest.raises(B.ConfigError, match="controller group 'policy' must be a mapping"):
        config_from_dict({"controller": {"policy": 3}})
    with pytest.raises(B.ConfigError, match="unknown parameter 'policy.dt'"):
        config_from_dict({"controller": {"policy": {"dt": 0.01}}})
    with pytest.raises(B.ConfigError, match="'dt' is a plant parameter, not a controller one"):
        config_from_dict({"controller": {"dt": 0.01}})
    with pytest.raises(B.ConfigError, match="'policy.gain' is a controller parameter, not a plant one"):
        config_from_dict({"plant": {"policy.gain": 1}})


def test_rejection_names_the_c_field():
    with pytest.raises(B.ConfigError) as info:
        build_config({"critic.range": [2.4, 3.5, 0.2, 0.0]}, condition="rl")
    assert info.value.status == B.ERR_BAD_CRITIC and "rejected: critic.range[3]=0.0" in str(info.value)
    with pytest.raises(B.ConfigError, match=r"rejected: actor.forgetting=0.25"):
        build_config({"actor.forgetting": 0.25}, condition="rl")
    # ICO mode validates only the policy and ico groups (icoac_config_check)
    build_config({"actor.forgetting": 0.25}, condition="ico")


# -- import graph -----------------------------------------------------------------------------------------
def test_import_graph_has_no_cycle_and_nothing_imports_cli():
    g = imports.graph()
    assert "icoac.cli" in g and "icoac.studies.conditions" in g and "icoac.core.errors" in g
    assert imports.problems(g) == []
    assert {m for m, deps in g.items() if "icoac.cli" in deps} == {"icoac.__main__"}
    assert g["icoac.core.errors"] == set() and g["icoac.core.options"] == set()
    assert g["icoac.core.binding"] == {"icoac.core.errors"}


def test_import_checker_finds_a_cycle_and_a_cli_import(tmp_path):
    pkg = tmp_path / "icoac"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "cli.py").write_text("from . import a\n")
    (pkg / "a.py").write_text("def f():\n    from .b import g\n")
    (pkg / "b.py").write_text("import icoac.a\nfrom .cli import main\n")
    g = imports.graph(pkg)
    assert g["icoac.a"] == {"icoac.b"} and g["icoac.b"] == {"icoac.a", "icoac.cli"}
    found = imports.problems(g)
    assert any(p.startswith("cycle:") and "icoac.a" in p and "icoac.b" in p for p in found)
    assert "icoac.b imports icoac.cli" in found


def test_import_checker_finds_a_layer_breach(tmp_path):
    pkg = tmp_path / "icoac"
    for folder in ("core", "studies", "gym"):
        (pkg / folder).mkdir(parents=True)
        (pkg / folder / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "core" / "grid.py").write_text("from icoac.studies import bench\n")
    (pkg / "studies" / "bench.py").write_text("from icoac.gym import env\n")  # allowed: a study may train on an env
    (pkg / "gym" / "env.py").write_text("from icoac.studies import bench\nfrom icoac.core import grid\n")
    found = imports.problems(imports.graph(pkg))
    assert "layer: icoac.core.grid (core) imports icoac.studies.bench (studies)" in found
    assert "layer: icoac.gym.env (gym) imports icoac.studies.bench (studies)" in found
    assert not any(p.startswith("layer: icoac.studies.bench") for p in found)
    assert not any(p.startswith("layer: icoac.gym.env") and "core" in p for p in found)


def test_import_graph_command():
    res = subprocess.run([sys.executable, "-m", "icoac.tools.imports"], cwd=REPO / "harness", capture_output=True,
                         text=True, timeout=60, env={"PATH": "/usr/bin:/bin", "ICOAC_SIM_LIBRARY": "/nonexistent"})
    assert res.returncode == 0, res.stdout + res.stderr
    assert "icoac.cli" in res.stdout and res.stdout.strip().endswith(
        "no cycle; every layer imports only the layers it may; nothing but icoac.__main__ imports icoac.cli")
