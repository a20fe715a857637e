# SPDX-License-Identifier: Apache-2.0
"""The condition registry (icoac.core.registry): every condition defined once, its control generated
from it, and the configurations and priors derived from it the same as before the registry."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from icoac.studies import bench, tables
from icoac import cli
from icoac.studies import prior as P
from icoac.studies.conditions import condition_prior
from icoac.core.config import CONDITION_OVERRIDES, build_config
from icoac.core.errors import UsageError
from icoac.core.registry import CONDITIONS, PRIOR_CONDITIONS, REGISTRY, Condition, PriorRule

# The condition tables of the harness before the registry (captured from main at ad0bc3e). When a
# condition's overrides change on purpose (registry.py), change them here too.
BEFORE = json.loads((Path(__file__).resolve().parent / "fixtures" / "conditions_before_registry.json").read_text())


def test_same_conditions_as_before():
    assert list(CONDITIONS) == BEFORE["conditions"]
    assert {c.name: c.control_of for c in REGISTRY.values() if c.control_of} == BEFORE["control_of"]
    assert {c.name: list(c.prior) for c in REGISTRY.values() if c.prior and c.learns} == BEFORE["prior_rules"]
    assert {c.name: c.label for c in REGISTRY.values()} == BEFORE["labels"]
    assert [c for c in CONDITIONS if REGISTRY[c].mode == "rl"] == BEFORE["rl_conditions"]
    assert [c for c in CONDITIONS if REGISTRY[c].mode == "search"] == BEFORE["search_conditions"]
    assert list(tables.PRIOR_TABLE) == BEFORE["prior_table"]
    assert list(bench.LEARNERS) == BEFORE["conditions"][1:]


@pytest.mark.parametrize("condition", BEFORE["conditions"])
def test_same_controller_config_as_before(condition):
    """The overrides, and the controller built from them, are exactly those of before."""
    before = BEFORE["overrides"][condition]
    assert CONDITION_OVERRIDES[condition] == before
    got = build_config(condition=condition)
    want = build_config(before)
    assert bytes(got.controller) == bytes(want.controller)
    assert got.to_dict() == want.to_dict()


def test_every_control_exists_and_points_back():
    learners = [c for c in REGISTRY.values() if c.learns]
    controls = [c for c in REGISTRY.values() if not c.learns]
    assert [c.name for c in learners if c.control is None] == ["ico"]  # every learner but ICO has one
    assert len(controls) == len(learners) - 1
    for cond in learners:
        if cond.control is None:
            continue
        control = REGISTRY[cond.control]
        assert control.control_of == cond.name and control.base == cond.name and control.control is None
        assert control.label == cond.label + " control" and control.name == cond.name + "-control"
        assert (control.mode, control.prior, dict(control.overrides)) == (cond.mode, cond.prior, dict(cond.overrides))
        # the control's configuration is its condition's with every update off
        a, b = build_config(condition=control.name).flat(), build_config(condition=cond.name).flat()
        assert a["learn"] is False and b["learn"] is True
        assert {n: v for n, v in a.items() if n != "learn"} == {n: v for n, v in b.items() if n != "learn"}
    for control in controls:
        assert REGISTRY[control.control_of].control == control.name
    # the order of the bench: each control right after its condition
    for i, name in enumerate(CONDITIONS):
        if not REGISTRY[name].learns:
            assert CONDITIONS[i - 1] == REGISTRY[name].control_of


def test_labels_unique_and_modes():
    labels = [c.label for c in REGISTRY.values()]
    assert len(set(labels)) == len(labels)
    for cond in REGISTRY.values():
        assert build_config(condition=cond.name).flat()["mode"] == cond.mode
    assert PRIOR_CONDITIONS == tuple(c for c in CONDITIONS if c != "ico")


ICO = P.PriorInfo(mean=np.array([0.1, 0.2, 0.3, 0.4]), cov=np.diag([1.0, 2.0, 3.0, 4.0]), frame=(1.2, 6.0),
                  n_cells=7, ridge=1e-6, source="/ico", source_commit="abc", source_seed=3)


@pytest.mark.parametrize("condition", [c for c in CONDITIONS if REGISTRY[c].prior is not None and REGISTRY[c].learns])
def test_prior_follows_the_rule(condition):
    """The mean is the ICO mean or 0, the covariance the ICO one, sigma_w^2 I or I, as the rule says;
    provenance only for a prior that takes something from ICO."""
    rule = REGISTRY[condition].prior
    info = P.condition_prior(condition, ICO, std=0.5)
    np.testing.assert_array_equal(info.mean, ICO.mean if rule.mean == "ico" else np.zeros(4))
    cov = {"ico": ICO.cov, "isotropic": 0.25 * np.eye(4), "identity": np.eye(4)}[rule.cov]
    np.testing.assert_array_equal(info.cov, cov)
    assert info.kind == condition and (info.extra["mean_from"], info.extra["cov_from"]) == rule
    assert (info.source == "/ico") is rule.takes_ico
    if rule.takes_ico:
        with pytest.raises(P.PriorError, match="needs an ICO prior"):
            P.condition_prior(condition, None)
    else:
        assert P.condition_prior(condition, None, std=0.5).to_dict() == info.to_dict()


@pytest.mark.parametrize("condition", CONDITIONS)
def test_prior_from_required_exactly_when_the_rule_takes_ico(condition, tmp_path):
    """--prior-from: needed by a condition (or control) whose rule takes from ICO, refused otherwise."""
    rule = REGISTRY[condition].prior
    if rule is not None and rule.takes_ico:
        with pytest.raises(UsageError, match="needs --prior-from"):
            condition_prior(condition, None, P.DEFAULT_FRAME, P.DEFAULT_RIDGE)
    else:
        with pytest.raises(UsageError, match="takes nothing from ICO"):
            condition_prior(condition, tmp_path, P.DEFAULT_FRAME, P.DEFAULT_RIDGE)
        info = condition_prior(condition, None, P.DEFAULT_FRAME, P.DEFAULT_RIDGE)
        assert (info is None) is (rule is None)
        if info is not None:  # a control's prior is its condition's
            assert info.kind == REGISTRY[condition].base


def test_condition_checks_itself():
    with pytest.raises(ValueError, match="unknown mode"):
        Condition("x", "X", "pid")
    with pytest.raises(ValueError, match="bad prior rule"):
        Condition("x", "X", "rl", PriorRule("ico", "diagonal"))
    with pytest.raises(TypeError):
        REGISTRY["rl"].overrides["actor.scale"] = 1  # read-only: edit registry.py
    assert PriorRule("zero", "identity").takes_ico is False and PriorRule("zero", "ico").takes_ico


def test_command_line_choices_come_from_the_registry():
    parser = cli.build_parser()
    assert parser.parse_args(["grid", "--out", "x", "--condition", "search-control"]).condition == "search-control"
    assert parser.parse_args(["sweep", "--prior-from", "i", "--out", "o"]).condition == "ico-rl"
    with pytest.raises(UsageError, match="invalid choice: 'ico'"):
        parser.parse_args(["sweep", "--prior-from", "i", "--out", "o", "--condition", "ico"])


def test_registry_imports_nothing_heavy():
    code = ("import sys, icoac.core.registry, icoac.core.options; "
            "assert not {'numpy', 'icoac.core.binding', 'icoac.core.config'} & set(sys.modules), sorted(sys.modules)")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=Path(__file__).resolve().parents[2])
