# SPDX-License-Identifier: Apache-2.0
"""RL alone's ranking by the sweeps' criterion (icoac.tools.learner_sweeps.ranked_rows): the
highest ICO-failed success; within one point of the best, the spread cells, then fewer median
trials; controls and confirmations left out; rows with identical results counted once."""
import csv
import json

from icoac.tools import learner_sweeps as L

COLUMNS = ("key", "success_rate_mean", "success_rate_sd", "median_trials")


def write_sweep(out, name, selection, condition, fixed, rows):
    d = out / f"{name}-{selection}"
    d.mkdir(parents=True)
    (d / "sweep.json").write_text(json.dumps({"condition": condition, "set": fixed, "seeds": [0, 1],
                                              "max_trials": 1000}))
    with open(d / "sweep.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        for key, mean, median in rows:
            w.writerow({"key": json.dumps(key, sort_keys=True), "success_rate_mean": mean,
                        "success_rate_sd": 0.01, "median_trials": median})


def sweep(out, name, condition, fixed, failed_rows, spread_rows):
    write_sweep(out, name, "ico-failed", condition, fixed, failed_rows)
    write_sweep(out, name, "spread", condition, fixed, spread_rows)


def test_ranking_follows_the_criterion(tmp_path):
    fixed = ["actor.update=posterior", "actor.noise_std=1"]
    a, b, c, d = ({"actor.rate": r} for r in (0.01, 0.03, 0.1, 0.3))
    # b is best on the ICO-failed cells; c is within one point of it and better on the spread
    # cells, so it ranks first; a is 1.5 points under b; d duplicates a's results exactly.
    sweep(tmp_path, "rl-alone-grid", "rl", fixed + ["actor.update=gradient"],
          [(a, 0.485, 100), (b, 0.500, 90), (c, 0.495, 80), (d, 0.485, 100)],
          [(a, 0.60, 50), (b, 0.55, 40), (c, 0.62, 45), (d, 0.60, 50)])
    sweep(tmp_path, "rl-alone-control", "rl-control", fixed, [({"actor.rate": 1}, 0.9, 1)],
          [({"actor.rate": 1}, 0.9, 1)])
    rows = L.ranked_rows(tmp_path, "rl-alone")
    assert [r["setting"]["actor.rate"] for r in rows] == ["0.1", "0.03", "0.01"]
    # the full setting: the sweep's fixed items in order, then the row's
    assert rows[0]["setting"]["actor.update"] == "gradient" and rows[0]["setting"]["actor.noise_std"] == "1"
    assert L.literal_items(rows[0]["setting"]) == ["actor.update=gradient", "actor.rate=0.1"]


def test_ties_on_the_spread_cells_go_to_fewer_trials(tmp_path):
    a, b = {"actor.rate": 0.01}, {"actor.rate": 0.03}
    sweep(tmp_path, "rl-alone-grid", "rl", [], [(a, 0.40, 120), (b, 0.405, 200)], [(a, 0.5, 60), (b, 0.5, 30)])
    assert [r["setting"]["actor.rate"] for r in L.ranked_rows(tmp_path, "rl-alone")] == ["0.01", "0.03"]


def test_confirmations_are_named_by_their_setting():
    items = ["actor.update=mean", "actor.noise_std=12"]
    assert L.confirm_name("rl-alone", items) == L.confirm_name("rl-alone", list(items))
    assert L.confirm_name("rl-alone", items) != L.confirm_name("rl-alone", items[:1])
