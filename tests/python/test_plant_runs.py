# SPDX-License-Identifier: Apache-2.0
"""The benchmark on registry plants (harness --plant): configurations and records by plant, the
plant's grid in every metric and map, the task settings and their sweep, refusals by name."""
import ctypes
import json
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac import cli
from icoac.core import config, geometry, grid, metrics, plants, results
from icoac.studies import prior as P
from icoac.core.config import build_config, config_from_dict
from icoac.tools import plant_sweeps

REPO = Path(__file__).resolve().parents[2]
TINY_ARGS = ["--max-trials", "30", "--success-steps", "200", "--quiet"]
CELLS = "600-605"


def main(capsys, *args):
    rc = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


def one_line_error(rc, err):
    assert rc == 2 and "Traceback" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("icoac: error: "), err
    return lines[0]


def test_cart_pole_config_unchanged_by_the_plant_argument():
    for condition in (None, "ico-rl", "rl", "search"):
        assert build_config(condition=condition).to_dict() == \
            build_config(condition=condition, plant="cart_pole").to_dict()
    cfg = build_config()
    assert cfg.plant_name == "cart_pole" and cfg.model.plant == B.CART_POLE
    # recorded as every plant: name, dt, integrator, its parameters by name
    assert cfg.to_dict()["plant"] == {"name": "cart_pole", "dt": 0.01, "integrator": "euler",
                                      **{p["name"]: p["value"] for p in B.plant_info("cart_pole")["params"]}}


def test_furuta_config_has_its_task_and_learner_settings():
    cfg = build_config(condition="ico-rl", plant="furuta", overrides={"pendulum_damping": 1e-4, "dt": 0.005})
    d = cfg.to_dict()
    assert d["plant"]["name"] == "furuta" and d["plant"]["pendulum_damping"] == 1e-4 and d["plant"]["dt"] == 0.005
    task = B.Config()
    plants.spec("furuta").task_config(task)
    assert bytes(task.policy) == bytes(cfg.controller.policy) and bytes(task.task) == bytes(cfg.controller.task)
    assert B.plant_info("furuta")["task"]["learners"] == [["ico-rl", "ico-mean-rl"], ["rl", "rl-ico-cov"]]
    assert cfg.controller.actor.noise_std == 1.0 and build_config(condition="ico-rl").controller.actor.noise_std != 1.0
    # the control takes its learner's noise; a user's --set wins over both
    ctrl = build_config(condition="ico-rl-control", plant="furuta", overrides={"policy.gain": 2})
    assert ctrl.to_dict()["controller"]["actor"]["noise_std"] == d["controller"]["actor"]["noise_std"]
    assert ctrl.controller.policy.gain == 2
    # the record reads back to the same configuration
    assert config_from_dict(d).to_dict() == d


def test_a_plant_without_a_task_is_refused(monkeypatch):
    bare = replace(plants.PLANTS["furuta"], task_source=None)
    monkeypatch.setitem(plants.PLANTS, "furuta", bare)
    with pytest.raises(B.ConfigError, match="plant furuta has no controller task"):
        build_config(plant="furuta")
    # C refuses it too: an index out of the registry has no task
    cfg = B.Config()
    assert B.lib.icoac_sim_plant_task(B.lib.icoac_sim_plant_count(), None, ctypes.byref(cfg)) == B.SIM_ERR_BAD_PLANT
    assert B.lib.icoac_sim_plant_learner(-1, b"rl", ctypes.byref(cfg)) == B.SIM_ERR_BAD_PLANT


@pytest.mark.parametrize("overrides, words", [
    ({"x_limit": 3.0}, ["furuta", "x_limit"]),
    ({"arm_mass": -3.0}, ["arm_mass=-3.0"]),
    ({"no_such": 1.0}, ["no_such"]),
])
def test_bad_plant_parameters_are_named(overrides, words):
    with pytest.raises(B.ConfigError) as exc:
        build_config(overrides, plant="furuta")
    for w in words:
        assert w in str(exc.value)


def test_task_of_another_size_and_unknown_plants_are_refused_by_name(capsys, tmp_path):
    line = one_line_error(*main(capsys, "grid", "--plant", "double_cart_pole", "--out", tmp_path / "d",
                                "--set", "task.n_inputs=4", "--set", "task.n_rules=4", *TINY_ARGS)[::2])
    assert "double_cart_pole" in line and "task.n_inputs=4" in line and "6 state components" in line
    line = one_line_error(*main(capsys, "grid", "--plant", "nope", "--out", tmp_path / "n", *TINY_ARGS)[::2])
    assert "nope" in line and "furuta" in line
    assert not (tmp_path / "d").exists() and not (tmp_path / "n").exists()


def test_plant_grid_geometry():
    fur = geometry.of("furuta")
    info = B.plant_info("furuta")
    cells = grid.plant_grid("furuta", 0)
    assert cells.size == fur.cells == info["rows"]["count"] * info["cols"]["count"]
    rows, cols = fur.grid_index(cells)
    k = np.arange(cells.size)
    assert np.array_equal(rows, k // fur.cols) and np.array_equal(cols, k % fur.cols)
    assert fur.on_grid(cells).all() and not geometry.on_grid(cells).all()
    assert fur.interior_mask(cells).sum() == fur.n_interior == (fur.rows - 2) * (fur.cols - 2)
    assert (fur.col_unit, fur.row_unit) == ("deg", "deg")
    assert geometry.CART_POLE.central_frame() == (1.2, 6.0)  # the cart-pole's default prior frame
    assert fur.central_frame() == (45.0, 6.0)
    # the summary's interior follows the plant's grid
    cells["outcome"] = B.FAILED
    assert metrics.summary(cells, fur)["n_interior"] == fur.n_interior


def test_prior_frame_of_the_plant():
    fur = geometry.of("furuta")
    cells = grid.plant_grid("furuta", 0)
    cells["outcome"] = B.SUCCESS
    cells["weights"][:, :4] = np.arange(cells.size)[:, None] * np.array([1.0, 2.0, 3.0, 4.0]) / cells.size
    info = P.compute(cells, P.CENTRAL, grid=fur)
    col_deg, row_deg = np.degrees(cells["x0"]), np.degrees(cells["theta0"])
    inside = (np.abs(col_deg) <= 45.0 + 1e-9) & (np.abs(row_deg) <= 6.0 + 1e-9)
    assert info.n_cells == int(inside.sum()) and info.frame == (45.0, 6.0)
    assert info.to_dict()["frame"] == {"theta0_abs_max_deg": 45.0, "alpha0_abs_max_deg": 6.0}
    assert np.allclose(info.mean, cells["weights"][inside][:, :4].mean(axis=0))


def test_grid_command_records_and_resumes_by_plant(capsys, tmp_path):
    out = tmp_path / "fur"
    rc, _, err = main(capsys, "grid", "--plant", "furuta", "--out", out, "--cells", CELLS, *TINY_ARGS)
    assert rc == 0, err
    cells, record = results.load(out)
    assert record["config"]["plant"]["name"] == "furuta" and results.record_plant(record) == "furuta"
    assert geometry.of("furuta").on_grid(cells).all()
    expected = grid.make_cells(0, grid.parse_cell_indices(CELLS, geometry.of("furuta").cells), plant="furuta")
    assert np.array_equal(cells["x0"], expected["x0"]) and np.array_equal(cells["theta0"], expected["theta0"])
    # the engine through the harness is the C engine on the model
    cfg = config_from_dict(record["config"])
    again = grid.make_cells(0, grid.parse_cell_indices(CELLS, geometry.of("furuta").cells), plant="furuta")
    grid.run_grid(cfg, again, threads=1, progress=False)
    assert again.tobytes() == cells.tobytes()
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    line = one_line_error(*main(capsys, "grid", "--out", out, "--cells", CELLS, *TINY_ARGS)[::2])
    assert "plant name 'furuta' != 'cart_pole'" in line
    line = one_line_error(*main(capsys, "grid", "--plant", "furuta", "--out", out, "--cells", CELLS,
                                "--set", "gravity=9.7", *TINY_ARGS)[::2])
    assert "plant gravity 9.81 != 9.7" in line
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
    rc, _, err = main(capsys, "grid", "--out", out, "--resume", "--quiet")
    assert rc == 0, err


def test_ceiling_of_a_plant_records_it(capsys, tmp_path):
    w = "3.37,2.08,20.8,11.1"
    rc, _, err = main(capsys, "ceiling", "--plant", "furuta", "--out", tmp_path / "c", "--w", w, "--cells", CELLS,
                      "--protocol", "first", "--success-steps", "300", "--quiet")
    assert rc == 0, err
    record = json.loads((tmp_path / "c" / "ceiling.json").read_text())
    assert record["settings"]["plant"] == "furuta"
    assert "G = 1 V" in (tmp_path / "c" / "ceiling.md").read_text()


def test_sweep_ranking_and_the_furuta_choice():
    rows = [{"key": "a", "seed": "0", "success_rate": "0.300", "median_trials": "900"},
            {"key": "b", "seed": "0", "success_rate": "0.295", "median_trials": "100"},
            {"key": "c", "seed": "0", "success_rate": "0.10", "median_trials": ""}]
    assert [r["key"] for r in plant_sweeps.ranked(rows)] == ["b", "a", "c"]  # within one point: fewer trials
    # each swept plant's C task (its knobs' defaults) is the choice its sweep's summary records, and
    # its learner settings the learner sweeps' choices
    for plant in plant_sweeps.TASK_SPACES:
        text = (REPO / "docs" / f"sweeps-{plant}.md").read_text()
        choice = plant_sweeps.setting_of(re.search(r"## Choice\s+`([^`]+)`", text).group(1))
        assert set(choice) - {"ico.rate", "policy.gain"} == set(plants.PLANTS[plant].knobs), plant
        swept, task = build_config(choice, plant=plant).controller, build_config(plant=plant).controller
        assert bytes(swept) == bytes(task), plant
        for learner in set(plants.PLANTS[plant].learners) & set(plant_sweeps.LEARNER_SPACE):
            picked = json.loads(re.search(rf"## Learner {learner}: .*?Choice: `([^`]+)`", text, re.S).group(1))
            assert build_config(picked, condition=learner, plant=plant).to_dict() == \
                build_config(condition=learner, plant=plant).to_dict()


def test_learner_sweeps_pin_each_reading(monkeypatch, tmp_path):
    """Every learner sweep sets its actor reading explicitly, its own as well as the other's: the
    Furuta's ICO->RL defaults to the mean reading, so a "gradient" sweep that left the reading to
    the plant's defaults would run the mean reading under the gradient's name."""
    runs = []
    monkeypatch.setattr(plant_sweeps, "run_sweep", runs.append)
    monkeypatch.setattr(plant_sweeps, "learner_cells", lambda ico_dir: {"ico-failed": [600], "spread": [601]})
    plant_sweeps.run_learners(tmp_path / "ico", tmp_path / "out")
    reading_of = {tmp_path / "out" / "learners" / f"{stem}-{label}": reading
                  for condition in plant_sweeps.LEARNER_SPACE
                  for stem, (reading, _) in plant_sweeps.learner_dirs(tmp_path / "out", condition).items()
                  for label in ("ico-failed", "spread")}
    assert sorted(o.out for o in runs) == sorted(reading_of) and len(set(reading_of.values())) == 2
    for options in runs:
        pinned = dict(x.split("=") for x in options.sets)
        actor = build_config(pinned, condition=options.condition, plant="furuta").to_dict()["controller"]["actor"]
        reading = plant_sweeps.READINGS[reading_of[options.out]]
        assert {k: actor[k.split(".")[1]] for k in reading} == reading, options.out


def test_figures_and_sweep_take_the_recorded_plant(capsys, tmp_path):
    out = tmp_path / "fur"
    assert main(capsys, "grid", "--plant", "furuta", "--out", out, "--cells", CELLS, *TINY_ARGS)[0] == 0
    line = one_line_error(*main(capsys, "figures", "--results", out, "--out", tmp_path / "f", "--plant",
                                "cart_pole")[::2])
    assert "furuta" in line and not (tmp_path / "f").exists()
    line = one_line_error(*main(capsys, "sweep", "--prior-from", out, "--out", tmp_path / "s", "--plant",
                                "cart_pole", "--param", "actor.noise_std=1")[::2])
    assert "furuta" in line and not (tmp_path / "s").exists()
    rc, printed, err = main(capsys, "figures", "--results", out, "--out", tmp_path / "f", "--plant", "furuta")
    assert rc == 0, err
    assert sorted(Path(p).name for p in printed.split()) == ["fig1b_success_map.png", "fig1cf_weights.png"]


def test_sweep_stage_writes_its_rows_and_resumes(tmp_path, monkeypatch):
    monkeypatch.setattr(plant_sweeps, "MAX_TRIALS", 20)
    monkeypatch.setattr(plant_sweeps, "SUCCESS_STEPS", 100)
    path = tmp_path / "stage.csv"
    setting = plant_sweeps.samples("furuta")[0]
    rows = plant_sweeps.run_stage("furuta", path, [setting], [0, 1], [600, 601])
    assert [r["seed"] for r in plant_sweeps.read_rows(path)] == ["0", "1"] and len(rows) == 2
    assert plant_sweeps.setting_of(rows[0]["key"]) == setting
    before = path.read_bytes()
    plant_sweeps.run_stage("furuta", path, [setting], [0, 1], [600, 601])  # nothing left to run
    assert path.read_bytes() == before


def test_prior_of_finished_cells():
    """A plant whose ICO prior averages every finished cell (plants.PlantSpec.prior_cells): the
    failed cells' weights count, pending and error cells do not, and the rule is recorded."""
    cells = grid.plant_grid("double_cart_pole", 0)[:6]
    cells["outcome"] = [B.SUCCESS, B.FAILED, B.FAILED, B.PENDING, B.ERROR, B.FAILED]
    cells["x0"], cells["theta0"] = 0.0, 0.0
    cells["weights"][:, :6] = np.arange(36.0).reshape(6, 6)
    grid6 = geometry.of("double_cart_pole")
    info = P.compute(cells, None, ridge=0.0, grid=grid6, use="finished")
    assert info.n_cells == 4 and info.to_dict()["prior_cells"] == "finished"
    np.testing.assert_allclose(info.mean, cells["weights"][[0, 1, 2, 5]][:, :6].mean(axis=0))
    with pytest.raises(P.PriorError, match="only 1 ICO-successful cell"):
        P.compute(cells, None, grid=grid6)
    with pytest.raises(P.PriorError, match="prior cells"):
        P.compute(cells, None, grid=grid6, use="some")
    assert plants.PLANTS["double_cart_pole"].prior_cells == "finished"
    assert plants.PLANTS["furuta"].prior_cells == plants.PLANTS["cart_pole"].prior_cells == "successful"


@pytest.mark.parametrize("plant", list(plants.PLANTS))
def test_cell_subsets_follow_each_plant_grid(plant):
    """The quick profile's, the sweep's spread and --subset cells lie on the plant's own grid; on
    the cart-pole's they are the paper grid's historical cells."""
    g = geometry.of(plant)
    for cells in (g.quick_cells(), g.spread_cells(), g.subset(40)):
        assert cells == sorted(set(cells)) and 0 <= cells[0] and cells[-1] < g.cells
        assert grid.make_cells(0, cells, plant=plant).size == len(cells)
    assert len(g.spread_cells()) == g.cols and g.subset(g.cells) == list(range(g.cells))
    if plant == "cart_pole":
        assert g.quick_cells() == sorted(r * 49 + c for r in (2, 8, 10, 12, 14, 22) for c in (4, 19, 22, 24, 26, 44))
        assert g.spread_cells() == list(range(0, 1225, 25))
    keys = g.frame_keys()
    assert keys[0].startswith(g.col_start()) and keys[1].startswith(g.row_start())
    assert [k.endswith("_deg") for k in keys] == [g.col_unit == "deg", g.row_unit == "deg"]


def test_task_knobs_are_set_by_name_and_checked_by_c():
    """A knob of a plant's task is set like a parameter, the C task writes the configuration from
    it, and a knob out of its range, of another plant or not a number is a one-line error."""
    default = build_config(plant="furuta").controller
    moved = build_config(config.parse_sets(["zone_deg=6"], plant="furuta"), plant="furuta").controller
    assert moved.task.rule_threshold[0] < default.task.rule_threshold[0]
    assert list(moved.policy.input_range) == list(default.policy.input_range)
    for overrides, plant, message in (({"zone_deg": 91.0}, "furuta", r"zone_deg=91 is outside \[1e-06, 90\] deg"),
                                      ({"zone_deg": "6"}, "furuta", "must be a number"),
                                      ({"zone_deg": 6.0}, "cart_pole", "unknown parameter 'zone_deg'")):
        with pytest.raises(B.ConfigError, match=message) as err:
            build_config(overrides, plant=plant)
        assert "\n" not in str(err.value)
    with pytest.raises(B.ConfigError, match=r"did you mean cart_velocity_range\?.*params --plant double_cart_pole"):
        config.parse_sets(["cart_velocity_rang=3"], plant="double_cart_pole")
