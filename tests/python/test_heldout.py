# SPDX-License-Identifier: Apache-2.0
"""The held-out tuning protocol (icoac.studies.heldout) and its runner (icoac.tools.heldout_tuning):
a fixed split disjoint from evaluation, the same budget for every learner with its default first,
the committed criterion, and the runner's priors from ICO's chosen grids."""
import json

import numpy as np
import pytest

from icoac.core import metrics, results
from icoac.core.config import build_config
from icoac.core.plants import PLANTS
from icoac.core.registry import REGISTRY
from icoac.studies import bench, heldout as H
from icoac.studies import prior as P
from icoac.studies.conditions import condition_prior, run_condition
from icoac.tools import heldout_tuning as T


@pytest.mark.parametrize("plant", sorted(PLANTS))
def test_split_is_fixed_and_held_out(plant):
    if not PLANTS[plant].has_task:
        pytest.skip(f"{plant} has no task")
    cells = H.tuning_cells(plant)
    assert np.array_equal(cells, H.tuning_cells(plant)) and np.all(np.diff(cells) > 0)
    held = H.heldout_mask(plant)
    assert cells.size == round(H.TUNING_FRACTION * held.size) and not held[cells].any()
    assert np.count_nonzero(held) == held.size - cells.size


def test_splits_differ_by_plant_and_seeds_are_disjoint():
    assert not np.array_equal(H.tuning_cells("cart_pole"), H.tuning_cells("furuta"))
    evaluation = set(range(bench.PROFILES["default"]["seeds"]))
    assert not evaluation & set(H.TUNING_SEEDS)


@pytest.mark.parametrize("plant", sorted(p for p in PLANTS if PLANTS[p].has_task))
@pytest.mark.parametrize("learner", list(H.LEARNERS))
def test_same_budget_default_first_every_setting_valid(learner, plant):
    settings = H.settings(learner, plant)
    assert len(settings) == H.SETTINGS and len({H.key(s) for s in settings}) == H.SETTINGS
    first = build_config(settings[0], condition=learner, plant=plant)
    assert bytes(first.controller) == bytes(build_config(condition=learner, plant=plant).controller)
    for s in settings:
        build_config(s, condition=learner, plant=plant)  # ConfigError if the C check refused one


def test_the_cart_poles_space_is_the_one_its_runs_used():
    """The cart-pole's tuning ran with the spaces committed in 22d5b07, the Furuta's with those of
    e3b0352: deriving them from each plant's defaults leaves them as they were."""
    gradient = {"actor.update": "gradient", "actor.rate": 0.001}
    mean = {"actor.update": "mean", "actor.likelihood_std": 0.1, "actor.scale": 0.1}
    cart = H.spaces("cart_pole")
    assert cart["ico"] == {"ico.rate": [1e-4, 1e-5, 3e-5, 3e-4, 1e-3, 3e-3], "ico.timing": ["code", "literal"]}
    for learner, reading, noise in (("ico-rl", [gradient, mean], [3, 1, 2, 5, 8, 12]),
                                    ("ico-mean-rl", [gradient, mean], [3, 1, 2, 5, 8, 12]),
                                    ("rl-ico-cov", [mean, gradient], [5, 1, 2, 3, 8, 12]),
                                    ("rl", [mean, gradient], [12, 1, 2, 3, 5, 8])):
        assert cart[learner] == {"reading": reading, "actor.noise_std": noise, "actor.explore_ticks": [1000]}
    assert cart["search"] == {"search.cov_scale": [4, 1, 2, 8, 16, 64], "search.floor": [1, 0.1]}
    assert H.settings("ico")[:2] == [{"ico.rate": 1e-4, "ico.timing": "code"}, {"ico.rate": 1e-4, "ico.timing": "literal"}]
    furuta = H.spaces("furuta")
    assert furuta["ico"]["ico.rate"] == [0.01, 0.001, 0.003, 0.03, 0.1, 0.3]
    assert furuta["ico-rl"]["actor.noise_std"] == [1, 0.3, 0.5, 2, 3, 5] and furuta["ico-rl"]["reading"] == [mean, gradient]
    assert furuta["rl"]["actor.noise_std"] == [3, 0.3, 0.5, 1, 2, 5]
    assert H.spaces("double_cart_pole")["ico"]["ico.rate"] == [1, 0.1, 0.3, 0.03, 0.01, 0.003]


@pytest.mark.parametrize("algo", list(H.BASELINE_SPACES))
def test_baselines_same_budget_zoo_first(algo):
    """PPO's and SAC's spaces: SETTINGS settings each, the RL Zoo's start first, every name one the
    algorithm's run takes (the Zoo's own or a Stable-Baselines3 default it leaves)."""
    from icoac.studies.baselines import sb3
    settings = H.baseline_settings(algo)
    assert len(settings) == H.SETTINGS and len({H.key(s) for s in settings}) == H.SETTINGS
    zoo = dict(sb3.ALGORITHMS[algo].hyper)
    sb3_defaults = {"learning_rate": 3e-4, "gamma": 0.99}
    assert all(settings[0][k] == zoo.get(k, sb3_defaults.get(k)) for k in settings[0])


def test_every_learner_is_tuned():
    learners = {c.name for c in REGISTRY.values() if c.learns}
    assert set(H.LEARNERS) == learners


def test_criterion():
    rows = [{"order": 0, "success_rate": 0.90, "median_trials": 10.0},
            {"order": 1, "success_rate": 0.95, "median_trials": 50.0},
            {"order": 2, "success_rate": 0.95, "median_trials": 20.0},
            {"order": 3, "success_rate": 0.95, "median_trials": 20.0},
            {"order": 4, "success_rate": 0.95, "median_trials": None}]
    assert [r["order"] for r in H.rank(rows)] == [2, 3, 1, 4, 0]


def test_report_runs_nothing_and_names_what_is_pending(tmp_path, monkeypatch):
    monkeypatch.setattr(H, "tuning_cells", lambda plant: np.array([600, 610]))
    assert T.main(["--out", str(tmp_path), "--report", "--quiet"]) == 0
    data = json.loads((tmp_path / "tuning.json").read_text())
    assert all("pending" in t for t in data["learners"].values()) and not (tmp_path / "ico").exists()
    assert "unfinished (0 of 12 settings finished)" in "\n".join(T.choices_table(data))


def test_runner_takes_icos_chosen_grids(tmp_path, monkeypatch):
    """Two settings each for ICO and ICO->RL on six tuning cells at small caps: the ranking is the
    criterion's, and ICO->RL's prior comes from ICO's chosen setting, seed for seed."""
    monkeypatch.setattr(H, "tuning_cells", lambda plant: np.array([560, 600, 610, 612, 640, 700]))
    monkeypatch.setattr(H, "spaces", lambda plant: {"ico": {"ico.rate": [1e-4, 1e-3]},
                                                    "ico-rl": {"actor.noise_std": [3, 1]}})
    monkeypatch.setitem(bench.PROFILES, "default", {**bench.PROFILES["default"],
                                                     "ico": {"max_trials": 3000, "success_steps": 1000},
                                                     "rl": {"max_trials": 200, "success_steps": 1000}})
    assert T.main(["--out", str(tmp_path), "--learners", "ico-rl", "--quiet"]) == 0
    data = json.loads((tmp_path / "tuning.json").read_text())
    ico = data["learners"]["ico"]
    assert [r["key"] for r in ico["rows"]] == ["ico.rate=0.0001", "ico.rate=0.001"]
    best = H.rank(ico["rows"])[0]
    assert ico["chosen_key"] == best["key"]
    for seed in H.TUNING_SEEDS:
        _, rec = results.load(tmp_path / "ico-rl" / "actor.noise_std=1" / f"seed-{seed}")
        assert rec["cells"] == [560, 600, 610, 612, 640, 700] and rec["seed"] == seed
        assert rec["prior_info"]["source"] == str((tmp_path / "ico" / ico["chosen_key"] / f"seed-{seed}").resolve())
    assert "Chosen:" in (tmp_path / "summary.md").read_text()
    table = T.choices_table(data)
    assert len(table) == 4 and table[2].startswith("| ICO |") and table[3].startswith("| ICO->RL |")


def test_evaluation_against_the_bench_defaults(tmp_path, monkeypatch):
    """--evaluate: ICO's choice runs on every cell with the bench's seeds, ICO->RL from the
    evaluated ICO grids; the table sets the held-out and all-cell rates beside the bench's."""
    caps = {"ico": {"max_trials": 200, "success_steps": 200}, "rl": {"max_trials": 20, "success_steps": 200}}
    monkeypatch.setattr(H, "tuning_cells", lambda plant: np.array([171, 200, 612, 613, 1020, 1053]))
    monkeypatch.setattr(H, "spaces", lambda plant: {"ico": {"ico.rate": [1e-4, 1e-2]}, "ico-rl": {"actor.noise_std": [3]}})
    monkeypatch.setitem(bench.PROFILES, "default", {**bench.PROFILES["default"], "seeds": 2, **caps})
    bench_dir = tmp_path / "bench"
    for seed in (0, 1):
        run_condition(condition="ico", out=bench.seed_dir(bench_dir, "ico", seed), seed=seed, threads=2,
                      overrides=caps["ico"], progress=False)
        info = condition_prior("ico-rl", bench.seed_dir(bench_dir, "ico", seed), P.CENTRAL, P.DEFAULT_RIDGE)
        run_condition(condition="ico-rl", out=bench.seed_dir(bench_dir, "ico-rl", seed), seed=seed, threads=2,
                      overrides=caps["rl"], info=info, progress=False)
    out = tmp_path / "tuning"
    assert T.main(["--out", str(out), "--learners", "ico-rl", "--evaluate", "--bench", str(bench_dir),
                   "--bench-data", str(tmp_path / "tuned.json"), "--quiet"]) == 0
    data = json.loads((out / "tuning.json").read_text())
    ev = data["evaluation"]
    assert ev["seeds"] == [0, 1] and ev["n_heldout"] == 1219
    for name in ("ico", "ico-rl"):
        e = ev["learners"][name]
        default = [metrics.success_mask(results.load(bench.seed_dir(bench_dir, name, s))[0]) for s in (0, 1)]
        assert e["all"]["default"]["mean"] == pytest.approx(np.mean(default))
        held = H.heldout_mask("cart_pole")
        assert e["heldout"]["default"]["mean"] == pytest.approx(np.mean([m[held] for m in default]))
    assert not data["learners"]["ico"]["default_kept"]  # 1e-2 learns more within 200 trials
    assert ev["learners"]["ico"]["rerun"] and ev["learners"]["ico-rl"]["rerun"]
    _, rec = results.load(out / "evaluation" / "ico-rl" / "seed-1")
    assert rec["prior_info"]["source"] == str((out / "evaluation" / "ico" / "seed-1").resolve())
    assert len(T.evaluation_table(data)) == 4
    # the rerun learner's control ran with its choice and prior; the tuned bench links every grid
    _, crec = results.load(out / "evaluation" / "ico-rl-control" / "seed-1")
    assert crec["prior_info"]["source"] == rec["prior_info"]["source"] and ev["learners"]["ico-rl"]["control_rerun"]
    assert crec["config"]["controller"]["learn"] is False and rec["config"]["controller"]["learn"] is True
    assert crec["config"]["controller"]["actor"] == rec["config"]["controller"]["actor"]
    assembled = out / "evaluation" / "bench"
    for name in ("ico", "ico-rl", "ico-rl-control"):
        assert (assembled / name / "seed-0").resolve() == (out / "evaluation" / name / "seed-0").resolve()
    tuned = json.loads((tmp_path / "tuned.json").read_text())
    assert tuned["tuned"]["chosen"]["ico"] == data["learners"]["ico"]["chosen_key"]
    assert set(tuned["aggregate"]) >= {"ico", "ico-rl", "ico-rl-control"}
    assert tuned["aggregate"]["ico-rl"]["success_rate"]["mean"] == pytest.approx(ev["learners"]["ico-rl"]["all"]["chosen"]["mean"])
    from icoac.studies import tables
    assert tables._plant_label(tuned) == "cart_pole (held-out tuned)"


def test_prior_reading_table_in_the_plants_unit():
    from icoac.tools import heldout_tuning
    rows = [{"setting": {"actor.update": "mean", "actor.noise_std": 0.5}, "success_rate": 0.25}]
    furuta = heldout_tuning.prior_reading_table({"plant": "furuta", "learners": {"rl": {"rows": rows}}})
    assert "σ_u = 0.5 V" in furuta[0] and "| 25.0 |" in furuta[3]
    cart = heldout_tuning.prior_reading_table({"plant": "cart_pole", "learners": {"rl": {"rows": rows}}})
    assert "σ_u = 0.5 N" in cart[0]


def test_a_tuning_goes_on_from_its_data_record(tmp_path, monkeypatch, capsys):
    """--data is the record a later run starts from: its settings are not run again, ICO's chosen
    grids (the priors of the learners after it) are rerun and must give the recorded rates, and a
    record of another protocol is refused."""
    monkeypatch.setattr(H, "tuning_cells", lambda plant: np.array([560, 600, 610, 612]))
    monkeypatch.setattr(H, "spaces", lambda plant: {"ico": {"ico.rate": [1e-4, 1e-3]},
                                                    "ico-rl": {"actor.noise_std": [3, 1]}})
    monkeypatch.setitem(bench.PROFILES, "default", {**bench.PROFILES["default"],
                                                     "ico": {"max_trials": 2000, "success_steps": 1000},
                                                     "rl": {"max_trials": 100, "success_steps": 1000}})
    record = tmp_path / "record.json"
    args = ["--learners", "ico-rl", "--data", str(record), "--quiet"]
    assert T.main(["--out", str(tmp_path / "first"), *args]) == 0
    first = json.loads(record.read_text())
    assert T.main(["--out", str(tmp_path / "second"), *args]) == 0
    second = json.loads(record.read_text())
    assert second["learners"] == first["learners"]
    ran = sorted(p.parent.name + "/" + p.name for p in (tmp_path / "second").glob("*/*") if p.is_dir())
    assert ran == ["ico/" + first["learners"]["ico"]["chosen_key"]]  # only ICO's chosen grids, for the priors
    chosen = next(r for r in first["learners"]["ico"]["rows"] if r["key"] == first["learners"]["ico"]["chosen_key"])
    chosen["success_rates"] = [0.5, 0.5]
    record.write_text(json.dumps(first))
    assert T.main(["--out", str(tmp_path / "third"), *args]) == 2
    assert "not the recorded" in capsys.readouterr().err
    first["protocol"]["tuning_seeds"] = [7, 8]
    record.write_text(json.dumps(first))
    assert T.main(["--out", str(tmp_path / "fourth"), *args]) == 2
    assert "another plant's or protocol's" in capsys.readouterr().err
