# SPDX-License-Identifier: Apache-2.0
"""The PPO and SAC adapters (icoac.studies.baselines.sb3, icoac.tools.rl_baselines): a short
training of each on the Furuta pendulum, the evaluation on every cell against the plant stepped
by hand, the records and the refusals. Needs the [baselines] extra: `make test-baselines` (without
it they fail with the one-line error that names the extra; `make test` leaves them out)."""
import ctypes
import json

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core.config import build_config, parse_sets
from icoac.core.errors import UsageError
from icoac.core.plants import PLANTS
from icoac.gym.plants import ModelParameters, model_start, plant_grid
from icoac.studies import heldout
from icoac.studies.baselines import sb3
from icoac.tools import rl_baselines

pytestmark = pytest.mark.baselines


def furuta(**sets):
    return build_config(parse_sets([f"{k}={v}" for k, v in sets.items()], plant="furuta"), plant="furuta")


@pytest.mark.parametrize("algo", sorted(sb3.ALGORITHMS))
def test_train_and_evaluate(algo):
    cfg = furuta(success_steps=60)
    trained = sb3.train(algo, cfg, seed=3, steps=320)
    assert trained.steps == 320 and trained.episodes >= 1
    lasted, ok = sb3.evaluate(trained.act, cfg, grid_seed=1)
    assert lasted.shape == ok.shape == (1225,)
    assert np.all((lasted >= 1) & (lasted <= 60)) and np.all(lasted[ok] == 60)
    # one cell replayed by hand: the same start, the same deterministic forces, the same end
    cell = int(np.argmax(lasted))
    flag = ctypes.c_int32(0)
    parameters = ModelParameters(cfg.model, float(cfg.run.init_velocity_noise))
    state = model_start(parameters, plant_grid(int(cfg.model.plant), 1)[cell:cell + 1])
    for step in range(1, 61):
        force = float(trained.act(state[None, :4])[0]) * 10.0
        B.check_status(B.lib.icoac_sim_model_step(ctypes.byref(cfg.model), state, force))
        B.check_status(B.lib.icoac_sim_model_failed(ctypes.byref(cfg.model), state, ctypes.byref(flag)))
        if flag.value:
            break
    assert step == lasted[cell] and bool(ok[cell]) == (not flag.value)
    # the same seed trains the same policy
    again = sb3.train(algo, cfg, seed=3, steps=320)
    probe = np.random.default_rng(0).uniform(-0.2, 0.2, (16, 4))
    assert np.array_equal(trained.act(probe), again.act(probe))


def test_actuator_limit_is_the_plants():
    assert sb3.actuator_limit(furuta()) == ("max_voltage", 10.0)
    assert sb3.actuator_limit(furuta(max_voltage=4)) == ("max_voltage", 4.0)
    cart = build_config({}, plant="cart_pole")
    with pytest.raises(UsageError, match=r"max_force = 1e\+06 is no actuator limit; hold it to a real actuator's"):
        sb3.actuator_limit(cart)
    limited = build_config(parse_sets(PLANTS["cart_pole"].limited_sets(), plant="cart_pole"), plant="cart_pole")
    assert sb3.actuator_limit(limited) == ("max_force", B.plant_info("cart_pole")["actuator"]["limit"])


def test_tool_resumes_and_reports(tmp_path, capsys):
    argv = ["--plant", "furuta", "--algos", "ppo", "--seeds", "0", "--steps", "64", "--set", "success_steps=20",
            "--out", str(tmp_path / "out")]
    assert rl_baselines.main(argv + ["--data", str(tmp_path / "data.json")]) == 0
    data = json.loads((tmp_path / "data.json").read_text())
    run = data["algorithms"]["ppo"]["runs"]["0"]
    assert run["steps"] == 64 and len(run["success"]) == 1225 and data["actuator"]["limit"] == 10.0
    assert data["algorithms"]["ppo"]["settings"]["steps"] == 64
    before = (tmp_path / "out" / "ppo" / "seed-0" / "result.json").stat().st_mtime_ns
    assert rl_baselines.main(argv + ["--report"]) == 0  # nothing rerun
    assert (tmp_path / "out" / "ppo" / "seed-0" / "result.json").stat().st_mtime_ns == before
    assert rl_baselines.main(["--plant", "cart_pole", "--out", str(tmp_path / "x"), "--report"]) == 2
    assert "max_force = 1e+06 is no actuator limit" in capsys.readouterr().err
    assert rl_baselines.main(argv + ["--steps", "0"]) == 2


def test_training_starts_only_from_the_given_cells():
    env = sb3.make_env(furuta(), cells=[5, 700])
    first = [int(env.reset(seed=4)[1]["cell"])] + [int(env.reset()[1]["cell"]) for _ in range(40)]
    assert set(first) == {5, 700}
    assert "cell" not in env.reset(options={"state": [0.0, 0.0, 0.1, 0.0]})[1]
    again = sb3.make_env(furuta(), cells=[5, 700])  # the same seed draws the same cells
    assert [int(again.reset(seed=4)[1]["cell"])] + [int(again.reset()[1]["cell"]) for _ in range(40)] == first


def test_tune_ranks_the_settings_on_the_tuning_cells(tmp_path, monkeypatch):
    monkeypatch.setitem(heldout.BASELINE_SPACES, "ppo", {"learning_rate": [2.22425e-4, 1e-3]})
    monkeypatch.setattr(heldout, "tuning_cells", lambda plant: np.array([3, 600, 900]))
    out = tmp_path / "out"
    argv = ["--plant", "furuta", "--algos", "ppo", "--steps", "64", "--set", "success_steps=20", "--out", str(out)]
    assert rl_baselines.main(argv + ["--tune"]) == 0
    data = json.loads((out / "tuning.json").read_text())
    entry = data["algorithms"]["ppo"]
    assert [r["order"] for r in entry["rows"]] == [r["order"] for r in heldout.rank(entry["rows"])]
    assert entry["chosen"] == entry["rows"][0]["setting"] and data["n_tuning_cells"] == 3
    for row in entry["rows"]:
        for seed, rate in zip(heldout.TUNING_SEEDS, row["success_rates"]):
            run = json.loads((out / "tuning" / "ppo" / row["key"] / f"seed-{seed}" / "result.json").read_text())
            assert run["overrides"] == row["setting"] and run["training_cells"] == 3 and run["seed"] == seed
            assert len(run["success"]) == 3 and rate == np.mean([c == "1" for c in run["success"]])
    # two runs at once (--jobs, each a process of its own) train and score the same as one at a time
    parallel = tmp_path / "parallel"
    assert rl_baselines.main(argv[:-1] + [str(parallel), "--tune", "--jobs", "2"]) == 0
    def without_wall(rows):
        return [{k: v for k, v in r.items() if k != "wall_time"} for r in rows]
    rows = json.loads((parallel / "tuning.json").read_text())["algorithms"]["ppo"]["rows"]
    assert without_wall(rows) == without_wall(entry["rows"])
    for row in entry["rows"]:
        for seed in heldout.TUNING_SEEDS:
            one, two = (json.loads((d / "tuning" / "ppo" / row["key"] / f"seed-{seed}" / "result.json").read_text())
                        for d in (out, parallel))
            assert (one["success"], one["lasted"], one["episodes"]) == (two["success"], two["lasted"], two["episodes"])
    # the record (--data): written as the runs finish, and a later run trains none of the runs it holds
    record = tmp_path / "record.json"
    assert rl_baselines.main(argv[:-1] + [str(tmp_path / "first"), "--tune", "--data", str(record)]) == 0
    assert without_wall(json.loads(record.read_text())["algorithms"]["ppo"]["rows"]) == without_wall(entry["rows"])
    assert rl_baselines.main(argv[:-1] + [str(tmp_path / "second"), "--tune", "--data", str(record)]) == 0
    again = json.loads((tmp_path / "second" / "tuning.json").read_text())["algorithms"]["ppo"]
    assert again["rows"] == json.loads(record.read_text())["algorithms"]["ppo"]["rows"]
    assert not (tmp_path / "second" / "tuning").exists()
    assert rl_baselines.main(argv[:-1] + [str(tmp_path / "third"), "--tune", "--data", str(record),
                                          "--set", "success_steps=30"]) == 2
    # --report rewrites the record from the runs it holds, training nothing
    kept = json.loads(record.read_text())
    record.write_text(json.dumps({k: v for k, v in kept.items() if k != "cell_builds"}))
    assert rl_baselines.main(argv[:-1] + [str(tmp_path / "fourth"), "--tune", "--report", "--data", str(record)]) == 0
    rewritten = json.loads(record.read_text())
    assert rewritten["cell_builds"] == kept["cell_builds"] and rewritten["algorithms"] == kept["algorithms"]
    assert rewritten["seeds"] == list(heldout.TUNING_SEEDS) and not (tmp_path / "fourth" / "tuning").exists()
    # the evaluation run with a chosen setting records it
    assert rl_baselines.main(argv + ["--seeds", "0", "--hyper", "learning_rate=1e-3"]) == 0
    run = json.loads((out / "ppo" / "seed-0" / "result.json").read_text())
    assert run["overrides"] == {"learning_rate": 1e-3} and run["training_cells"] == "all"
    # ... and a finished record's choice (--tuned), which a run of other settings does not stand in for
    evaluated = tmp_path / "evaluated.json"
    tuned = argv[:-1] + [str(tmp_path / "tuned"), "--seeds", "0", "--tuned", str(record)]
    assert rl_baselines.main(tuned + ["--data", str(evaluated)]) == 0
    data = json.loads(evaluated.read_text())
    chosen = json.loads(record.read_text())["algorithms"]["ppo"]["chosen"]
    entry = data["algorithms"]["ppo"]
    assert entry["runs"]["0"]["overrides"] == chosen == entry["settings"]["overrides"]
    assert data["tuned"] == {"record": str(record), "chosen": {"ppo": heldout.key(chosen)}}
    assert rl_baselines.main(argv + ["--seeds", "0", "--tuned", str(record), "--report"]) == (
        0 if chosen == {"learning_rate": 1e-3} else 2)
    # the record's table: the choice in bold, first
    lines = rl_baselines.tuning_table(json.loads(record.read_text()))
    assert lines[2].startswith(f"| PPO | **learning_rate {chosen['learning_rate']:g}** |") and len(lines) == 4
    # a record with a setting unfinished has no choice to evaluate
    unfinished = json.loads(record.read_text())
    unfinished["algorithms"]["ppo"]["runs"].popitem()
    (tmp_path / "unfinished.json").write_text(json.dumps(unfinished))
    assert rl_baselines.main(argv + ["--seeds", "0", "--tuned", str(tmp_path / "unfinished.json"), "--report"]) == 2


@pytest.mark.parametrize("bad", [["--hyper", "learning_rate"], ["--hyper", "nonsense=1"], ["--hyper", "gamma=nan"],
                                 ["--algos", "ppo", "sac", "--hyper", "gamma=0.9"],
                                 ["--tune", "--hyper", "gamma=0.9"], ["--tuned", "r.json", "--hyper", "gamma=0.9"]])
def test_bad_hyper_is_a_one_line_error(tmp_path, capsys, bad):
    argv = ["--plant", "furuta", "--out", str(tmp_path / "x"), "--report"]
    if "--algos" not in bad:
        argv += ["--algos", "ppo"]
    assert rl_baselines.main(argv + bad) == 2
    assert "--hyper" in capsys.readouterr().err
