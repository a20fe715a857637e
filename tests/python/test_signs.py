# SPDX-License-Identifier: Apache-2.0
"""ICO's input signs from the plant (icoac.core.signs, task.input_sign; docs/method.md, input signs)."""
import ctypes

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import config as C
from icoac.core import grid, plants, results, signs
from icoac.studies.ceiling import lqr
from icoac.core.errors import ResultsError

PLANTS = [B.plant_info(i)["name"] for i in range(int(B.lib.icoac_sim_plant_count()))]


def _bytes(struct) -> bytes:
    return ctypes.string_at(ctypes.addressof(struct), ctypes.sizeof(struct))


@pytest.mark.parametrize("plant", ["cart_pole", "furuta"])
@pytest.mark.parametrize("condition", [None, "ico", "ico-rl", "ico-rl-control", "rl", "search"])
def test_derived_signs_keep_todays_configuration(plant, condition):
    """The cart-pole's and the Furuta's derived signs are +1 on every input, so their configuration
    is byte for byte the one without the derivation, and their results are today's (the
    cart-pole's: test_reference_cells.py)."""
    derived = C.build_config(condition=condition, plant=plant)
    plain = C.build_config(condition=condition, plant=plant, derive_signs=False)
    assert signs.derive_input_signs(derived) == (1, 1, 1, 1)
    assert list(plain.controller.task.input_sign) == [1] * B.MAX_INPUTS
    assert _bytes(derived.controller) == _bytes(plain.controller)
    assert derived.to_dict() == plain.to_dict()


def test_shipped_plants_derived_signs():
    """The derived signs of the shipped plants: the cart-pole's and the Furuta's are today's (+1),
    the double pendulum's are those of the best single w its ceiling found (docs/results.md):
    the cart's and the upper link's against the lower link's."""
    got = {p: tuple(C.build_config(plant=p).controller.task.input_sign)[:C.build_config(plant=p).n_inputs]
           for p in PLANTS}
    assert got == {"cart_pole": (1, 1, 1, 1), "furuta": (1, 1, 1, 1), "double_cart_pole": (-1, -1, 1, 1, -1, -1)}


@pytest.mark.parametrize("plant", PLANTS)
def test_derived_signs_are_the_lqr_gain_pattern(plant):
    """sign_i = sign(-K_i) of the LQR gain with R = 1 / G^2, so that the LQR feedback's weights
    w_i = -K_i range_i sign_i / G are all >= 0: the feedback ICO's growing weights can reach."""
    cfg = C.build_config(plant=plant)
    n = cfg.n_inputs
    a, b = signs.linearise(cfg)
    ranges = np.array(list(cfg.controller.policy.input_range)[:n])
    gain = float(cfg.controller.policy.gain)
    k = signs.lqr_gain(a, b, np.diag(1 / ranges ** 2), 1 / gain ** 2)
    sign = np.array(list(cfg.controller.task.input_sign)[:n])
    assert np.all(-k * ranges * sign / gain >= 0)
    # and the ceiling's LQR start at that R is those weights
    starts = dict(lqr.lqr_starts(cfg))
    if gain in lqr.LQR_FORCES:
        np.testing.assert_allclose(starts[f"lqr R=1/{gain:g}^2"], -k * ranges * sign / gain, rtol=1e-5, atol=1e-6)


def test_lqr_signs_of_a_mixed_pattern():
    """A plant whose LQR gain has mixed signs gets mixed input signs (a double integrator pushed
    away from its goal: u = -K s with K > 0 on both states gives -1, -1)."""
    dt = 0.01
    a = np.array([[1.0, dt], [0.0, 1.0]])
    b = np.array([[0.5 * dt * dt], [dt]])
    assert signs.lqr_signs(a, b, np.array([1.0, 1.0]), 10.0) == (-1, -1)
    assert signs.lqr_signs(a, -b, np.array([1.0, 1.0]), 10.0) == (1, 1)
    # no stabilising gain (an unstable mode the input cannot reach): None
    assert signs.lqr_signs(np.diag([1.5, 1.0]), np.array([[0.0], [1.0]]), np.array([1.0, 1.0]), 1.0) is None


def test_given_signs_switch_the_derivation_off():
    """task.input_sign given by any layer wins: a list, or one number for every input; a record's
    signs are its own, and a record without them is refused, never read as +1 or derived again."""
    plant = "double_cart_pole"
    assert list(C.build_config({"task.input_sign": 1}, plant=plant).controller.task.input_sign) == [1] * 6
    given = [1, -1, 1, -1, 1, -1]
    cfg = C.build_config({"task.input_sign": given}, condition="ico", plant=plant)
    assert list(cfg.controller.task.input_sign) == given
    assert cfg.to_dict()["controller"]["task"]["input_sign"] == given
    assert list(C.config_from_dict(cfg.to_dict()).controller.task.input_sign) == given
    assert C.parse_sets(["task.input_sign=-1"]) == {"task.input_sign": -1}
    record = results.make_record(grid.make_cells(indices=[0], plant=plant), cfg, condition="ico", seed=0,
                                 wall_time=0.0, threads=1, builds=[results.build_entry({})], cell_indices=[0])
    assert results.check_record(record) is record
    del record["config"]["controller"]["task"]["input_sign"]
    with pytest.raises(ResultsError, match=r"config\.controller\.task: 'input_sign' is a required property"):
        results.check_record(record)


def test_a_task_that_gives_signs_keeps_them(monkeypatch):
    """A plant's C task that writes its own signs (a -1) is not derived over; the others are."""
    plant = "double_cart_pole"
    derived = list(C.build_config(plant=plant).controller.task.input_sign)
    task_config = plants.PlantSpec.task_config

    def with_signs(spec, cfg, knobs=None):
        task_config(spec, cfg, knobs)
        cfg.task.input_sign[0] = -1
        cfg.task.input_sign[1] = 1
    monkeypatch.setattr(plants.PlantSpec, "task_config", with_signs)
    given = list(C.build_config(plant=plant).controller.task.input_sign)
    assert given == [-1] + [1] * 5 != derived


@pytest.mark.parametrize("bad", [0, 2, [1, 1, 0, 1, 1, 1]])
def test_bad_signs_are_refused_by_name(bad):
    with pytest.raises(B.ConfigError, match=r"task\.input_sign\[[0-9]\]") as err:
        C.build_config({"task.input_sign": bad}, plant="double_cart_pole")
    assert err.value.status == B.ERR_BAD_TASK


def test_signs_follow_the_configured_task():
    """The derivation reads the configuration in force (here the gain, R = 1 / G^2): the double
    pendulum's lower-link velocity gain changes sign between G = 10 N and G = 100 N."""
    plant = "double_cart_pole"
    assert tuple(C.build_config({"policy.gain": 100}, plant=plant).controller.task.input_sign) == (-1, -1, 1, -1, -1, -1)
    assert tuple(C.build_config({"policy.gain": 10}, plant=plant).controller.task.input_sign) == (-1, -1, 1, 1, -1, -1)
