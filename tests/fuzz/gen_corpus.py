#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Write the committed seed corpus of the fuzz targets, tests/fuzz/corpus/<target>/.

Inputs follow the formats documented at the top of fuzz_controller.c, fuzz_state.c,
fuzz_model.c and fuzz_batch.c; the value tables below mirror fuzz_input.c, the state fields
fuzz_state.c. Files named repro-* are known reproducers.

    python3 tests/fuzz/gen_corpus.py          # (re)write the corpus
    python3 tests/fuzz/gen_corpus.py --check  # exit 1 unless the committed corpus is current
"""
import argparse
import math
import random
import re
import struct
import sys
from pathlib import Path

CORPUS = Path(__file__).resolve().parent / "corpus"

# Special-value tables of fuzz_input.c, by selector.
REAL_TABLE = ["0", "-0", "1e-39", "1e-45", "min", "max", "1e30", "1e-20", "nan", "inf", "-inf",
              "-1", "1", "0.5", "-1e30", "1e38", "-max", "2", "0.25", "2.4", "-2.4", "10", "1e-5",
              "-0.25", "true_min", "0.999", "1e10", "-1e-39"]
DOUBLE_TABLE = ["0", "-0", "1e-310", "true_min", "min", "max", "1e300", "1e30", "nan", "inf",
                "-inf", "-1", "1", "0.5", "-1e30", "1e-20", "-max", "2", "0.25", "2.4", "-2.4",
                "9.8", "0.01", "1e-6", "1e6", "0.1", "1e-39", "3.2"]
BOUNDED_SCALES = [1e-3, 1e-2, 0.1, 1.0, 3.0, 10.0, 100.0, 1e4]
INT32_TABLE = [0, 1, 2, -1, 2**31 - 1, -2**31, 3]
INT64_TABLE = [0, 1, 2, 3, -1, 300, 1000, 100000, 2**63 - 1, -2**63, 10]

# icoac_config_t with the default maxima (6 inputs, 6 rules), one group per concern, read from the
# rows of firmware/include/icoac/icoac_params.h: (member, kind) with kind "i" an int32 (switch or
# count), "r" an icoac_real_t, "r6" / "i6" an array of 6 of them, or a nested group.
MAX_INPUTS = 6
PARAMS_H = Path(__file__).resolve().parents[2] / "firmware" / "include" / "icoac" / "icoac_params.h"


def config_layout():
    layout, groups = [], {}
    for group, field, ctype, dim in re.findall(r"^\s*X\((\w+), (\w+), (\w+), (\w+),", PARAMS_H.read_text(), re.M):
        kind = ("i" if ctype == "int32_t" else "r") + ("" if dim == "scalar" else "6")
        if group == "config":
            layout.append((field, kind))
        else:
            if group not in groups:
                groups[group] = []
                layout.append((group, groups[group]))
            groups[group].append((field, kind))
    return layout


CONFIG_LAYOUT = config_layout()
# sizeof(icoac_config_t) with float and with double reals (x86-64 and AArch64 alignment).
CONFIG_SIZES = {"f": 316, "d": 504}


def config_fields():
    """Scalar fields of icoac_config_t in struct order: [(C designator, is_int)]."""
    out = []

    def walk(members, prefix):
        for name, kind in members:
            if isinstance(kind, list):
                walk(kind, prefix + name + ".")
            elif kind in ("r6", "i6"):
                out.extend((f"{prefix}{name}[{i}]", kind == "i6") for i in range(6))
            else:
                out.append((prefix + name, kind == "i"))

    walk(CONFIG_LAYOUT, "")
    return out


# The mutation field indices of fuzz_input.c: struct order.
CONFIG_FIELDS = [name for name, _ in config_fields()]
CONFIG_INTS = {name for name, is_int in config_fields() if is_int}
assert CONFIG_FIELDS[:3] == ["mode", "learn", "task.n_inputs"], CONFIG_FIELDS[:3]  # the rows were found
ZONE_THETA, ZONE_X = 0.20071286397934788, 2.35


def array(name, values):
    """{name[i]: values[i]} over the 6 entries (0 past the values)."""
    return {f"{name}[{i}]": (values[i] if i < len(values) else 0) for i in range(MAX_INPUTS)}


CONFIG_DEFAULT = {"mode": 0, "learn": 1,
                  "task.n_inputs": 4, **array("task.input_sign", [1] * 6), "task.late_source": 0, "task.n_rules": 4,
                  **array("task.rule_input", [2, 0, 2, 0]), **array("task.rule_side", [1, 0, 0, 1]),
                  **array("task.rule_threshold", [ZONE_THETA, -ZONE_X, -ZONE_THETA, ZONE_X]),
                  **array("task.rule_reflex", [1.0, 1.0, -1.0, -1.0]),
                  **array("policy.input_range", [2.4, 3.5, 0.2094384, 2.0]),
                  "policy.clip_inputs": 1, "policy.gain": 10.0, "policy.reflex_mode": 0,
                  "policy.reflex_force": 1.0,
                  "ico.rate": 1.0e-4, "ico.timing": 0,
                  "critic.rate": 0.6, "critic.discount": 0.95, "critic.td_clip": 1.0,
                  **array("critic.range", [2.4, 3.5, 0.2094384, 2.0]), **array("critic.units", [3, 3, 6, 3]),
                  "critic.threshold": 0.001, "critic.quirks": 0,
                  "actor.noise_std": 1.0, "actor.scale": 0.5, "actor.forgetting": 1.0,
                  "actor.reflex": 1, "actor.act_with_sample": 0, "actor.update": 2, "actor.rate": 0.01,
                  "actor.likelihood_std": 0.0, "actor.batch": 0, "actor.explore_ticks": 1000,
                  "search.batch": 8, "search.elite_fraction": 0.25, "search.step": 0.5, "search.floor": 1.0,
                  "search.cov_scale": 64.0}
assert list(CONFIG_DEFAULT) == CONFIG_FIELDS


def config_offsets(fmt):
    """(sizeof(icoac_config_t), {designator: (offset, struct code)}) for real type fmt, by the C
    rules: each member at a multiple of its alignment, a struct aligned like its widest
    member and padded to a multiple of that."""
    real = struct.calcsize("<" + fmt)

    def place(members):
        """(size, alignment, {designator: (offset, code)}) of one struct."""
        fields, offset, align = {}, 0, 1
        for name, kind in members:
            if isinstance(kind, list):
                size, sub_align, sub = place(kind)
                offset = -(-offset // sub_align) * sub_align
                fields.update({f"{name}.{key}": (offset + o, code) for key, (o, code) in sub.items()})
                offset += size
                align = max(align, sub_align)
                continue
            size, code = (4, "i") if kind in ("i", "i6") else (real, fmt)
            offset = -(-offset // size) * size
            if kind in ("r6", "i6"):
                fields.update({f"{name}[{i}]": (offset + i * size, code) for i in range(6)})
                offset += 6 * size
            else:
                fields[name] = (offset, code)
                offset += size
            align = max(align, size)
        return -(-offset // align) * align, align, fields

    size, _, fields = place(CONFIG_LAYOUT)
    assert list(fields) == CONFIG_FIELDS
    return size, fields


RUN_FIELDS = ["max_trials", "success_steps", "init_velocity_noise"]


class Exact(float):
    """A real given by its raw bits (selector 36), e.g. a documented bound exactly."""


def value(v, table, fmt="f"):
    """A real or double: a table name (str), an Exact value as raw bits of struct code fmt, or an
    ordinary number as a bounded int16."""
    if isinstance(v, Exact):
        return bytes([len(REAL_TABLE) + len(BOUNDED_SCALES)]) + struct.pack("<" + fmt, v)
    if isinstance(v, str):
        return bytes([table.index(v)])
    for k, scale in enumerate(BOUNDED_SCALES):
        q = round(v / scale * 32768)
        if -32768 <= q <= 32767:
            return bytes([len(REAL_TABLE) + k]) + struct.pack("<h", q)
    raise ValueError(f"{v} is outside the bounded range; use a table name")


def real(v, fmt="f"):
    return value(v, REAL_TABLE, fmt)


def double(v):
    return value(v, DOUBLE_TABLE, "d")


def int32(v):
    """A table value by its selector, any other int32 as selector 7 and its 4 raw bytes."""
    if v in INT32_TABLE:
        return bytes([INT32_TABLE.index(v)])
    return bytes([len(INT32_TABLE)]) + struct.pack("<i", v)


def int64(v):
    return bytes([INT64_TABLE.index(v)])


def config(fields=None, fmt="f"):
    """icoac_config_default with mutations {C designator: value} (at most 7, applied in order);
    fmt: the real type's struct code (for Exact values)."""
    fields = fields or {}
    assert len(fields) <= 7
    out = bytes([len(fields) << 1])
    for name, v in fields.items():
        out += bytes([CONFIG_FIELDS.index(name)]) + (int32(v) if name in CONFIG_INTS else real(v, fmt))
    return out


def config_raw(fmt, fields=None):
    """Raw icoac_config_t bytes (fmt 'f' float, 'd' double) over the default; padding 0."""
    cfg = dict(CONFIG_DEFAULT, **(fields or {}))
    assert set(cfg) == set(CONFIG_FIELDS)
    size, offsets = config_offsets(fmt)
    assert size == CONFIG_SIZES[fmt], (fmt, size)
    raw = bytearray(size)
    for name, (offset, code) in offsets.items():
        struct.pack_into("<" + code, raw, offset, cfg[name])
    return b"\x01" + bytes(raw)


def prior(*mutations, fmt="f"):
    """None: NULL; (): mean 0, cov I; else (field, value[, mirror]) mutations of that; fmt: the
    real type's struct code (for Exact values)."""
    if mutations == (None,):
        return b"\x00"
    if not mutations:
        return b"\x01"
    assert len(mutations) <= 7
    out = bytes([3 * len(mutations) + 2])
    for m in mutations:
        field, v = m[0], m[1]
        mirror = len(m) > 2 and m[2]
        index = int(field[4:]) if isinstance(field, str) else MAX_INPUTS * (1 + field[0]) + field[1]
        out += bytes([index | (0x80 if mirror else 0)]) + real(v, fmt)
    return out


NO_PRIOR = prior(None)


def seed(n):
    return struct.pack("<Q", n)


def step(s=None, repeat=1, terminal=False, late=False, reflex=None):
    """repeat (1..8) controller steps on s (the task's n values), or on the previous s when None;
    late: ICOAC_INPUT_LATE; reflex: a value for in.reflex."""
    assert 1 <= repeat <= 8
    op = ((2 if terminal else 0) | ((repeat - 1) << 2) | (0x20 if s is None else 0) | (0x40 if late else 0)
          | (0x80 if reflex is not None else 0))
    return (bytes([op]) + (b"".join(real(x) for x in s) if s is not None else b"")
            + (real(reflex) if reflex is not None else b""))


def steps(s, n, terminal=False):
    """n steps on s, in ops of up to 8."""
    out = step(s, min(n, 8), terminal)
    n -= min(n, 8)
    while n > 0:
        out += step(None, min(n, 8), terminal)
        n -= min(n, 8)
    return out


RESET = b"\x03"
ZERO = ("0", "0", "0", "0")


def retune(fields=None, over_default=False, fmt="f"):
    """icoac_retune with a config section laid over the configuration in force, or (over_default)
    over the default."""
    return bytes([0xC3 if over_default else 0x43]) + config(fields, fmt)

# A trial through the middle, the reflex / penalty zones, a failure and a new trial.
EXERCISE = (steps(ZERO, 2) + steps((0.5, 0.3, 0.05, 0.2), 4) + steps((2.5, 1.0, "0.25", 1.0), 2)
            + steps(("-2.4", -1.0, "-0.25", -1.0), 2) + step((2.5, 1.0, "0.25", 1.0), terminal=True)
            + RESET + steps((0.1, 0.0, 0.01, 0.0), 8) + steps((-0.3, 0.2, -0.1, 0.5), 8))


# Six trials of different lengths, each ended by a failure and a reset: a search batch of 4
# updates once (and a batch of 2 three times; the default batch of 8 needs SEARCH_TRIALS * 2).
SEARCH_TRIALS = b"".join(steps((0.1 * k, -0.2, 0.02 * k, 0.3), 2 + 3 * k) + step((2.5, 1.0, "0.25", 1.0), terminal=True)
                         + RESET for k in range(6))


def rounded(fmt):
    """Rounding to the real type of struct code fmt. IEEE double operations on two reals of
    that type, then this rounding, give the real type's correctly rounded +, -, *, / and sqrt."""
    return lambda x: struct.unpack("<" + fmt, struct.pack("<" + fmt, x))[0]


def next_up(x, fmt):
    """The next real of type fmt above x > 0."""
    bits_fmt = {"f": "<I", "d": "<Q"}[fmt]
    bits = struct.unpack(bits_fmt, struct.pack("<" + fmt, x))[0]
    return struct.unpack("<" + fmt, struct.pack(bits_fmt, bits + 1))[0]


def prior_lost_by_scale(fmt, scale):
    """(c, b): the prior cov I with cov[0][1] = cov[1][0] = c and cov[1][1] = b passes the
    Cholesky test of icoac_prior_check (pivot b - c^2 > 0 by a few ulps), but scale * it, as
    icoac_init forms Sigma0 in search mode, does not: its pivot rounds to <= 0. The test is
    replayed here in the real type's arithmetic, in the order of icoac_priv_cholesky4."""
    r = rounded(fmt)

    def second_pivot(a, c, b):
        l00 = r(math.sqrt(a))
        l10 = r(c / l00)
        return r(b - r(l10 * l10))

    for i in range(1, 20000):
        c = r(0.5 + i / 40000.0)
        b = r(c * c)
        for _ in range(4):
            b = next_up(b, fmt)
            if second_pivot(1.0, c, b) > 0 and second_pivot(r(scale), r(c * r(scale)), r(b * r(scale))) <= 0:
                return c, b
    raise AssertionError("no prior found")


def controller_seeds(fmt):
    """Seeds of the controller targets; fmt is the real type's struct code."""
    rl = {"mode": 1}
    search = {"mode": 2}
    s = {
        "default-ico": config() + NO_PRIOR + seed(1) + EXERCISE,
        "default-rl": config(rl) + NO_PRIOR + seed(2) + EXERCISE + EXERCISE,
        "rl-sample": config({**rl, "actor.act_with_sample": 1}) + NO_PRIOR + seed(3) + EXERCISE + RESET + EXERCISE,
        # the paper's literal reading (harness configuration `literal`): the posterior update with
        # sigma_L = sigma_u, exploring at every tick
        "rl-literal": (config({**rl, "actor.update": 0, "actor.explore_ticks": 0}) + NO_PRIOR + seed(42)
                       + EXERCISE * 2),
        "rl-literal-sample": (config({**rl, "actor.update": 0, "actor.explore_ticks": 0, "actor.act_with_sample": 1})
                              + NO_PRIOR + seed(43) + EXERCISE + RESET + EXERCISE),
        "rl-dense-forgetting": (config({**rl, "critic.threshold": "0", "actor.forgetting": 0.9, "actor.update": 0})
                                + NO_PRIOR + seed(4) + EXERCISE),
        "rl-no-reflex": config({**rl, "actor.reflex": 0, "critic.discount": "1"}) + NO_PRIOR + seed(5) + EXERCISE,
        "ico-literal": config({"ico.timing": 1}) + NO_PRIOR + seed(6) + EXERCISE,
        "ico-reflex-gain": config({"policy.reflex_mode": 1}) + NO_PRIOR + seed(7) + EXERCISE,
        "ico-prior": config() + prior(("mean0", 1.0), ("mean2", 10.0), ((1, 1), 2.0)) + seed(8) + EXERCISE,
        "rl-prior-correlated": config(rl) + prior(("mean2", 5.0), ((0, 1), 0.5, True)) + seed(9) + EXERCISE,
        "prior-asymmetric": config(rl) + prior(((0, 1), 0.5)) + seed(10) + EXERCISE,
        "prior-mean-nan": config() + prior(("mean1", "nan")) + seed(11) + EXERCISE,
        "config-bad-mode": config({"mode": 3}) + NO_PRIOR + seed(12) + EXERCISE,
        "config-bad-range": config({"policy.input_range[1]": "-1"}) + NO_PRIOR + seed(13) + EXERCISE,
        "config-raw-default": config_raw(fmt) + NO_PRIOR + seed(14) + EXERCISE,
        "config-raw-rl": config_raw(fmt, {**rl, "actor.noise_std": 0.5}) + prior() + seed(15) + EXERCISE,
        "nonfinite-input": (config(rl) + NO_PRIOR + seed(16) + steps(ZERO, 2)
                            + step(("nan", "0", "0", "0")) + step(("0", "inf", "0", "0"))
                            + step(("0", "0", "-inf", "0"), terminal=True) + steps(ZERO, 2)),
        # A mode ignores the groups it does not use, even when they are bad.
        "config-ico-ignores-rl-groups": (config({"critic.range[0]": "1e-39", "critic.threshold": "nan",
                                                 "actor.noise_std": "1e-20", "actor.reflex": 2})
                                         + NO_PRIOR + seed(17) + EXERCISE),
        "config-rl-ignores-ico-group": (config({**rl, "ico.rate": "nan", "ico.timing": 2}) + NO_PRIOR + seed(18)
                                        + EXERCISE),
        # The learners (docs/method.md, L2-L4, A10): actor readings, per-trial batches, the exploration
        # schedule, the critic quirks, and the episodic search over several batches.
        "rl-mean": config({**rl, "actor.update": 1, "actor.likelihood_std": 0.25}) + NO_PRIOR + seed(19) + EXERCISE * 2,
        "rl-gradient": config({**rl, "actor.update": 2, "actor.rate": 0.1}) + NO_PRIOR + seed(20) + EXERCISE * 2,
        "rl-batch-posterior": (config({**rl, "actor.batch": 1, "actor.forgetting": 0.9, "actor.update": 0})
                               + NO_PRIOR + seed(21) + EXERCISE * 2),
        "rl-batch-mean": config({**rl, "actor.batch": 1, "actor.update": 1}) + NO_PRIOR + seed(22) + EXERCISE * 2,
        "rl-batch-gradient": (config({**rl, "actor.batch": 1, "actor.update": 2, "actor.rate": 1.0}) + NO_PRIOR
                              + seed(23) + EXERCISE * 2),
        "rl-explore-ticks": (config({**rl, "actor.explore_ticks": 5, "actor.act_with_sample": 1}) + NO_PRIOR
                             + seed(24) + EXERCISE * 2),
        "rl-batch-explore-quirks": (config({**rl, "actor.batch": 1, "actor.explore_ticks": 3, "critic.quirks": 1,
                                            "actor.update": 0}) + NO_PRIOR + seed(25) + EXERCISE * 2),
        "rl-likelihood-std": (config({**rl, "actor.update": 0, "actor.likelihood_std": 3.0, "actor.noise_std": 0.5})
                              + NO_PRIOR + seed(44) + EXERCISE * 2),
        "rl-quirks": config({**rl, "critic.quirks": 1, "critic.threshold": "0"}) + NO_PRIOR + seed(26) + EXERCISE,
        "rl-learner-extremes": (config({**rl, "actor.update": 2, "actor.rate": Exact(1000.0),
                                        "actor.noise_std": Exact(0.001), "actor.likelihood_std": Exact(1000.0),
                                        "actor.explore_ticks": 100000000}, fmt)
                                + NO_PRIOR + seed(27) + EXERCISE),
        "rl-mean-likelihood-min": (config({**rl, "actor.update": 1, "actor.likelihood_std": Exact(0.001),
                                           "actor.scale": Exact(1000.0)}, fmt) + NO_PRIOR + seed(40) + EXERCISE),
        "rl-ignores-search-group": (config({**rl, "search.batch": 0, "search.floor": "nan", "search.cov_scale": "0"})
                                    + NO_PRIOR + seed(28) + EXERCISE),
        "search-default": config(search) + NO_PRIOR + seed(29) + SEARCH_TRIALS * 3,
        "search-batch-1": config({**search, "search.batch": 1, "search.step": "1"}) + NO_PRIOR + seed(30) + SEARCH_TRIALS,
        "search-step-1": (config({**search, "search.step": "1", "search.elite_fraction": "0.5", "search.floor": 1.0,
                                  "search.batch": 4}) + NO_PRIOR + seed(31) + SEARCH_TRIALS),
        # a = 1 with an elite of 2 and a small floor: Sigma' singular, the fallback Sigma' + diag(floor)
        "search-step-1-singular": (config({**search, "search.step": "1", "search.elite_fraction": "0.5",
                                           "search.floor": 1e-3, "search.batch": 4, "search.cov_scale": "1"})
                                   + NO_PRIOR + seed(45) + SEARCH_TRIALS * 2),
        "search-max-batch": (config({**search, "search.batch": 16, "search.elite_fraction": "0.25"}) + NO_PRIOR
                             + seed(32) + SEARCH_TRIALS * 3),
        "search-prior-scaled": (config({**search, "search.cov_scale": 16.0, "search.floor": "1e-5", "search.batch": 4})
                                + prior(("mean2", 5.0), ((0, 1), 0.5, True), ((2, 2), 4.0)) + seed(33) + SEARCH_TRIALS),
        # a prior icoac_prior_check accepts whose cov_scale * cov is not positive definite:
        # ICOAC_ERR_BAD_PRIOR from icoac_init in search mode, the state untouched
        "search-prior-lost-by-scale": (config({**search, "search.cov_scale": Exact(3.0)}, fmt)
                                       + prior(((0, 1), Exact(prior_lost_by_scale(fmt, 3.0)[0]), True),
                                               ((1, 1), Exact(prior_lost_by_scale(fmt, 3.0)[1])), fmt=fmt)
                                       + seed(46) + SEARCH_TRIALS),
        "search-floor-max": (config({**search, "search.floor": Exact(1000.0), "search.cov_scale": Exact(1000.0),
                                     "search.batch": 2}, fmt) + NO_PRIOR + seed(34) + SEARCH_TRIALS),
        "search-floor-min": (config({**search, "search.floor": Exact(1e-6), "search.elite_fraction": Exact(1e-6),
                                     "search.step": Exact(1e-6), "search.batch": 3}, fmt) + NO_PRIOR + seed(41)
                             + SEARCH_TRIALS),
        "search-no-learning": config({**search, "learn": 0, "search.batch": 4}) + NO_PRIOR + seed(35) + SEARCH_TRIALS,
        "search-ignores-other-groups": (config({**search, "ico.rate": "nan", "critic.range[0]": "1e-39",
                                                "actor.noise_std": "0", "actor.update": 7, "critic.quirks": 2,
                                                "search.batch": 4})
                                        + NO_PRIOR + seed(36) + SEARCH_TRIALS),
        "search-bad-batch": config({**search, "search.batch": 17}) + NO_PRIOR + seed(37) + SEARCH_TRIALS,
        "search-nonfinite-terminal": (config({**search, "search.batch": 2}) + NO_PRIOR + seed(38) + steps(ZERO, 3)
                                      + step(("nan", "0", "0", "0"), terminal=True) + SEARCH_TRIALS),
        "config-raw-search": config_raw(fmt, {**search, "search.batch": 2, "search.step": 0.25}) + prior() + seed(39)
                             + SEARCH_TRIALS,
        # Live tuning (icoac_retune) and ended trials (ICOAC_ERR_TRIAL_ENDED until icoac_reset).
        "rl-retune": (config(rl) + NO_PRIOR + seed(47) + EXERCISE
                      + retune({"actor.update": 0, "actor.batch": 1, "policy.input_range[2]": 0.5}) + EXERCISE
                      + retune({"mode": 2}) + retune(over_default=True) + retune({"critic.threshold": "nan"})
                      + retune({"actor.explore_ticks": 3, "learn": 0, "critic.quirks": 1}) + EXERCISE),
        "ico-retune": (config() + NO_PRIOR + seed(48) + EXERCISE
                       + retune({"ico.timing": 1, "policy.input_range[0]": 1.0, "ico.rate": 0.01}) + EXERCISE
                       + retune({"ico.rate": "nan"}) + retune({"mode": 1}) + retune({"learn": 0}) + EXERCISE),
        # a retune to a batch smaller than the trials recorded: the next terminal tick closes it
        "search-retune-batch": (config(search) + NO_PRIOR + seed(49) + SEARCH_TRIALS
                                + retune({"search.batch": 2, "search.floor": 0.5, "search.cov_scale": 2.0})
                                + SEARCH_TRIALS + retune({"search.batch": 16, "search.elite_fraction": "1"})
                                + retune({"search.batch": 17}) + SEARCH_TRIALS),
        "config-raw-retune": (config_raw(fmt, {**rl, "actor.noise_std": 0.5}) + NO_PRIOR + seed(50) + EXERCISE
                              + bytes([0x43]) + config_raw(fmt, {**rl, "actor.update": 1}) + EXERCISE),
    }
    # Task descriptions (icoac.h, task): six inputs with a 3x3x3x2x2x2 critic and a rule on each
    # position's two sides; one input; a sensor's late signal; random rule tables.
    six = {"task.n_inputs": 6, "task.n_rules": 6, **array("task.rule_input", [0, 0, 1, 1, 2, 2]),
           **array("task.rule_side", [1, 0, 1, 0, 1, 0]),
           **array("task.rule_threshold", [2.35, -2.35, 0.3, -0.3, 0.3, -0.3]),
           **array("task.rule_reflex", [-1.0, 1.0, 1.0, -1.0, 0.5, -0.5]),
           **array("policy.input_range", [2.4, 0.35, 0.35, 3.5, 2.0, 2.0]),
           **array("critic.range", [2.4, 0.35, 0.35, 3.5, 2.0, 2.0]), **array("critic.units", [3, 3, 3, 2, 2, 2])}
    six_s = [(0.1 * k, 0.05 * k, -0.04 * k, 0.3, -0.2 * k, 0.1) for k in range(4)]
    six_exercise = (b"".join(steps(x, 3) for x in six_s) + step((2.5, 0.4, 0.0, 1.0, 0.0, 0.0), terminal=True)
                    + RESET + steps((-0.2, -0.31, 0.2, 0.0, 1.0, -1.0), 4) + step(("0", "nan", "0", "0", "0", "0")))
    one = {"task.n_inputs": 1, "task.n_rules": 2, **array("task.rule_input", [0, 0]),
           **array("task.rule_side", [1, 0]), **array("task.rule_threshold", [0.5, -0.5]),
           **array("task.rule_reflex", [-1.0, 1.0]), **array("critic.units", [7])}
    sensor_ops = (steps((0.1, 0.0, 0.01, 0.0), 3) + step((0.2, 0.0, 0.3, 0.0), late=True, reflex=1.0)
                  + step(None, late=True, reflex=-0.25) + step(None, late=True, reflex=2.0) + step(None, late=False)
                  + step(None, late=True, reflex="nan") + step(None, late=True, reflex="-inf")
                  + step((0.2, 0.0, 0.3, 0.0), terminal=True, late=True, reflex=1.0) + RESET + EXERCISE)
    for mode, name in ((0, "ico"), (1, "rl"), (2, "search")):
        s[f"task-six-inputs-{name}"] = (config_raw(fmt, {**six, "mode": mode, "search.batch": 2}) + NO_PRIOR
                                        + seed(60 + mode) + six_exercise * 2)
        s[f"task-one-input-{name}"] = (config_raw(fmt, {**one, "mode": mode, "search.batch": 2}) + NO_PRIOR
                                       + seed(63 + mode) + steps((0.1,), 3) + steps((0.6,), 2)
                                       + step((-0.7,), terminal=True) + RESET + steps(("nan",), 1)
                                       + steps((-0.2,), 4))
        s[f"task-sensor-{name}"] = (config({"mode": mode, "task.late_source": 1, "search.batch": 2}) + NO_PRIOR
                                    + seed(66 + mode) + sensor_ops)
        # the double pendulum's derived input signs (icoac.core.signs): mixed, on six inputs
        s[f"task-six-signs-{name}"] = (config_raw(fmt, {**six, **array("task.input_sign", [-1, -1, 1, 1, -1, -1]),
                                                        "mode": mode, "search.batch": 2}) + NO_PRIOR
                                       + seed(90 + mode) + six_exercise * 2)
    rules = random.Random(20261202)
    for k in range(6):
        n_rules = rules.randrange(7)
        table = {"task.n_rules": n_rules}
        table.update(array("task.rule_input", [rules.randrange(4) for _ in range(6)]))
        table.update(array("task.rule_side", [rules.randrange(2) for _ in range(6)]))
        table.update(array("task.rule_threshold", [round(rules.uniform(-3, 3), 3) for _ in range(6)]))
        table.update(array("task.rule_reflex", [rules.choice([-1.0, -0.5, 0.0, 0.5, 1.0]) for _ in range(6)]))
        s[f"task-random-rules-{k}"] = (config_raw(fmt, {**table, "mode": k % 3, "search.batch": 2}) + NO_PRIOR
                                       + seed(70 + k) + EXERCISE + EXERCISE)
    s.update({
        "task-bad-rule-input": config({"task.rule_input[2]": 4}) + NO_PRIOR + seed(80) + EXERCISE,
        "task-bad-input-sign": config({"task.input_sign[1]": 0}) + NO_PRIOR + seed(84) + EXERCISE,
        "task-bad-units": config({"mode": 1, "critic.units[0]": 16, "critic.units[1]": 16}) + NO_PRIOR + seed(81),
        "task-retune-inputs-and-grid": (config({"mode": 1}) + NO_PRIOR + seed(82) + EXERCISE
                                        + retune({"task.n_inputs": 3}) + retune({"critic.units[2]": 5})
                                        + retune({"task.rule_threshold[0]": 0.1, "task.late_source": 1}) + EXERCISE),
        "task-six-inputs-prior": (config_raw(fmt, {**six, "mode": 1}) + prior(("mean5", 2.0), ((5, 4), 0.3, True))
                                  + seed(83) + six_exercise),
    })
    for mode, name in ((0, "ico"), (1, "rl"), (2, "search")):
        # the same terminal tick again and again: one trial recorded, then refused until reset
        s[f"{name}-terminal-repeated"] = (config({"mode": mode, "search.batch": 2}) + NO_PRIOR + seed(51 + mode)
                                          + steps((0.1, 0.0, 0.01, 0.0), 5)
                                          + steps((2.5, 1.0, "0.25", 1.0), 16, terminal=True)
                                          + steps(ZERO, 3) + step(("nan", "0", "0", "0")) + RESET + EXERCISE)
    s.update({
        # Known reproducers of the tick contract.
        "repro-rl-critic-range0-1e-39": config({**rl, "critic.range[0]": "1e-39"}) + NO_PRIOR + seed(1) + step(ZERO),
        "repro-rl-noise-std-1e-20": (config({**rl, "actor.noise_std": "1e-20"}) + NO_PRIOR + seed(1) + steps(ZERO, 3)
                                     + EXERCISE),
        "repro-input-range0-1e-39": (config({"policy.input_range[0]": "1e-39"}) + NO_PRIOR + seed(1) + step(ZERO)
                                     + EXERCISE),
        "repro-noclip-x-1e30": (config({"policy.clip_inputs": 0}) + NO_PRIOR + seed(1)
                                + steps(("1e30", "0", "0", "0"), 3)),
        # Found by fuzzing the fixed firmware: a finite prior mean whose |w| overflows.
        "repro-prior-mean-1e30": config() + prior(("mean0", "1e30")) + seed(1) + EXERCISE,
    })
    for label, field, v in (("gain", "policy.gain", "1e30"), ("reflex-force", "policy.reflex_force", "1e38"),
                            ("ico-rate", "ico.rate", "1e30"), ("noise-std", "actor.noise_std", "1e30")):
        s[f"repro-ico-{label}-{v}"] = config({field: v}) + NO_PRIOR + seed(1) + EXERCISE
        s[f"repro-rl-{label}-{v}"] = config({**rl, field: v}) + NO_PRIOR + seed(1) + EXERCISE
    return s


# ---- fuzz_state ----

# The named fields of icoac_priv_state_t a patch sets (state_fields in fuzz_state.c, in its
# order): (name, kind) with kind "i" int32, "u" uint32, "b" uint8, "q" uint64, "r" real.
STATE_FIELDS = [
    ("has_prev", "i"), ("grid.n", "b"), ("grid.split", "b"), ("grid.shape", "b"), ("inv_range", "r"), ("w", "r"), ("weight_norm", "r"), ("w_act", "r"), ("cov_slot", "i"),
    ("active_slot", "i"), ("x_prev", "r"), ("penalty_prev", "r"), ("value_prev", "r"), ("noise_prev", "r"),
    ("trial_ticks", "u"), ("rng.state", "q"), ("rng.increment", "q"), ("rng.spare_normal", "r"),
    ("rng.has_spare", "i"), ("counters", "u"), ("cov_buffer", "r"), ("active.sparse.product", "r"),
    ("active.sparse.index", "b"),
    ("active.sparse.cells", "b"), ("active.sparse.rows", "b"), ("active.sparse.stride", "b"),
    ("active.dense.product", "r"), ("active.dense.cell_begin", "b"), ("active.dense.cell_end", "b"),
    ("active.dense.rows", "b"), ("active.dense.stride", "b"), ("v", "r"), ("batch.info", "r"), ("batch.shift", "r"),
    ("batch.staged_shift", "r"), ("search.w", "r"), ("search.ticks", "u"), ("search.lower", "r"),
    ("search.floor", "r"), ("search.prior_var", "r"), ("search.count", "i"),
]
STATE_FIELD_NAMES = [name for name, _ in STATE_FIELDS]
PATCH_HEADER, PATCH_CONFIG, PATCH_RAW = len(STATE_FIELDS), len(STATE_FIELDS) + 1, len(STATE_FIELDS) + 2
# sizeof(icoac_state_t) with float and with double reals (ICOAC_STATE_SIZE).
STATE_SIZES = {"f": 2880, "d": 5440}


def patch(field, v, index=0, fmt="f"):
    """Set element index of a named state field to v (int32 fields: a table value or any int32;
    uint8: 0..255; uint64: an int; real: as real())."""
    k = STATE_FIELD_NAMES.index(field)
    kind = STATE_FIELDS[k][1]
    if kind in "iu":
        value_bytes = int32(v - 2**32 if kind == "u" and v >= 2**31 else v)
    elif kind == "b":
        value_bytes = bytes([v])
    elif kind == "q":
        value_bytes = struct.pack("<Q", v)
    else:
        value_bytes = real(v, fmt)
    return bytes([k, index]) + value_bytes


def patch_header(ended):
    return bytes([PATCH_HEADER, 1 if ended else 0])


def patch_config(fields, fmt="f"):
    return bytes([PATCH_CONFIG]) + config(fields, fmt)


def patch_raw(offset, data):
    return bytes([PATCH_RAW]) + struct.pack("<H", offset) + bytes([len(data)]) + data


def state_setup(kind, mode, init_fields=None, prior_section=NO_PRIOR, seed_value=1, warm_ticks=10, warm_trials=1,
                fmt="f"):
    """Kind byte (0 raw configuration, 1 raw state), then a valid state of the mode: config
    mutations init_fields (its mode is replaced), prior, seed and the warm-up byte."""
    assert 0 <= warm_ticks < 32 and 1 <= warm_trials <= 8
    return (bytes([kind, mode]) + config(init_fields, fmt) + prior_section + seed(seed_value)
            + bytes([(warm_trials - 1) << 5 | warm_ticks]))


def raw_config(mode, fields=None, fmt="f", **setup):
    """Kind A: fields written into the state's configuration copy (no check)."""
    return state_setup(0, mode, fmt=fmt, **setup) + config(fields, fmt)


def raw_state(mode, patches=(), ended=False, fmt="f", **setup):
    """Kind B: named-field patches of a valid state, then the header word."""
    assert len(patches) < 64
    return state_setup(1, mode, fmt=fmt, **setup) + bytes([len(patches) << 2 | (1 if ended else 0)]) + b"".join(patches)


def filled_state(mode, data, ended=False, fmt="f", **setup):
    """Kind B: the whole state from data (sizeof(icoac_state_t) bytes), then the header word."""
    assert len(data) == STATE_SIZES[fmt]
    return state_setup(1, mode, fmt=fmt, **setup) + bytes([2 | (1 if ended else 0)]) + data


def tick(s=None, repeat=1, terminal=False):
    """repeat (1..8) ticks on s (4 values), or on the previous s when None."""
    assert 1 <= repeat <= 8
    op = (1 if terminal else 0) | ((repeat - 1) << 3) | (0x40 if s is None else 0)
    return bytes([op]) + (b"".join(real(x) for x in s) if s is not None else b"")


def ticks(s, n, terminal=False):
    out = tick(s, min(n, 8), terminal)
    n -= min(n, 8)
    while n > 0:
        out += tick(None, min(n, 8), terminal)
        n -= min(n, 8)
    return out


S_RESET = b"\x02"
S_RETUNE_SETUP = b"\x04"
S_GET = b"\x05"


def s_retune(fields=None, over_setup=False, fmt="f"):
    """icoac_retune with a config section over the state's configuration (or the setup one)."""
    return bytes([0x0B if over_setup else 0x03]) + config(fields, fmt)


def s_edit(fields, fmt="f"):
    """Fields written into the state's configuration copy, no check."""
    return b"\x06" + config(fields, fmt)


def s_patch(p):
    return b"\x07" + p


FAIL = (2.5, 1.0, "0.25", 1.0)
# Ticks, a non-finite one, a terminal one, ticks after it, a new trial, the retunes and getters.
STATE_EXERCISE = (S_GET + ticks((0.1, 0.0, 0.01, 0.0), 4) + tick(("nan", "0", "0", "0")) + tick(FAIL, terminal=True)
                  + ticks(None, 2) + S_GET + S_RESET + ticks((-0.3, 0.2, -0.1, 0.5), 8) + S_RETUNE_SETUP
                  + s_retune({"policy.gain": 5.0}) + s_retune({"mode": 1, "learn": 0}) + S_GET
                  + tick(FAIL, terminal=True) + S_RESET + ticks(ZERO, 3) + S_GET)


def trials(n, length, s=(0.1, -0.2, 0.02, 0.3), before_terminal=b"", after_reset=b""):
    """n trials: reset, after_reset, length ticks, before_terminal, a terminal tick."""
    return (S_RESET + after_reset + ticks(s, length) + before_terminal + tick(FAIL, terminal=True)) * n


def state_seeds(fmt):
    """Seeds of the fuzz_state targets; fmt is the real type's struct code."""
    size = STATE_SIZES[fmt]
    noise = random.Random(20261202)
    s = {}
    for mode, name in ((0, "ico"), (1, "rl"), (2, "search")):
        s[f"config-{name}-unchanged"] = raw_config(mode, fmt=fmt) + STATE_EXERCISE
        s[f"config-{name}-raw"] = (state_setup(0, mode, fmt=fmt, warm_trials=2)
                                   + config_raw(fmt, {"mode": mode, "search.batch": 2, "actor.update": 0})
                                   + STATE_EXERCISE)
        s[f"state-{name}-unchanged"] = raw_state(mode, fmt=fmt, warm_trials=3) + STATE_EXERCISE
        s[f"state-{name}-ended"] = raw_state(mode, ended=True, fmt=fmt) + STATE_EXERCISE
        s[f"state-{name}-zeros"] = filled_state(mode, bytes(size), fmt=fmt) + STATE_EXERCISE
        s[f"state-{name}-ones"] = filled_state(mode, b"\xff" * size, fmt=fmt) + STATE_EXERCISE
        s[f"state-{name}-random"] = (filled_state(mode, bytes(noise.randrange(256) for _ in range(size)), fmt=fmt)
                                     + STATE_EXERCISE)
    s.update({
        "config-raw-garbage": (state_setup(0, 1, fmt=fmt) + b"\x01"
                               + bytes(noise.randrange(256) for _ in range(CONFIG_SIZES[fmt])) + STATE_EXERCISE),
        "config-bad-groups": (raw_config(1, {"critic.range[0]": "0", "critic.threshold": "nan", "actor.noise_std": "inf",
                                             "critic.td_clip": "-1", "critic.discount": "1e30", "actor.forgetting": "0",
                                             "actor.likelihood_std": "-1"}, fmt=fmt) + STATE_EXERCISE),
        "config-search-bad-groups": (raw_config(2, {"search.step": "nan", "search.floor": "-1", "search.cov_scale": "0",
                                                    "search.batch": 0}, fmt=fmt, init_fields={"search.batch": 2})
                                     + trials(4, 3) + STATE_EXERCISE),
        "rl-actor-update-9": raw_config(1, {"actor.update": 9}, fmt=fmt) + ticks(ZERO, 3) + STATE_EXERCISE,
        # the task in the copy: its input count, rules and critic geometry hold anything
        "task-copy-corrupt": (raw_config(1, {"task.n_inputs": 200, "task.n_rules": -3, "task.rule_input[0]": 99,
                                             "critic.units[1]": 40, "task.late_source": 5}, fmt=fmt)
                              + ticks(ZERO, 4) + S_RESET + STATE_EXERCISE),
        "task-grid-corrupt": (raw_state(1, [patch("grid.n", 255), patch("grid.split", 9), patch("grid.shape", 255, 0), patch("active.sparse.rows", 200, 0),
                                            patch("active.sparse.stride", 200, 1), patch("active.dense.rows", 255, 0),
                                            patch("active.dense.stride", 255, 1)], fmt=fmt) + ticks(ZERO, 4)
                              + STATE_EXERCISE),
        # the shape tag cleared: the general kernels on the cart-pole's configuration
        "task-shape-general": (raw_state(1, [patch("grid.shape", 0, 0)], fmt=fmt) + ticks(ZERO, 4)
                               + STATE_EXERCISE),
        # the rule-layout tag against the table: set on a table of another layout (the tick reads
        # the preset's inputs and sides, the table's thresholds), cleared on the preset (the loop)
        "task-rules-tag-other-table": (raw_state(0, [patch("grid.shape", 1, 0)], fmt=fmt,
                                                 init_fields={"task.rule_side[2]": 1, "task.rule_input[3]": 1})
                                       + ticks(ZERO, 4) + STATE_EXERCISE),
        "task-rules-tag-cleared": (raw_state(0, [patch("grid.shape", 0, 0)], fmt=fmt) + ticks(ZERO, 4)
                                   + STATE_EXERCISE),
        "task-sensor-copy": (raw_config(0, {"task.late_source": 1}, fmt=fmt) + ticks(ZERO, 2)
                             + bytes([0x80]) + real(1.0) + bytes([0x80]) + real("nan") + STATE_EXERCISE),
        "rl-actor-update-9-batch": (raw_config(1, {"actor.update": 9}, fmt=fmt, init_fields={"actor.batch": 1})
                                    + ticks(ZERO, 3) + tick(FAIL, terminal=True) + STATE_EXERCISE),
        "rl-explore-negative": (raw_config(1, {"actor.explore_ticks": -1}, fmt=fmt) + ticks(ZERO, 4)
                                + s_patch(patch("trial_ticks", 2**32 - 1)) + ticks(ZERO, 3) + STATE_EXERCISE),
        # the kept-unit lists of both critic kernels, and the slots, hold anything
        "rl-kept-units-corrupt": (raw_state(1, [patch("active.sparse.index", 255, i) for i in range(18)]
                                            + [patch("active.sparse.index", 255, i) for i in range(9, 74, 5)]
                                            + [patch("active.sparse.cells", 255, 0), patch("active.sparse.cells", 255, 1),
                                               patch("active.dense.cell_begin", 0, 0), patch("active.dense.cell_end", 255, 0),
                                               patch("active.dense.cell_begin", 0, 1), patch("active.dense.cell_end", 255, 1)],
                                            fmt=fmt, init_fields={"critic.threshold": "0"}) + ticks(ZERO, 4)
                                  + STATE_EXERCISE),
        "rl-dense-range-inverted": (raw_state(1, [patch("active.dense.cell_begin", 200, 0),
                                                  patch("active.dense.cell_end", 3, 0),
                                                  patch("active.dense.cell_begin", 17, 1),
                                                  patch("active.dense.cell_end", 18, 1)], fmt=fmt) + ticks(ZERO, 3)),
        "rl-sparse-products-nan": (raw_state(1, [patch("active.sparse.product", "nan", i) for i in range(9)]
                                             + [patch("active.sparse.product", "inf", i) for i in range(9, 74, 7)],
                                             fmt=fmt) + ticks(ZERO, 3) + STATE_EXERCISE),
        "rl-learned-nonfinite": (raw_state(1, [patch("w", "nan", 1), patch("weight_norm", "inf"),
                                               patch("cov_buffer", "nan", 5), patch("v", "nan", 80),
                                               patch("x_prev", "1e30", 2), patch("value_prev", "-inf"),
                                               patch("noise_prev", "max")], fmt=fmt) + STATE_EXERCISE),
        # critic weights are not checked by icoac_reset: the ticks reading them fail instead
        "rl-critic-weights-nan": (raw_state(1, [patch("v", "nan", i) for i in range(0, 176, 3)], fmt=fmt)
                                  + S_RESET + ticks(ZERO, 4) + ticks((0.1, 0.0, 0.01, 0.0), 4) + STATE_EXERCISE),
        "rl-batch-sums": (raw_state(1, [patch("batch.info", "nan", 0), patch("batch.shift", "max", 1),
                                        patch("batch.staged_shift", "-inf", 2)], fmt=fmt,
                                    init_fields={"actor.batch": 1, "actor.update": 0}) + ticks(ZERO, 3)
                          + tick(FAIL, terminal=True) + STATE_EXERCISE),
        "rl-rng-stalled": (raw_state(1, [patch("rng.state", 0), patch("rng.increment", 0), patch("rng.has_spare", 0)],
                                     fmt=fmt, init_fields={"actor.act_with_sample": 1}) + S_RESET + ticks(ZERO, 8)
                           + STATE_EXERCISE),
        "rl-rng-spare": (raw_state(1, [patch("rng.has_spare", 7), patch("rng.spare_normal", "nan")], fmt=fmt)
                         + ticks(ZERO, 2) + S_RESET + STATE_EXERCISE),
        "rl-counters-wrap": (raw_state(1, [patch("counters", 2**32 - 1, 0), patch("counters", 2**32 - 1, 1),
                                           patch("counters", 2**32 - 1, 2), patch("trial_ticks", 2**32 - 1)], fmt=fmt,
                                       init_fields={"actor.explore_ticks": 0}) + ticks(ZERO, 2)
                             + tick(("nan", "0", "0", "0")) + STATE_EXERCISE),
        "ico-timing-literal-caches": (raw_state(0, [patch("has_prev", 5), patch("penalty_prev", "nan"),
                                                    patch("x_prev", "inf", 0), patch("inv_range", "max", 3)],
                                                fmt=fmt, init_fields={"ico.timing": 1}) + ticks(FAIL, 2) + STATE_EXERCISE),
        "search-record-corrupt": (raw_state(2, [patch("search.count", 15), patch("search.ticks", 2**32 - 1, 3),
                                                patch("search.w", "nan", 7), patch("search.lower", "inf", 5),
                                                patch("search.floor", "-1", 0), patch("search.prior_var", "0", 2)],
                                            fmt=fmt) + tick(FAIL, terminal=True) + trials(3, 2) + STATE_EXERCISE),
        "search-count-negative": (raw_state(2, [patch("search.count", -1)], fmt=fmt, init_fields={"search.batch": 3})
                                  + trials(2, 2) + tick(FAIL, terminal=True) + S_RESET
                                  + s_patch(patch("search.count", -2**31)) + tick(FAIL, terminal=True)),
        "header-flips": (raw_state(2, [], fmt=fmt, init_fields={"search.batch": 2}) + tick(FAIL, terminal=True)
                         + s_patch(patch_header(False)) + tick(FAIL, terminal=True) + s_patch(patch_header(False))
                         + tick(FAIL, terminal=True) + s_patch(patch_header(True)) + ticks(ZERO, 2) + S_GET),
        "raw-patches": (raw_state(1, [patch_raw(0, b"\xff" * 64), patch_raw(size - 3, b"\x01\x02\x03\x04\x05"),
                                      patch_config({"mode": 2, "search.batch": 1}, fmt)], fmt=fmt)
                        + STATE_EXERCISE),
        # Known reproducers (the issue): (i) search.batch = 1000 in the copy wrote past the batch
        # arrays (search.w[16], search.ticks[16]) after 16 trials
        "repro-search-batch-1000": (raw_config(2, {"search.batch": 1000}, fmt=fmt) + trials(40, 20)),
        # ... the copy rewritten after each (checked) reset, so the trials are recorded
        "repro-search-batch-1000-after-reset": (raw_config(2, fmt=fmt)
                                                + trials(40, 20, after_reset=s_edit({"search.batch": 1000}))),
        "repro-search-count-1000-after-reset": (raw_state(2, [], fmt=fmt)
                                                + trials(20, 3, after_reset=s_patch(patch("search.count", 1000)))),
        # (ii) cov_slot read unmasked: icoac_get_posterior read far outside the state
        "repro-cov-slot-huge": (raw_state(1, [patch("cov_slot", 2**31 - 1), patch("active_slot", -2**31)], fmt=fmt)
                                + S_GET + ticks(ZERO, 3) + S_GET + tick(FAIL, terminal=True) + S_RESET + S_GET
                                + s_patch(patch("cov_slot", 1000001)) + S_GET + ticks(ZERO, 2) + S_GET),
        # (iii) elite_fraction out of range in the copy when a full batch closes: the conversion of
        # round(rho K) to int was undefined
        "repro-search-elite-1e30": (raw_config(2, {"search.elite_fraction": "1e30"}, fmt=fmt,
                                               init_fields={"search.batch": 2})
                                    + tick(FAIL, terminal=True)
                                    + trials(4, 3, before_terminal=s_edit({"search.elite_fraction": "1e30"}),
                                             after_reset=s_edit({"search.elite_fraction": 0.25}))),
        "repro-search-elite-nan": (raw_config(2, {"search.elite_fraction": "nan"}, fmt=fmt, init_fields={"search.batch": 2})
                                   + tick(FAIL, terminal=True)
                                   + trials(2, 3, before_terminal=s_edit({"search.elite_fraction": "nan"}),
                                            after_reset=s_edit({"search.elite_fraction": 0.25}))
                                   + trials(2, 3, before_terminal=s_edit({"search.elite_fraction": "-inf"}),
                                            after_reset=s_edit({"search.elite_fraction": 0.25}))
                                   + trials(2, 3, before_terminal=s_edit({"search.elite_fraction": "max",
                                                                          "search.batch": 16}),
                                            after_reset=s_edit({"search.elite_fraction": 0.25, "search.batch": 2}))),
        # (iv) a repeated terminal tick recorded the same trial again
        "repro-terminal-1000": raw_config(2, fmt=fmt) + ticks((0.1, 0.0, 0.01, 0.0), 10) + ticks(FAIL, 1000, True),
        "repro-terminal-1000-rl": raw_config(1, fmt=fmt) + ticks((0.1, 0.0, 0.01, 0.0), 10) + ticks(FAIL, 1000, True),
        # Found by this target (open): icoac_reset accepts any finite rng.spare_normal, and the RL
        # tick that draws a huge one as its noise returns ICOAC_OK with an infinite force.
        "repro-rl-spare-normal-huge": (raw_state(1, [patch("rng.has_spare", 1), patch("rng.spare_normal", "max")],
                                                 fmt=fmt) + S_RESET + ticks(ZERO, 2)),
        # (v) an unknown mode or ICO timing in the copy fell back to a default with ICOAC_OK
        "repro-mode-99": raw_config(0, {"mode": 99}, fmt=fmt) + STATE_EXERCISE,
        "repro-ico-timing-7": raw_config(0, {"ico.timing": 7}, fmt=fmt) + STATE_EXERCISE,
    })
    return s


def run(**fields):
    assert len(fields) <= 3
    out = bytes([len(fields) << 1])
    for name, v in fields.items():
        out += bytes([RUN_FIELDS.index(name)]) + (double(v) if name == "init_velocity_noise" else int64(v))
    return out


# ---- fuzz_model ----

# The registry in its order (plant_registry.c): name, n_state.
PLANTS = [("cart_pole", 4), ("furuta", 4), ("double_cart_pole", 6)]
MAX_PARAMS = 16
MODEL_FIELDS = ["plant", "integrator", "dt"]  # then 3 + i: param<i>, 3 + MAX_PARAMS + i: bound<i>
# bound<i> selectors: a bound of the range, or past n_params -0, 0, DBL_TRUE_MIN, -DBL_TRUE_MIN
BOUNDS = ["min", "max", "below", "above"]
# op kinds, (o & 7) % 7
M_STEP, M_DERIVATIVES, M_FAILED, M_ENERGY, M_START, M_GRID, M_REGISTRY = range(7)
# NULL pointers of an op (o >= 0xC0): the state array, the output (start: the cell), the rng
NULL_STATE, NULL_OUT, NULL_RNG = 0xC8, 0xD0, 0xE0
GRID_SIZES = ["exact", 0, -1, "exact-1", "exact+1", "max", "min", 1]


def model(of=0, **fields):
    """icoac_sim_model_default of registry plant `of` with mutations (at most 7, in order):
    plant, integrator (int32), dt, param<i> (doubles), bound<i> (a BOUNDS name)."""
    assert len(fields) <= 7
    out = bytes([len(fields) << 2, of])
    for name, v in fields.items():
        if name in ("plant", "integrator"):
            out += bytes([MODEL_FIELDS.index(name)]) + int32(v)
        elif name == "dt":
            out += bytes([2]) + double(v)
        elif name.startswith("param"):
            out += bytes([3 + int(name[5:])]) + double(v)
        else:
            out += bytes([3 + MAX_PARAMS + int(name[5:]), BOUNDS.index(v)])
    return out


def model_raw(plant, integrator, dt, params, over=0):
    """Raw icoac_sim_model_t bytes laid over the default of registry plant `over`."""
    params = list(params) + [0.0] * (MAX_PARAMS - len(params))
    return b"\x01" + bytes([over]) + struct.pack("<iid16d", plant, integrator, dt, *params)


NULL_MODEL = b"\x03\x00"
THETA_LIMIT = 12.0 * math.pi / 180.0  # the cart-pole's default, as cart_pole.c computes it


def op_state(kind, s, u=None, nulls=0):
    """step, derivatives (with u), failed or energy on s (padded to 6 values with 0)."""
    s = list(s) + ["0"] * (6 - len(s))
    out = bytes([kind | nulls]) + b"".join(double(x) for x in s)
    return out + (double(u) if kind in (M_STEP, M_DERIVATIVES) else b"")


def op_start(x0, theta0, cell_seed, noise, rng_seed, nulls=0):
    return (bytes([M_START | nulls]) + double(x0) + double(theta0) + bytes([cell_seed]) + double(noise)
            + bytes([rng_seed]))


def op_model_grid(index, size="exact", grid_seed=7, null=False):
    return bytes([M_GRID]) + int32(index) + bytes([GRID_SIZES.index(size) | (0x80 if null else 0), grid_seed])


def op_registry(index, name=None):
    """name: None (NULL), ("plant", i) its name, ("truncated", i) less its last character, or a str."""
    out = bytes([M_REGISTRY]) + int32(index)
    if name is None:
        return out + b"\x00"
    if isinstance(name, tuple):
        return out + bytes([1 if name[0] == "plant" else 2, name[1]])
    raw = name.encode()
    return out + bytes([3, len(raw)]) + raw


# Run ops (op bytes 0x80..0xBF): kind, and NULL pointers with RUN_NULLS (the configuration, the
# cell / cells / trajectory states, the run / trajectory forces).
R_CELL, R_GRID, R_TRAJECTORY, R_CANCELLED = 0x80, 0x81, 0x82, 0x83
RUN_NULLS, NULL_CFG, NULL_CELLS, NULL_RUN = 0x20, 0x24, 0x28, 0x30
PRESETS = [None, "success", "failed", "error"]


def grid_cell(i, grid_seed=1, preset=None):
    """Cell i of the plant byte's grid with grid_seed; preset: a finished outcome (grid op)."""
    return bytes([PRESETS.index(preset) << 1, grid_seed]) + struct.pack("<H", i)


def xy_cell(x0, theta0, cell_seed=1, preset=None):
    return bytes([1 | PRESETS.index(preset) << 1]) + double(x0) + double(theta0) + bytes([cell_seed])


def op_run_cell(cell, run_=None, cfg=None, prior_=NO_PRIOR, nulls=0):
    """icoac_sim_run_cell; run_ and cfg default to run() and config()."""
    return bytes([R_CELL | nulls]) + (run_ or run()) + (cfg or config()) + prior_ + cell


def op_run_grid(cells, threads=1, run_=None, cfg=None, prior_=NO_PRIOR, nulls=0, cancelled=False):
    """icoac_sim_run_grid on 0 to 4 cells (cell specs)."""
    count = len(cells) - 1 if cells else 31
    return (bytes([(R_CANCELLED if cancelled else R_GRID) | nulls]) + (run_ or run()) + (cfg or config()) + prior_
            + bytes([count, {1: 0, 2: 13, -1: 15}[threads]]) + b"".join(cells))


def op_run_trajectory(cell, noise, max_steps, cfg=None, prior_=NO_PRIOR, nulls=0, null_steps=False):
    return (bytes([R_TRAJECTORY | nulls]) + (cfg or config()) + prior_ + cell + double(noise)
            + bytes([(max_steps + 1) | (0x80 if null_steps else 0)]))


SMALL_RUN = run(max_trials=3, success_steps=300)
ONE_TRIAL = run(max_trials=1, success_steps=300)
RL = config({"mode": 1})


def run_ops(p):
    """Each run op once on plant p's model within the tick budget: ICO and RL cells, a grid with a
    finished cell, a trajectory."""
    return (op_run_cell(grid_cell(600), ONE_TRIAL) + op_run_cell(xy_cell(0.1, 0.02, 3), SMALL_RUN, RL)
            + op_run_grid([grid_cell(0, 2), grid_cell(612, 2, "success"), xy_cell(-0.5, -0.05, 4)], 2, ONE_TRIAL)
            + op_run_trajectory(grid_cell(612, 5), "0.01", 64))


def control_ops(cfg, prior_=NO_PRIOR, run_=None):
    """A cell, a grid of two cells and a trajectory with one configuration, prior and run."""
    return (op_run_cell(xy_cell(0.5, 0.05, 1), run_, cfg, prior_)
            + op_run_grid([xy_cell(0.0, 0.02, 2), xy_cell(-1.0, -0.1, 3)], 1, run_, cfg, prior_)
            + op_run_trajectory(xy_cell(0.5, 0.1, 4), "0", 64, cfg, prior_))


def model_ops(p):
    """Every op once on plant p's model, with small values."""
    n = PLANTS[p][1]
    s = [0.01 * (i + 1) for i in range(n)]
    return (op_state(M_STEP, s, 0.5) + op_state(M_DERIVATIVES, s, -1.0) + op_state(M_FAILED, s)
            + op_state(M_ENERGY, s) + op_start(0.5, 0.05, 1, 0.01, 2) + op_model_grid(p)
            + op_registry(p, ("plant", p)))


def model_seeds():
    nulls = (op_state(M_STEP, [], 0.0, NULL_STATE) + op_state(M_DERIVATIVES, [0.1], 0.0, NULL_OUT)
             + op_state(M_FAILED, [], nulls=NULL_STATE | NULL_OUT) + op_state(M_ENERGY, ["nan"], nulls=NULL_OUT)
             + op_start(0.0, 0.0, 1, "0", 1, NULL_STATE) + op_start(0.0, 0.0, 1, "0", 1, NULL_OUT)
             + op_start(0.0, 0.0, 1, "0", 1, NULL_RNG))
    s = {}
    for p, (name, n) in enumerate(PLANTS):
        s[f"{name}-default"] = model(p) + model_ops(p)
        s[f"{name}-rk4"] = model(p, integrator=1) + model_ops(p) + op_state(M_STEP, [0.2] * n, 5.0)
        s[f"{name}-bounds"] = (model(p, dt="1e-6", bound0="min", bound1="max", bound3="min", bound15="min")
                               + model_ops(p) + op_state(M_STEP, [], 0.0))
        s[f"{name}-param-below"] = model(p, bound0="below") + model_ops(p)
        s[f"{name}-param-above"] = model(p, integrator=1, bound1="above") + model_ops(p)
        s[f"{name}-unused-param"] = model(p, bound15="below") + model_ops(p)
        s[f"{name}-param-nan"] = model(p, param2="nan") + model_ops(p)
        s[f"{name}-nonfinite"] = (model(p) + op_state(M_STEP, ["nan"], 0.0) + op_state(M_STEP, [], "inf")
                                  + op_state(M_DERIVATIVES, [0.0, "-inf"], 0.0) + op_state(M_DERIVATIVES, [], "nan")
                                  + op_state(M_FAILED, ["0"] * (n - 1) + ["inf"]) + op_state(M_FAILED, ["nan"])
                                  + op_state(M_ENERGY, ["0", "nan"]) + op_state(M_ENERGY, ["-inf"]))
        s[f"{name}-overflow"] = (model(p, integrator=1) + op_state(M_STEP, [], "max")
                                 + op_state(M_STEP, ["1e300"] * n, 0.0)
                                 + op_state(M_DERIVATIVES, ["1e300"] * n, "max") + op_state(M_ENERGY, ["1e300"] * n)
                                 + op_state(M_FAILED, ["1e300"] * n) + op_state(M_FAILED, [2.4, "0", "-2.4"]))
        s[f"{name}-nulls"] = model(p) + nulls
        s[f"{name}-start"] = (model(p) + op_start(0.5, 0.05, 1, "0", 2) + op_start(-2.4, "-2.4", 3, "1e-6", 4)
                              + op_start("max", "-max", 5, 0.01, 6) + op_start(0.0, 0.0, 7, "1e-20", 8)
                              + op_start(0.0, 0.0, 7, "1e6", 9) + op_start(0.0, 0.0, 7, "-1", 10)
                              + op_start(0.0, 0.0, 7, "nan", 11) + op_start("inf", 0.0, 7, "0", 12)
                              + op_start(0.0, "nan", 7, "0", 13) + op_start(0.0, 0.0, 7, "1e-310", 14))
        s[f"{name}-grid"] = (model(p) + b"".join(op_model_grid(p, size, 3) for size in GRID_SIZES)
                             + op_model_grid(p, null=True))
    for p, (name, n) in enumerate(PLANTS):
        s[f"{name}-runs"] = model(p) + run_ops(p)
        s[f"{name}-runs-rk4"] = model(p, integrator=1, dt=0.02) + run_ops(p)
    run_nulls = (op_run_cell(grid_cell(1), nulls=NULL_CFG) + op_run_cell(grid_cell(1), nulls=NULL_CELLS)
                 + op_run_cell(grid_cell(1), nulls=NULL_RUN)
                 + op_run_grid([grid_cell(1)], nulls=NULL_CFG) + op_run_grid([grid_cell(1)], nulls=NULL_CELLS)
                 + op_run_grid([grid_cell(1)], nulls=NULL_RUN)
                 + op_run_trajectory(grid_cell(1), "0", 8, nulls=NULL_CFG)
                 + op_run_trajectory(grid_cell(1), "0", 8, nulls=NULL_CELLS)
                 + op_run_trajectory(grid_cell(1), "0", 8, nulls=NULL_RUN)
                 + op_run_trajectory(grid_cell(1), "0", 8, null_steps=True))
    bad_args = (op_run_cell(xy_cell("nan", 0.0)) + op_run_cell(xy_cell(0.0, "-inf"))
                + op_run_grid([]) + op_run_grid([grid_cell(1)], threads=-1)
                + op_run_grid([grid_cell(1), xy_cell("inf", 0.0, 2, "failed")])
                + op_run_trajectory(grid_cell(1), "0", 0) + op_run_trajectory(grid_cell(1), "0", -1)
                + op_run_trajectory(xy_cell("nan", 0.0), "0", 8) + op_run_trajectory(grid_cell(1), "1e-20", 8)
                + op_run_trajectory(grid_cell(1), "-1", 8) + op_run_trajectory(grid_cell(1), "inf", 8)
                + op_run_trajectory(grid_cell(1), "1e6", 8))
    # checks in order: config, model, observation fit, run; then arguments, then the prior
    bad_config = config({"mode": 3})
    bad_run = run(max_trials=0)
    bad_prior = prior(((2, 2), "-1"))
    order = (op_run_cell(xy_cell("nan", 0.0), bad_run, bad_config, bad_prior)
             + op_run_cell(xy_cell("nan", 0.0), bad_run, None, bad_prior)
             + op_run_cell(xy_cell("nan", 0.0), None, None, bad_prior) + op_run_cell(grid_cell(1), None, None, bad_prior)
             + op_run_grid([], -1, bad_run, bad_config, bad_prior) + op_run_grid([], -1, bad_run, None, bad_prior)
             + op_run_grid([grid_cell(1)], 1, None, None, bad_prior)
             + op_run_trajectory(xy_cell("nan", 0.0), "-1", 0, bad_config, bad_prior)
             + op_run_trajectory(grid_cell(1), "0", 8, None, bad_prior))
    s.update({
        "runs-nulls": model(0) + run_nulls,
        "runs-null-model": NULL_MODEL + run_nulls + op_run_cell(grid_cell(1), cfg=config({"mode": 3})),
        "runs-bad-arguments": model(1) + bad_args,
        "runs-order-cart-pole": model(0) + order,
        "runs-order-bad-model": model(1, param0="nan") + order,
        "runs-order-unfit-plant": model(2) + order,
        "runs-order-unused-param": model(0, param15=1.0) + order,
        # -0 as an unused parameter: accepted
        "runs-unused-param-minus-0": model(0, bound15="min") + run_ops(0),
        "runs-cancelled": (model(1) + op_run_grid([grid_cell(3), grid_cell(5, 1, "failed")], 2, cancelled=True)
                           + op_run_grid([grid_cell(3, 1, "error")], cancelled=True)
                           + op_run_grid([grid_cell(3)], nulls=NULL_CFG, cancelled=True)),
        "runs-presets": (model(0) + op_run_grid([grid_cell(0, 1, "success"), grid_cell(1, 1, "failed"),
                                                 grid_cell(2, 1, "error"), xy_cell(0.0, 0.0, 1, "success")], 2)
                         + op_run_grid([grid_cell(7), grid_cell(8), grid_cell(9), grid_cell(10)], 2, ONE_TRIAL)),
        "runs-rl-prior": (model(1) + op_run_cell(grid_cell(100), SMALL_RUN, RL, prior(("mean2", 5.0), ("mean3", 1.0)))
                          + op_run_trajectory(grid_cell(100), "0", 64, RL, prior(("mean2", 5.0)))),
        "runs-search": (model(0) + op_run_cell(grid_cell(300), run(max_trials=3, success_steps=10),
                                               config({"mode": 2, "search.batch": 1}))
                        + op_run_grid([grid_cell(301), grid_cell(302)], 2, run(max_trials=3, success_steps=10),
                                      config({"mode": 2, "search.batch": 2}))),
        "runs-fall": (model(1, dt=0.1) + op_run_trajectory(xy_cell(0.0, 0.2, 9), "0.01", 64, config({"policy.gain": "0"}))
                      + op_run_cell(xy_cell(0.0, 0.2, 9), SMALL_RUN, config({"policy.gain": "0"}))
                      + op_run_trajectory(xy_cell("1e300", "-1e30", 9), "0", 64)),
        "runs-noise": (model(0) + op_run_cell(grid_cell(11), run(max_trials=3, success_steps=300,
                                                                 init_velocity_noise="1e-6"))
                       + op_run_trajectory(grid_cell(11), "1e-6", 64) + op_run_trajectory(grid_cell(11), 3.0, 64)),
        "null-model": NULL_MODEL + model_ops(0) + nulls,
        "raw-cart-pole": model_raw(0, 0, 0.01, [9.8, 1.0, 0.1, 0.5, 2.4, 12.0 * math.pi / 180.0]) + model_ops(0),
        "raw-garbage": model_raw(7, 2, float("nan"), [float("inf")] * MAX_PARAMS, over=2) + model_ops(2),
        "bad-plant-index": model(1, plant=-1) + model_ops(1),
        "bad-plant-index-count": model(2, plant=3) + model_ops(2),
        "bad-plant-index-max": model(0, plant=2**31 - 1) + model_ops(0),
        "bad-dt": model(0, dt="1e-310") + model_ops(0),
        "dt-max": model(1, dt="1", bound2="max") + model_ops(1),
        "bad-dt-above": model(1, dt="2") + model_ops(1),
        "bad-integrator": model(2, integrator=2) + model_ops(2),
        "registry": (model(0) + op_registry(0, None) + op_registry(1, "") + op_registry(2, "no_such_plant")
                     + op_registry(3, ("plant", 0)) + op_registry(-1, ("plant", 1))
                     + op_registry(2**31 - 1, ("plant", 2))
                     + op_registry(-2**31, ("truncated", 0)) + op_registry(1, ("truncated", 2))
                     + op_registry(0, "cart_pole") + op_registry(1, "furuta_") + op_registry(2, "DOUBLE_CART_POLE")),
        "grid-bad-index": (model(0) + op_model_grid(-1) + op_model_grid(3, "exact-1") + op_model_grid(2**31 - 1, "max")
                           + op_model_grid(-2**31, "min", null=True)),
        # the cart-pole's failure test at and just past its limits (2.4 m, 12 deg)
        "cart-pole-failed-limits": (model(0) + op_state(M_FAILED, ["2.4", "0", Exact(THETA_LIMIT), "0"])
                                    + op_state(M_FAILED, ["-2.4", "0", Exact(-THETA_LIMIT), "0"])
                                    + op_state(M_FAILED, [Exact(math.nextafter(2.4, math.inf)), "0", "0", "0"])
                                    + op_state(M_FAILED, ["0", "0", Exact(math.nextafter(THETA_LIMIT, math.inf)), "0"])
                                    + op_state(M_FAILED, ["0", "inf", "0", "0"])
                                    + op_state(M_FAILED, ["0", "0", "0", "nan"])),
        # learners and settings of the runs
        "runs-rl-literal": model(0) + control_ops(config({"mode": 1, "actor.update": 0, "actor.explore_ticks": 0})),
        "runs-rl-learners": model(0) + control_ops(config({"mode": 1, "actor.update": 1, "actor.batch": 1,
                                                           "actor.explore_ticks": 50, "critic.quirks": 1})),
        "runs-search-prior": model(0) + control_ops(config({"mode": 2, "search.batch": 1, "search.cov_scale": 4.0}),
                                                    prior(("mean2", 5.0), ("mean3", 1.0)), run(max_trials=3)),
        "runs-rk4-noise": model(0, integrator=1) + control_ops(config(), run_=run(init_velocity_noise=0.1)),
        # Known reproducers of the runs' contract: a subnormal dt passed the plant check; float
        # subnormals in the configuration or prior were checked as given, then flushed to 0 in the
        # run (FTZ/DAZ), so the verdicts differed.
        "repro-runs-dt-1e-310": model(0, dt="1e-310") + control_ops(config()),
        "repro-runs-config-zone-theta-1e-39": model(0) + control_ops(config({"task.rule_threshold[0]": "1e-39"})),
        "repro-runs-prior-cov-diag-1e-39": model(0) + control_ops(config(), prior(((0, 0), "1e-39"))),
        "repro-runs-prior-cov-asymmetric-1e-39": model(0) + control_ops(config(), prior(((3, 0), "-1e-39"))),
    })
    return s


# ---- fuzz_batch.c --------------------------------------------------------------------------

def b_lane(mode, fields=None, prior_section=NO_PRIOR, seed_byte=1):
    """A lane: mode byte (% 3: ICO, RL, search; 4: literal timing; 8: sensor task), config, prior."""
    return bytes([mode]) + config(fields) + prior_section + bytes([seed_byte])


def b_tick(flags, rotation=0, inputs=None, reflexes=None):
    """A batch tick: per lane a flags byte (3 terminal, 4 late with a reflex), fresh inputs (a
    list per lane of MAX_INPUTS values) or the previous ones moved by (f & 7) / 100."""
    out = bytes([8 if inputs is not None else 0, rotation])
    for i, f in enumerate(flags):
        out += bytes([f])
        if inputs is not None:
            out += b"".join(real(v) for v in inputs[i])
        if f & 4:
            out += real((reflexes or {}).get(i, 0.5))
    return out


def b_op(op, lane, data=b""):
    """4 reset, 5 retune (data: a config section), 6 icoac_step (data: MAX_INPUTS reals)."""
    return bytes([op, lane]) + data


def batch_seeds():
    centre = [0.1, -0.2, 0.02, 0.3, 0.0, 0.0]
    beyond = [1.0, 0.5, 0.3, -0.5, 0.1, -0.1]
    modes = [0, 4, 2, 1, 8, 0, 4, 2]
    s = {}
    walk = b"".join(b_tick([(t * 3) % 3]) for t in range(60))
    s["one-ico-lane-walk"] = bytes([0]) + b_lane(0) + walk + b_tick([3]) + b_op(4, 0) + walk
    lanes8 = bytes([7]) + b"".join(b_lane(m, seed_byte=k + 1) for k, m in enumerate(modes))
    ticks8 = b"".join(b_tick([(t + k) % 3 for k in range(8)], rotation=t % 8,
                             inputs=[centre if (t + k) % 4 else beyond for k in range(8)]) for t in range(12))
    s["eight-mixed-lanes"] = (lanes8 + ticks8 + b_tick([3] * 8) + b"".join(b_op(4, k) for k in range(8)) + ticks8
                              + b_op(5, 2, config({"policy.gain": 3})) + b_op(6, 0, b"".join(real(v) for v in centre))
                              + ticks8)
    s["eight-lanes-late-reflex"] = lanes8 + b"".join(
        b_tick([4 if k == 4 else 0 for k in range(8)], inputs=[centre] * 8, reflexes={4: "inf" if t == 3 else 1.5})
        for t in range(6))
    s["nan-in-one-lane"] = lanes8 + b_tick([0] * 8, inputs=[centre if k != 3 else ["nan"] + centre[1:]
                                                              for k in range(8)]) + ticks8
    lanes17 = bytes([16]) + b"".join(b_lane(modes[k % 8], seed_byte=k + 3) for k in range(17))
    s["seventeen-lanes"] = lanes17 + b"".join(b_tick([(t * k) % 3 for k in range(17)], rotation=t) for t in range(30))
    s["literal-timing-learning"] = bytes([3]) + b"".join(b_lane(4, {"ico.rate": 0.5}, seed_byte=k) for k in range(4)) + \
        b"".join(b_tick([0] * 4, inputs=[beyond if t % 2 else centre] * 4) for t in range(20))
    corrupt_batch = bytes([7 | 8, 0x40, 0x00, 64]) + bytes(range(64))
    s["batch-bytes-overwritten"] = lanes8 + ticks8 + corrupt_batch + ticks8
    # the batch's header (its magic, past the lanes' arrays, near 16.5 KB) overwritten: refused
    tail = b"".join(bytes([7 | 8]) + struct.pack("<H", offset) + bytes([255]) + bytes([0xBE] * 255)
                    for offset in range(16000, 16800, 255))
    s["batch-header-overwritten"] = lanes8 + ticks8 + tail + ticks8
    corrupt_state = bytes([7, 0x10, 0x00, 32, 2]) + bytes([0xFF] * 32)
    s["state-bytes-overwritten"] = lanes8 + ticks8 + corrupt_state + ticks8
    return s


# Op 7 of fuzz_model (icoac_sim_model_step_lanes), written byte by byte: model mode and plant,
# op 7, the lane count, then per lane 6 value selectors of the state, one of u and an ended byte.
LANE_SEEDS = {
    "lanes-mixed": bytes([0x00, 0x00, 0x07, 3] + [0] * 6 + [12, 0] + [8, 0, 0, 0, 0, 0] + [0, 0] + [0] * 6 + [9, 1]
                         + [0xCF, 1] + [0] * 6 + [12, 0] + [0xE7, 2] + [0] * 16),
    "lanes-furuta": bytes([0x02, 0x01, 0x07, 4] + [20] * 6 + [24, 0] + [5, 6, 7, 0, 0, 0] + [12, 2] + [0] * 6
                          + [10, 0] + [13] * 6 + [14, 0]),
    "lanes-null-model": bytes([0x03, 0x02, 0x07, 2] + [0] * 16),
}
# fuzz_state_double's finding of 2026-12-06 (a retune after icoac_step_batch had loaded the state:
# the batch stamp is cleared), kept as found.
RETUNE_AFTER_BATCH_LOAD = bytes.fromhex(
    "010100000100000a000000000029000aec1f00081f03081f06081f09081f0c081f0f081f12081f15081f181e081f2108"
    "1f24081f27081f2a081f2d3d081f30081f33081f36081f39081f3c081f3f081f420ffffaa883635838081f45081f4808"
    "1f4b081f4e081f51081f54081f57081f5a081f5d081f60081f63081f66081f6908000000000000003a081f75081f7808"
    "1f7b081f7e081f81081f84081f87081f8a081f8d081f90081f93081f96081f99081f9c081f9f081fa2081fa5081fa808"
    "1fab081fae08021800000000181fcd0c1c00001ecd0c1c00000101044801450000010000000000000a000c2000082101"
    "0522020a10000000000120ab6a20ab2a1220ab2affffffffffffffffffffffffffffffffffffffff05301fcd0c081f45"
    "081f48081f4b081f4e081f51081f54081f5708000120ab6a20ab2a1220ab2a480502371f9ad91f9a191e00801f004004"
    "03022a2100400304000101000403022a2100400304000101050120ab6a20ab2a1220ab2a0210000000000501200005ab"
    "6a20ab2a1220ab2a02100000000005")


def corpus():
    """{target: {file name: bytes}}."""
    float_seeds = controller_seeds("f")
    return {
        "fuzz_controller": float_seeds,
        "fuzz_controller_fast_exp": float_seeds,
        "fuzz_controller_double": controller_seeds("d"),
        "fuzz_state": state_seeds("f"),
        "fuzz_state_mcu": state_seeds("f"),
        "fuzz_state_double": {**state_seeds("d"), "retune-after-batch-load": RETUNE_AFTER_BATCH_LOAD},
        "fuzz_model": {**model_seeds(), **LANE_SEEDS},
        "fuzz_batch": batch_seeds(),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare instead of writing")
    args = parser.parse_args()
    stale = []
    for target, files in corpus().items():
        directory = CORPUS / target
        if not args.check:
            directory.mkdir(parents=True, exist_ok=True)
            for old in directory.iterdir():
                if old.name not in files:
                    old.unlink()
        for name, data in files.items():
            path = directory / name
            if args.check:
                if not path.is_file() or path.read_bytes() != data:
                    stale.append(str(path))
            else:
                path.write_bytes(data)
        if args.check and directory.is_dir():
            stale += [str(p) for p in directory.iterdir() if p.name not in files]
    if stale:
        print("corpus out of date (run tests/fuzz/gen_corpus.py):", *stale, sep="\n  ")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
