# SPDX-License-Identifier: Apache-2.0
"""Canonical names and their aliases, ABI-3 records (flat controller dict), and the import graph."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from harness import _binding as B
from harness import config, figures, results, store
from harness import prior as P
from harness.config import (ALIASES, ALL_FIELDS, build_config, canonical, config_from_dict, named_sets,
                            parse_sets)
from harness.errors import UsageError
from harness.tools import imports

REPO = Path(__file__).resolve().parents[2]
FIXTURES = Path(__file__).resolve().parent / "fixtures"
ABI3_ICO = FIXTURES / "abi3_ico"            # an ICO results directory written by the ABI-3 harness
ABI3_ICORL = FIXTURES / "abi3_icorl_run.json"  # the ICO->RL run.json of the same bench, prior from ABI3_ICO

# One non-default value per aliased field, valid in RL mode (every group the values touch is checked).
VALUES = {
    "input_range": [2.0, 3.0, 0.25, 2.5], "clip_inputs": False, "gain": 7.5, "reflex_mode": "gain",
    "reflex_force": 2.0, "zone_theta": 0.19, "zone_x": 2.2, "ico_rate": 2e-4, "ico_timing": "literal",
    "critic_rate": 0.3, "discount": 0.9, "td_clip": 0.5, "critic_range": [2.0, 3.0, 0.2, 1.5],
    "critic_threshold": 0.0, "noise_std": 0.5, "actor_scale": 0.25, "forgetting": 0.999, "rl_reflex": False,
    "act_with_sample": True,
}


def test_alias_table_covers_the_abi3_names():
    old = json.loads((ABI3_ICO / "run.json").read_text())["config"]["controller"]
    assert set(old) - {"mode"} == set(ALIASES) | set(config.ZONE_ALIASES) == set(VALUES)
    # every ABI-3 field has its alias (the zone's set the cart-pole task's rule thresholds);
    # "learn" (the no-learning control), the learners' fields of ABI 6 (method.md, L2-L4, A10) and
    # the task description of ABI 8 and its input signs (ABI 9) came after ABI 3 and have canonical names only
    after_abi3 = {"mode", "learn", "critic.quirks", "actor.update", "actor.rate", "actor.likelihood_std",
                  "actor.batch", "actor.explore_ticks", "search.batch", "search.elite_fraction", "search.step",
                  "search.floor", "search.cov_scale", "task.n_inputs", "task.late_source", "task.n_rules",
                  "task.rule_input", "task.rule_side", "task.rule_threshold", "task.rule_reflex", "critic.units",
                  "task.input_sign"}
    assert set(ALIASES.values()) & after_abi3 == set()
    assert sorted(ALIASES.values()) == sorted(n for n in config.CONTROLLER_FIELDS if n not in after_abi3)
    for alias, name in ALIASES.items():
        assert canonical(alias) == canonical(name) == name
    for name in ALL_FIELDS:
        assert canonical(name) == name


def test_zone_names_set_the_cartpole_rule_thresholds():
    """zone_theta / zone_x (and policy.zone_*) of earlier versions: the preset's four thresholds."""
    for name in ("zone_theta", "policy.zone_theta"):
        t = list(build_config({name: 0.19, "zone_x": 2.2}).controller.task.rule_threshold)[:4]
        assert t == pytest.approx([0.19, -2.2, -0.19, 2.2], rel=1e-6)
    with pytest.raises(B.ConfigError, match="policy.zone_x") as info:
        build_config({"zone_x": 0.0})
    assert info.value.status == B.ERR_BAD_ZONE
    assert "policy.zone_theta" not in build_config({"zone_theta": 0.19}).flat()  # recorded as the thresholds


@pytest.mark.parametrize("alias", sorted(ALIASES))
def test_alias_and_canonical_give_identical_configs(alias):
    value = VALUES[alias]
    a = build_config({alias: value}, condition="rl")
    b = build_config({ALIASES[alias]: value}, condition="rl")
    assert bytes(a.controller) == bytes(b.controller) != bytes(build_config(condition="rl").controller)
    assert a.to_dict() == b.to_dict()
    text = json.dumps(value)
    assert parse_sets([f"{alias}={text}"]) == parse_sets([f"{ALIASES[alias]}={text}"])


def test_all_aliases_at_once_and_a_field_given_twice():
    a = build_config(VALUES, condition="rl")
    b = build_config({{**ALIASES, **config.ZONE_ALIASES}[k]: v for k, v in VALUES.items()}, condition="rl")
    assert bytes(a.controller) == bytes(b.controller)
    for items in (["gain=3", "policy.gain=4"], ["policy.gain=4", "gain=3"], ["gain=3", "gain=3"]):
        with pytest.raises(UsageError, match=f"--set {items[0]} and --set {items[1]} both set policy.gain"):
            parse_sets(items)


def test_canonical_record_nested_and_flat_names():
    d = build_config({"gain": 5}).to_dict()
    assert d["controller"]["policy"]["gain"] == 5.0 and "gain" not in d["controller"]
    flat = build_config({"gain": 5}).flat()
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
        config_from_dict({"plant": {"gain": 1}})


def test_rejection_names_the_c_field():
    with pytest.raises(B.ConfigError) as info:
        build_config({"critic_range": [2.4, 3.5, 0.2, 0.0]}, condition="rl")
    assert info.value.status == B.ERR_BAD_CRITIC and "rejected: critic.range[3]=0.0" in str(info.value)
    with pytest.raises(B.ConfigError, match=r"rejected: actor.forgetting=0.25"):
        build_config({"actor.forgetting": 0.25}, condition="rl")
    # ICO mode validates only the policy and ico groups (icoac_config_check)
    build_config({"actor.forgetting": 0.25}, condition="ico")


# -- ABI-3 records ---------------------------------------------------------------------------------------
def test_abi3_record_loads_with_the_same_configuration():
    cells, record = results.load(ABI3_ICO)
    assert record["abi"]["abi_version"] == 3 and "gain" in record["config"]["controller"]
    cfg = results.load_config(record)
    # a record from before the learners: their fields take the literal configuration's values (the
    # record's own fields, sigma_u = 1 N among them, are those of the literal configuration too)
    literal = parse_sets(named_sets("literal"))
    assert cfg.to_dict() == build_config({"max_trials": 6000, "success_steps": 2000, **literal},
                                         condition="ico").to_dict()
    assert cfg.flat()["actor.update"] == "posterior" and cfg.flat()["actor.explore_ticks"] == 0
    store.check_resumable(record, condition="ico", seed=record["seed"], cfg=cfg, cell_indices=record["cells"])
    with pytest.raises(results.ResultsError, match=r"policy.gain 10.0 != 5.0"):
        store.check_resumable(record, condition="ico", seed=record["seed"], cell_indices=record["cells"],
                                cfg=build_config({"max_trials": 6000, "success_steps": 2000, "gain": 5}))
    rl = json.loads(ABI3_ICORL.read_text())
    rl_cfg = config_from_dict(rl["config"])
    assert rl_cfg.controller.mode == B.MODE_RL and rl_cfg.prior is not None
    assert config_from_dict(rl_cfg.to_dict()).to_dict() == rl_cfg.to_dict()


def test_abi3_record_gives_the_same_prior():
    rl = json.loads(ABI3_ICORL.read_text())
    info = P.from_results(ABI3_ICO).to_dict()
    for key in ("mean", "cov", "n_cells", "frame", "ridge", "ico_phase_simulated_time", "source_cells",
                "source_success_rate"):
        assert info[key] == rl["prior_info"][key], key


def test_abi3_record_draws_figures(tmp_path):
    cells, record = results.load(ABI3_ICO)
    paths = figures.make_figures(cells, record, tmp_path / "fig", duration=2.0)
    assert sorted(p.name for p in paths) == ["fig1b_success_map.png", "fig1cf_weights.png", "fig1g_trajectory.png"]


def test_abi3_record_via_cli(tmp_path):
    d = tmp_path / "old"
    shutil.copytree(ABI3_ICO, d)
    res = subprocess.run([sys.executable, "-m", "harness", "figures", "--results", str(d), "--out",
                          str(tmp_path / "fig"), "--duration", "1"], cwd=REPO, capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    before = {p.name: p.read_bytes() for p in d.iterdir()}
    res = subprocess.run([sys.executable, "-m", "harness", "grid", "--out", str(d), "--resume", "--quiet"],
                         cwd=REPO, capture_output=True, text=True, timeout=120)
    # readable, but not resumed: its cells were written by the ABI-3 library
    assert res.returncode == 2 and "another ABI (abi_version 3, this library" in res.stderr, res.stderr
    assert {p.name: p.read_bytes() for p in d.iterdir()} == before


# -- import graph -----------------------------------------------------------------------------------------
def test_import_graph_has_no_cycle_and_nothing_imports_cli():
    g = imports.graph()
    assert "harness.cli" in g and "harness.conditions" in g and "harness.errors" in g
    assert imports.problems(g) == []
    assert {m for m, deps in g.items() if "harness.cli" in deps} == {"harness.__main__"}
    assert g["harness.errors"] == set() and g["harness.options"] == set()
    assert g["harness._binding"] == {"harness.errors"}


def test_import_checker_finds_a_cycle_and_a_cli_import(tmp_path):
    pkg = tmp_path / "harness"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "cli.py").write_text("from . import a\n")
    (pkg / "a.py").write_text("def f():\n    from .b import g\n")
    (pkg / "b.py").write_text("import harness.a\nfrom .cli import main\n")
    g = imports.graph(pkg)
    assert g["harness.a"] == {"harness.b"} and g["harness.b"] == {"harness.a", "harness.cli"}
    found = imports.problems(g)
    assert any(p.startswith("cycle:") and "harness.a" in p and "harness.b" in p for p in found)
    assert "harness.b imports harness.cli" in found


def test_import_graph_command():
    res = subprocess.run([sys.executable, "-m", "harness.tools.imports"], cwd=REPO, capture_output=True,
                         text=True, timeout=60, env={"PATH": "/usr/bin:/bin", "ICOAC_SIM_LIBRARY": "/nonexistent"})
    assert res.returncode == 0, res.stdout + res.stderr
    assert "harness.cli" in res.stdout and res.stdout.strip().endswith(
        "no cycle; nothing but harness.__main__ imports harness.cli")
