# SPDX-License-Identifier: Apache-2.0
"""The task description's late signal (method.md, the task description) against a Python oracle:
random rule tables on random input counts (first match wins: penalty -1 and the rule's reflex;
no match 0, 0), the sensor source (ICOAC_INPUT_LATE and in.reflex), and the cart-pole preset's
four rules against Eq. (4) as the paper writes it."""
import ctypes
import math
import random

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core.config import build_config

REAL = B.real_dtype.type
ABOVE, BELOW = B.RULE_SIDES["above"], B.RULE_SIDES["below"]


def oracle(rules, s):
    """(penalty, reflex) of the first rule (input, side, threshold, reflex) that matches s."""
    for index, side, threshold, reflex in rules:
        value = float(REAL(s[index]))
        if (value > threshold) if side == ABOVE else (value < threshold):
            return -1.0, reflex
    return 0.0, 0.0


def controller(n, rules, late_source=B.LATE_SOURCES["rules"]):
    """An ICO controller (no learning) of a task with n inputs and these rules (checked by icoac_init;
    no plant: the controller alone)."""
    cfg = build_config({"learn": 0})
    task = cfg.controller.task
    task.n_inputs = n
    task.late_source = late_source
    task.n_rules = len(rules)
    for k, (index, side, threshold, reflex) in enumerate(rules):
        task.rule_input[k], task.rule_side[k] = index, side
        task.rule_threshold[k], task.rule_reflex[k] = threshold, reflex
    for i in range(B.MAX_INPUTS):
        cfg.controller.policy.input_range[i] = 1.0
    state = B.State()
    B.check_status(B.lib.icoac_init(ctypes.byref(cfg.controller), ctypes.byref(state), None, 1))
    return cfg, state


def tick(state, s, flags=0, reflex=0.0):
    inp = B.Input()
    for i in range(B.MAX_INPUTS):
        inp.s[i] = s[i] if i < len(s) else math.nan  # entries past n: never read
    inp.flags, inp.reflex = flags, reflex
    out = B.Output()
    status = B.lib.icoac_step(ctypes.byref(state), ctypes.byref(inp), ctypes.byref(out))
    return status, out


@pytest.mark.parametrize("seed", range(8))
def test_random_rule_tables_first_match_wins(seed):
    rng = random.Random(seed)
    n = rng.randint(1, B.MAX_INPUTS)
    thresholds = [round(rng.uniform(-1, 1), 2) for _ in range(B.MAX_RULES)]
    rules = [(rng.randrange(n), rng.choice([ABOVE, BELOW]), float(REAL(thresholds[k])),
              rng.choice([-1.0, -0.5, 0.0, 0.25, 1.0])) for k in range(rng.randint(0, B.MAX_RULES))]
    _, state = controller(n, rules)
    matched = set()
    for _ in range(400):
        # values on a coarse grid, so that inputs land exactly on thresholds too (no match there)
        s = [rng.choice([rng.uniform(-1.5, 1.5), rng.choice(thresholds)]) for _ in range(n)]
        status, out = tick(state, s)
        assert status == B.OK
        penalty, reflex = oracle(rules, s)
        assert (out.penalty, out.reflex) == (penalty, float(REAL(reflex))), (rules, s)
        matched.add(next((k for k, r in enumerate(rules) if oracle([r], s)[0] < 0), None))
    # the tables are exercised: some rules match, and ticks where none does
    assert len(matched) >= min(len(rules), 2)


# The cart-pole preset's layout (theta above, x below, theta below, x above), which the controller's
# cart-pole instance reads as constants, and two 4-rule tables of 4 inputs that differ from it in
# one input or one side (read from the table).
PRESET_LAYOUT = [(2, ABOVE), (0, BELOW), (2, BELOW), (0, ABOVE)]
OTHER_LAYOUTS = {"side": [(2, ABOVE), (0, BELOW), (2, ABOVE), (0, ABOVE)],
                 "input": [(2, ABOVE), (1, BELOW), (2, BELOW), (0, ABOVE)]}


def random_rules(rng, layout):
    return [(index, side, float(REAL(round(rng.uniform(-1, 1), 2))), rng.choice([-1.0, -0.5, 0.25, 1.0]))
            for index, side in layout]


def check_against_oracle(state, rules, rng, ticks=400):
    thresholds = [r[2] for r in rules]
    for _ in range(ticks):
        s = [rng.choice([rng.uniform(-1.5, 1.5), rng.choice(thresholds)]) for _ in range(4)]
        status, out = tick(state, s)
        penalty, reflex = oracle(rules, s)
        assert status == B.OK and (out.penalty, out.reflex) == (penalty, float(REAL(reflex))), (rules, s)


@pytest.mark.parametrize("layout", ["preset", "side", "input"])
def test_four_rule_tables_of_four_inputs(layout):
    # any thresholds and reflexes on the preset's layout, and the layouts next to it
    rng = random.Random(layout)
    rules = random_rules(rng, PRESET_LAYOUT if layout == "preset" else OTHER_LAYOUTS[layout])
    _, state = controller(4, rules)
    check_against_oracle(state, rules, rng)


@pytest.mark.parametrize("layout", ["side", "input"])
def test_retune_between_rule_layouts(layout):
    # icoac_retune re-derives which layout the tick reads: to another layout and back
    rng = random.Random(f"retune-{layout}")
    preset = random_rules(rng, PRESET_LAYOUT)
    other = random_rules(rng, OTHER_LAYOUTS[layout])
    cfg, state = controller(4, preset)
    for rules in (other, preset):
        task = cfg.controller.task
        for k, (index, side, threshold, reflex) in enumerate(rules):
            task.rule_input[k], task.rule_side[k] = index, side
            task.rule_threshold[k], task.rule_reflex[k] = threshold, reflex
        B.check_status(B.lib.icoac_retune(ctypes.byref(state), ctypes.byref(cfg.controller)))
        check_against_oracle(state, rules, rng, ticks=200)


def test_first_match_precedence():
    # two rules on one input that both match above 0.5: the first one's reflex
    _, state = controller(2, [(1, ABOVE, 0.1, 0.25), (1, ABOVE, 0.5, -1.0), (0, BELOW, -0.2, 1.0)])
    assert (tick(state, [0.0, 0.7])[1].reflex, tick(state, [0.0, 0.3])[1].reflex) == (0.25, 0.25)
    assert tick(state, [-0.5, 0.7])[1].reflex == 0.25       # rule 0 before rule 2
    assert tick(state, [-0.5, 0.0])[1].reflex == 1.0        # only rule 2
    assert (tick(state, [0.0, 0.1])[1].penalty, tick(state, [-0.2, 0.0])[1].penalty) == (0.0, 0.0)  # strict


def test_cartpole_preset_is_eq4():
    cfg = build_config({"learn": 0})
    state = B.State()
    B.check_status(B.lib.icoac_init(ctypes.byref(cfg.controller), ctypes.byref(state), None, 1))
    zt, zx = float(REAL(math.radians(11.5))), 2.35
    rng = np.random.default_rng(5)
    for _ in range(2000):
        x, th = rng.uniform(-2.6, 2.6), rng.uniform(-0.25, 0.25)
        xs, ths = float(REAL(x)), float(REAL(th))
        if ths > zt or xs < -float(REAL(zx)):
            expect = (-1.0, 1.0)
        elif ths < -zt or xs > float(REAL(zx)):
            expect = (-1.0, -1.0)
        else:
            expect = (0.0, 0.0)
        status, out = tick(state, [x, 0.0, th, 0.0])
        assert status == B.OK and (out.penalty, out.reflex) == expect, (x, th)


def test_sensor_late_signal():
    _, state = controller(3, [(0, ABOVE, 0.0, 1.0)], late_source=B.LATE_SOURCES["sensor"])
    s = [0.9, 0.0, 0.0]  # the (ignored) rule would match
    assert (tick(state, s)[1].penalty, tick(state, s)[1].reflex) == (0.0, 0.0)
    for given, expect in ((0.5, 0.5), (-1.0, -1.0), (3.0, 1.0), (-7.0, -1.0), (0.0, 0.0)):
        status, out = tick(state, s, flags=B.INPUT_LATE, reflex=given)
        assert status == B.OK and (out.penalty, out.reflex) == (-1.0, expect)
    # the reflex is read only on a late tick: a NaN one is a non-finite input there, ignored otherwise
    assert tick(state, s, flags=0, reflex=math.nan)[0] == B.OK
    assert tick(state, s, flags=B.INPUT_LATE, reflex=math.nan)[0] == B.ERR_NONFINITE_INPUT
    assert tick(state, s, flags=B.INPUT_LATE, reflex=math.inf)[0] == B.ERR_NONFINITE_INPUT


def test_inputs_past_n_are_not_read():
    _, state = controller(2, [(1, BELOW, -0.5, -1.0)])
    status, out = tick(state, [0.1, -0.9])  # s[2:] NaN
    assert status == B.OK and (out.penalty, out.reflex) == (-1.0, -1.0)
    assert tick(state, [0.1, math.nan])[0] == B.ERR_NONFINITE_INPUT
