# SPDX-License-Identifier: Apache-2.0
"""docs/results.md's tables are the committed summaries (docs/data/*.json) formatted by
icoac.tools.results_tables: the page must agree with them, and a changed number must be caught."""
import json
import re
import shutil
from pathlib import Path

import pytest

from icoac.tools import results_tables as RT

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "results.md"
DATA = ROOT / "docs" / "data"


def blocks(text):
    return [(m.group("name"), m.group("file")) for m in RT.BLOCK.finditer(text)]


def test_results_page_has_the_tables_of_its_summaries():
    found = blocks(PAGE.read_text())
    assert {name for name, _ in found} >= {"comparison", "priors", "within", "trials-quantiles"}
    for _, files in found:
        for file in files.split(","):
            assert (DATA / file).is_file(), file


def test_results_page_agrees_with_its_summaries():
    assert RT.main([str(PAGE), "--check"]) == 0


def test_a_changed_number_is_caught(tmp_path):
    """One success rate of one summary moved by a point: the check fails, and --update rewrites
    exactly the blocks of that summary."""
    page = tmp_path / "results.md"
    data = tmp_path / "data"
    shutil.copy(PAGE, page)
    shutil.copytree(DATA, data)
    file = next(f for _, f in blocks(page.read_text()) if "," not in f)
    summary = json.loads((data / file).read_text())
    entry = summary["aggregate"]["ico-rl"]["success_rate"]
    entry["mean"] += 0.01
    (data / file).write_text(json.dumps(summary))
    assert RT.main([str(page), "--data", str(data), "--check"]) == 1
    before = page.read_text()
    assert RT.main([str(page), "--data", str(data), "--update"]) == 0
    after = page.read_text()
    assert after != before
    assert RT.main([str(page), "--data", str(data), "--check"]) == 0
    # only the tables changed, not the prose around them
    strip = lambda t: RT.BLOCK.sub("", t)  # noqa: E731
    assert strip(after) == strip(before)


def test_unknown_table_is_refused(tmp_path):
    page = tmp_path / "results.md"
    page.write_text("<!-- table: nonsense bench-default.json -->\n<!-- end table -->\n")
    with pytest.raises(SystemExit, match="unknown table"):
        RT.render(page.read_text(), DATA)


def test_compare_data_flags_a_change_beyond_the_seed_spread():
    """compare_data: a summary against itself changes nothing; a rate moved by more than its sd is
    flagged, one moved by less is not."""
    import copy
    import json
    from pathlib import Path

    from icoac.tools import compare_data

    before = json.loads((Path(__file__).resolve().parents[2] / "docs" / "data" / "bench-default.json").read_text())
    assert all(r["within"] and r["change"] == 0 for r in compare_data.rows(before, before))
    after = copy.deepcopy(before)
    ico = after["aggregate"]["ico"]["success_rate"]
    ico["mean"] += 3 * max(ico["sd"], 1e-3)
    rl = after["aggregate"]["rl"]["success_rate"]
    rl["mean"] += 0.5 * rl["sd"]
    flagged = {(r["condition"], r["rate"]) for r in compare_data.rows(before, after) if not r["within"]}
    assert flagged == {("ico", "all cells")}
    assert "| ico | all cells |" in compare_data.markdown(before, after)


def _entry(rate, lo, trials, cap=1000, ico_trials=None):
    cost = {"trials": {"mean": trials}, "simulated_time": {"mean": 1.0}, "wall_time": {"mean": 1.0}}
    if ico_trials is not None:
        cost["with_ico"] = {k: {"mean": v["mean"] + ico_trials} for k, v in cost.items()}
    return {"max_trials": cap, "success_rate": {"mean": rate, "sd": 0.0, "ci95": [lo, 2 * rate - lo]}, "cost": cost}


def test_the_method_to_use_is_the_cheapest_within_the_best_interval():
    """The highest rate sets the interval; of the conditions inside it the one with the fewest trials
    for the whole grid wins, its ICO phase counted; one outside it does not, however cheap; ICO at
    another cap is not a candidate."""
    from icoac.studies import tables
    agg = {"ico": _entry(0.99, 0.98, 1, cap=100000),
           "ico-rl": _entry(0.95, 0.93, 100, ico_trials=10**7),
           "ico-search": _entry(0.96, 0.94, 50, ico_trials=10**7),   # the highest: interval [0.94, 0.98]
           "search": _entry(0.945, 0.93, 500),                       # inside it
           "search-control": _entry(0.95, 0.93, 400),                # inside it, fewer trials
           "lqr": _entry(0.90, 0.88, 10)}                            # the cheapest, outside it
    assert tables.recommended(agg) == "search-control"
    agg["search"]["cost"]["trials"]["mean"] = 300
    assert tables.recommended(agg) == "search"
    lines = tables.headline_table([{"aggregate": agg}, {"plant": "furuta", "aggregate": agg}])
    assert [line.split(" | ")[1] for line in lines[2:]] == ["**search** (use)", "ICO->RL", "search control", "LQR"] * 2
    assert "1e+07" in lines[3]   # ICO->RL's row counts its ICO phase
    del agg["ico-search"]["success_rate"]["ci95"]
    assert tables.recommended(agg) == "ico-search"  # without an interval: the highest


def test_policies_trained_once_join_the_headline_of_their_plant_and_settings():
    """PPO and SAC rows (an rl-baselines data file) follow the bench rows of the same plant and --set,
    with their training cost; a file of other settings adds nothing; the rl-baselines table pairs
    them with the bench's conditions."""
    from icoac.studies import tables
    from icoac.tools import rl_baselines
    agg = {"ico-rl": _entry(0.95, 0.93, 100), "search": _entry(0.96, 0.94, 50)}
    bench = {"plant": "cart_pole", "set": ["max_force=10"], "aggregate": agg}
    paired = {"points": -3.5, "ci95": [-5.0, -2.0], "p_max": 0.001}
    trained = {"plant": "cart_pole", "set": ["max_force=10"], "algorithms": {"ppo": {
        "settings": {"algorithm": "PPO", "steps": 200000, "zoo_steps": 1000000},
        "runs": {"0": {}, "1": {}}, "all": {"mean": 0.5, "sd": 0.1, "ci95": [0.45, 0.55]},
        "heldout": {"mean": 0.49}, "paired": {"ico-rl": paired},
        "cost": {"trials": {"mean": 321.0}, "steps": {"mean": 2e5}, "simulated_time": {"mean": 2e3},
                 "wall_time": {"mean": 250.0}}}}}
    lines = tables.headline_table([bench, trained, {**trained, "set": []}])
    assert [line.split(" | ")[1] for line in lines[2:]] == ["**search** (use)", "ICO->RL", "PPO (trained once)"]
    assert lines[-1].startswith("| cart_pole (max_force=10) |") and "| 321 | 2e+03 | 250 |" in lines[-1]
    # the untuned PPO and SAC are not set beside a bench of held-out tuned settings
    tuned = tables.headline_table([{**bench, "tuned": {"chosen": {}}}, trained])
    assert [line.split(" | ")[1] for line in tuned[2:]] == ["**search** (use)", "ICO->RL"]
    # PPO and SAC held-out tuned: beside the tuned bench when there is one, else beside the untuned
    ppo_tuned = {**trained, "tuned": {"record": "r.json", "chosen": {"ppo": "gamma=0.99"}}}
    both = tables.headline_table([bench, {**bench, "tuned": {"chosen": {"ico": "rate=0.003"}}}, trained, ppo_tuned])
    assert [line.split(" | ")[1] for line in both[2:]] == ["**search** (use)", "ICO->RL", "PPO (trained once)",
                                                           "**search** (use)", "ICO->RL",
                                                           "PPO (held-out tuned, trained once)"]
    assert both[-1].startswith("| cart_pole (max_force=10, held-out tuned) | PPO")
    alone = tables.headline_table([bench, ppo_tuned])
    assert [line.split(" | ")[1] for line in alone[2:]] == ["**search** (use)", "ICO->RL",
                                                            "PPO (held-out tuned, trained once)"]
    rows = rl_baselines.table(trained)
    assert "against ICO->RL (points)" in rows[0] and "-3.5 (-5.0 to -2.0), p ≤ 0.001" in rows[2]
    assert "| 2e+05 (1e+06) | 2 |" in rows[2]


def test_a_block_over_several_summaries(tmp_path):
    page = "<!-- table: headline bench-default.json,bench-default-furuta.json -->\n<!-- end table -->\n"
    text = RT.render(page, DATA)
    assert text.count("*From docs/data:") == 2 and "| furuta |" in text and "| cart_pole |" in text
    with pytest.raises(SystemExit, match="unknown table"):
        RT.render("<!-- table: comparison bench-default.json,bench-default-furuta.json -->\n<!-- end table -->\n",
                  DATA)


def test_the_baseline_tuning_table_ranks_only_a_finished_algorithm():
    """The PPO/SAC tuning record's table: while settings are unfinished, the finished ones in the
    space's order and the count left; once all are in, best first by the criterion, the choice in
    bold (ties to the Zoo's start, the space's first setting)."""
    from icoac.studies import heldout
    from icoac.tools import rl_baselines
    settings = heldout.baseline_settings("ppo")

    def run(rate):
        return {"success_rate": rate, "train_wall_time": 100.0, "eval_wall_time": 5.0}
    rates = {heldout.key(s): 0.5 for s in settings}
    rates[heldout.key(settings[3])] = 0.9
    runs = {heldout.key(settings[1]): {"100": run(0.2), "101": run(0.4)},
            heldout.key(settings[0]): {"100": run(0.1), "101": run(0.1)}}
    record = {"seeds": [100, 101], "algorithms": {"ppo": rl_baselines._ranking("ppo", 200000, runs)}}
    lines = rl_baselines.tuning_table(record)
    assert [line.split(" | ")[4] for line in lines[2:4]] == ["10.0 %", "30.0 %"]  # the space's order
    assert lines[4] == "| PPO | 10 of 12 settings unfinished | | | | |" and "**" not in "".join(lines)
    runs = {key: {"100": run(rate), "101": run(rate)} for key, rate in rates.items()}
    record["algorithms"]["ppo"] = rl_baselines._ranking("ppo", 200000, runs)
    lines = rl_baselines.tuning_table(record)
    assert len(lines) == 2 + 12 and "| **90.0 %** | 210 |" in lines[2]
    assert lines[2].split(" | ")[1] == "**" + ", ".join(f"{k} {v:g}" for k, v in sorted(settings[3].items())) + "**"
    assert lines[3].split(" | ")[1] == ", ".join(f"{k} {v:g}" for k, v in sorted(settings[0].items()))  # tie: first
