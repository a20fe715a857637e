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
from icoac.core.plants import PLANTS
from icoac.core.registry import CONDITIONS, PRIOR_CONDITIONS, REGISTRY, SWEEP_CONDITIONS, Condition, PriorRule
from icoac.core.signs import linearise

# The condition tables of the harness before the registry (captured from main at ad0bc3e). When a
# condition's overrides change on purpose (registry.py), change them here too.
BEFORE = json.loads((Path(__file__).resolve().parent / "fixtures" / "conditions_before_registry.json").read_text())


# The conditions that came after the registry: fixed policies and optimisers outside the controller.
ADDED = [c.name for c in REGISTRY.values() if c.baseline or c.optimiser is not None]


def test_same_conditions_as_before():
    """The learning conditions and controls as before; the baselines (fixed policies) and the
    optimisers came after."""
    assert ADDED == ["lqr", "cma-es"]
    assert [c for c in CONDITIONS if c not in ADDED] == BEFORE["conditions"]
    assert {c.name: c.control_of for c in REGISTRY.values() if c.control_of} == BEFORE["control_of"]
    assert {c.name: list(c.prior) for c in REGISTRY.values() if c.prior and c.learns and c.name not in ADDED} \
        == BEFORE["prior_rules"]
    assert {c.name: c.label for c in REGISTRY.values() if c.name not in ADDED} == BEFORE["labels"]
    assert [c for c in CONDITIONS if REGISTRY[c].mode == "rl"] == BEFORE["rl_conditions"]
    assert [c for c in CONDITIONS if REGISTRY[c].mode == "search"] == BEFORE["search_conditions"]
    assert list(tables.PRIOR_TABLE) == BEFORE["prior_table"]
    assert list(bench.LEARNERS) == BEFORE["conditions"][1:] + ADDED


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
    controls = [c for c in REGISTRY.values() if c.control_of is not None]
    # every learner but ICO and CMA-ES has one (CMA-ES's is the search control: the same start
    # distribution, never adapted)
    assert [c.name for c in learners if c.control is None] == ["ico", "cma-es"]
    assert len(controls) == len(learners) - 2
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
        if REGISTRY[name].control_of is not None:
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


def _riccati_by_iteration(a, b, q, r, steps=400_000, tol=1e-13):
    """K of the discrete LQR by iterating the Riccati difference equation to its fixed point: an
    algorithm independent of scipy's solver, which the harness uses."""
    p = q.copy()
    for _ in range(steps):
        k = np.linalg.solve(r + b.T @ p @ b, b.T @ p @ a)
        nxt = q + a.T @ p @ (a - b @ k)
        if np.max(np.abs(nxt - p)) <= tol * np.max(np.abs(nxt)):
            return np.linalg.solve(r + b.T @ nxt @ b, b.T @ nxt @ a).ravel()
        p = nxt
    raise AssertionError("the Riccati iteration did not converge")


@pytest.mark.parametrize("plant", list(PLANTS))
def test_lqr_baseline_acts_with_the_plants_lqr_gain(plant):
    """The LQR condition never learns and has no control; it runs ICO mode with every update off
    and its prior mean as w, and that w is the plant's discrete LQR gain (Q = diag(1 / range^2),
    R = 1 / G^2): G w_i sign_i / range_i = -K_i, with K found by iterating the Riccati equation,
    and the gain closes the linearised loop."""
    cond = REGISTRY["lqr"]
    assert cond.baseline and not cond.learns and cond.control is None
    assert "lqr" in PRIOR_CONDITIONS and "lqr" not in SWEEP_CONDITIONS
    cfg = build_config(condition="lqr", plant=plant)
    assert cfg.flat()["learn"] is False and cfg.flat()["mode"] == "ico"
    info = condition_prior("lqr", None, P.DEFAULT_FRAME, P.DEFAULT_RIDGE, plant=plant)
    n = cfg.n_inputs
    ranges = np.array(list(cfg.controller.policy.input_range)[:n])
    signs = np.array(list(cfg.controller.task.input_sign)[:n], dtype=float)
    gain = float(cfg.controller.policy.gain)
    k = -np.asarray(info.mean) * gain * signs / ranges
    a, b = linearise(cfg)
    want = _riccati_by_iteration(a, b, np.diag(1.0 / ranges ** 2), np.array([[1.0 / gain ** 2]]))
    np.testing.assert_allclose(k, want, rtol=1e-6, atol=1e-9)
    assert np.max(np.abs(np.linalg.eigvals(a - b @ k.reshape(1, n)))) < 1.0
    assert info.extra["mean_from"] == "lqr" and info.source is None


def test_lqr_baseline_grid_keeps_its_w(tmp_path):
    """A grid of the LQR condition acts with the LQR w in every cell and learns nothing: every
    cell's final weights are the prior mean (in the controller's real type)."""
    from icoac.core import binding as B
    from icoac.studies.conditions import run_condition
    info = condition_prior("lqr", None, P.DEFAULT_FRAME, P.DEFAULT_RIDGE)
    cells, record, _ = run_condition(condition="lqr", out=tmp_path / "lqr", seed=0, threads=1,
                                     overrides={"max_trials": 3, "success_steps": 500}, cell_spec=[0, 300, 612, 900],
                                     info=info, progress=False)
    w = np.asarray(info.mean, dtype=B.real_dtype).astype(float)
    np.testing.assert_array_equal(cells["weights"][:, :4], np.tile(w, (4, 1)))
    assert record["config"]["controller"]["learn"] is False and np.all(cells["trials"] >= 1)
    assert cells["outcome"][2] == B.SUCCESS  # cell 612, the upright at the centre
