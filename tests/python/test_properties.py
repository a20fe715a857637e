# SPDX-License-Identifier: Apache-2.0
"""Property tests (hypothesis): configuration building, `--set` parsing, cell lists and results
loading accept an input and round-trip it, or reject it with the harness's own error type - never
another exception. Profile (examples, derandomized) in conftest.py."""
import ctypes
import io
import json
import math
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from icoac.core import binding as B
from icoac.core import config, geometry, grid, metrics, results, store
from icoac.core.config import (ALL_FIELDS, BOOLS, ENUMS, RunConfig, build_config, canonical, config_from_dict,
                               parse_sets, parse_value)
from icoac.core.errors import HarnessError
from icoac.core.registry import CONDITIONS

HARNESS_ERRORS = (HarnessError,)  # ConfigError, ResultsError, UsageError, ... all derive from it

# -- strategies ----------------------------------------------------------------------------------------
floats = st.floats(allow_nan=True, allow_infinity=True) | st.floats(min_value=-1e-300, max_value=1e-300) \
    | st.sampled_from([0.0, -0.0, 1e-310, 5e-324, 1e-40, 1e-46, 3.5e38, 1e39, 1e308, 0.5, 2.0, 1e-6, 1e6])
ints = st.integers() | st.integers(min_value=-2 ** 70, max_value=2 ** 70) \
    | st.sampled_from([0, 1, 2, -1, 2 ** 31 - 1, 2 ** 31, 2 ** 32 + 1, 2 ** 63 - 1, 2 ** 63, 2 ** 64, 10 ** 400])
scalars = st.none() | st.booleans() | ints | floats | st.text(max_size=12) \
    | st.sampled_from(["nan", "inf", "-inf", "1e999", "1e-310", "true", "off", "rk4", "gain", "1e5", " 7 ",
                       "0x10", "1_0", "NaN", "Infinity"] + [n for names in ENUMS.values() for n in names])
json_values = st.recursive(scalars, lambda kids: st.lists(kids, max_size=5)
                           | st.dictionaries(st.text(max_size=8), kids, max_size=4), max_leaves=12)
field_values = scalars | st.lists(floats | ints, min_size=3, max_size=5) | json_values
names = st.sampled_from(ALL_FIELDS + ("gain", "reserved", "gian", "", "Gain", "policy", "policy.")) \
    | st.text(max_size=10)


def total(fn, *args, **kw):
    """fn(...) or None if it raised one of the harness's own errors; anything else propagates."""
    try:
        return fn(*args, **kw)
    except HARNESS_ERRORS:
        return None


def assert_round_trip(cfg: RunConfig):
    d = cfg.to_dict()
    assert json.loads(json.dumps(d)) == d           # JSON-clean: finite, plain types
    again = config_from_dict(d)
    assert again.to_dict() == d
    # the same configuration from `--set` strings of the values
    flat = cfg.flat()
    sets = [f"{name}={json.dumps(value)}" for name, value in flat.items()]
    assert build_config(parse_sets(sets), prior=cfg.prior).to_dict() == d


# -- configuration ---------------------------------------------------------------------------------------
@given(st.dictionaries(names, field_values, max_size=4))
def test_build_config_accepts_and_round_trips_or_rejects(overrides):
    cfg = total(build_config, overrides)
    if cfg is not None:
        assert_round_trip(cfg)


@given(st.sampled_from(ALL_FIELDS), field_values, st.sampled_from(CONDITIONS))
def test_single_field_override(given_name, value, condition):
    cfg = total(build_config, {given_name: value}, condition=condition)
    if cfg is None:
        return
    assert_round_trip(cfg)
    name = canonical(given_name)
    group = config.group_of(name)
    got = cfg.flat()[name]
    # what was accepted is what is stored: no truncation, wrap-around or rounding beyond the C type
    is_int = isinstance(value, int) and not isinstance(value, bool)
    if name in ENUMS and is_int:
        assert ENUMS[name].get(got, got) == value
    elif name in BOOLS and is_int:
        assert value in (0, 1) and got is bool(value)
    elif isinstance(got, int) and not isinstance(got, bool) and isinstance(value, (int, float)) \
            and not isinstance(value, bool):
        assert got == value
    elif isinstance(got, float) and isinstance(value, (int, float)) and not isinstance(value, bool):
        kind = B.real_dtype.type if group == "controller" else np.float64
        assert kind(got) == kind(value) and math.isfinite(got)


# switches, flags and counts: every integer field (explore_ticks, search.batch and the task's sizes are
# plain int32 counts; task.rule_side is an array of switches)
INT_FIELDS = [n for n in ALL_FIELDS if n in ENUMS or n in BOOLS
              or n in ("max_trials", "success_steps", "actor.explore_ticks", "search.batch", "task.n_inputs",
                       "task.n_rules")]
assert len(INT_FIELDS) == 19
assert {n for n in config.CONTROLLER_FIELDS if config._ctype(B.Config(), n) is ctypes.c_int32} <= set(INT_FIELDS)


# k + m * 2^32 (and 2^64) wraps to a valid small value if anything truncates to int32 (int64)
aliases = st.builds(lambda k, m, w: k + m * w, st.integers(0, 2), st.integers(-3, 3), st.sampled_from([2 ** 32, 2 ** 64]))


@given(st.sampled_from(INT_FIELDS), aliases | ints | aliases.map(str) | ints.map(str) | ints.filter(lambda v: abs(v) < 2 ** 1000).map(float))
def test_integer_fields_are_range_checked_not_truncated(name, value):
    cfg = total(build_config, {name: value})
    if cfg is None:
        return
    number = int(float(value)) if isinstance(value, str) and not value.strip().lstrip("-").isdigit() else int(value)
    got = cfg.flat()[name]
    if name in ENUMS:
        got = ENUMS[name].get(got, got)
    assert int(got) == number


@given(st.sampled_from(ALL_FIELDS),
       st.text(max_size=20) | floats.map(repr) | ints.map(str) | json_values.map(json.dumps))
def test_set_option_parsing(name, text):
    over = total(parse_sets, [f"{name}={text}"])
    assert over is not None and set(over) == {canonical(name)}
    cfg = total(build_config, over)
    if cfg is not None:
        assert_round_trip(cfg)


@given(st.lists(st.text(max_size=25), max_size=3))
def test_set_option_arbitrary_text(items):
    over = total(parse_sets, items)
    if over is not None:
        cfg = total(build_config, over)
        if cfg is not None:
            assert_round_trip(cfg)


@given(st.text(max_size=40))
def test_parse_value_never_raises(text):
    parse_value(text)


def _has_subnormal(value) -> bool:
    if isinstance(value, float):
        return value != 0.0 and abs(value) < sys.float_info.min
    if isinstance(value, list):
        return any(_has_subnormal(v) for v in value)
    if isinstance(value, dict):
        return any(_has_subnormal(v) for v in value.values())
    return False


@given(json_values)
def test_parse_value_reads_json(value):
    """JSON reads as itself, except that a subnormal number makes the whole text stay a string (no
    field takes one: icoac.core.literals.real)."""
    text = json.dumps(value)
    assume("NaN" not in text)
    assert parse_value(text) == (text if _has_subnormal(value) else value)


def _paths(d, prefix=()):
    for k, v in d.items():
        yield prefix + (k,)
        if isinstance(v, dict):
            yield from _paths(v, prefix + (k,))


DEFAULT_DICT = build_config().to_dict()
DEFAULT_DICT["prior"] = {"mean": [0.1, 0.0, 0.3, 0.0], "cov": np.eye(4).tolist()}
DICT_PATHS = sorted(_paths(DEFAULT_DICT))


@given(st.sampled_from(DICT_PATHS), json_values, st.booleans())
def test_config_from_dict_of_edited_dict(path, value, delete):
    data = json.loads(json.dumps(DEFAULT_DICT))
    node = data
    for k in path[:-1]:
        node = node[k]
    if delete:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    cfg = total(config_from_dict, data)
    if cfg is not None:
        assert_round_trip(cfg)


@given(json_values)
def test_config_from_dict_of_anything(data):
    cfg = total(config_from_dict, data)
    if cfg is not None:
        assert_round_trip(cfg)


# -- cell lists ------------------------------------------------------------------------------------------
@given(st.lists(st.integers(0, geometry.CELLS - 1), min_size=1, max_size=60), st.randoms(use_true_random=False))
def test_cell_list_round_trip(indices, rnd):
    want = sorted(set(indices))
    assert grid.parse_cell_indices(grid.format_cell_indices(indices), geometry.CELLS) == want
    assert grid.parse_cell_indices(indices, geometry.CELLS) == want
    # the same cells written another way: shuffled parts, some ranges split, spaces, empty parts
    parts = grid.format_cell_indices(indices).split(",")
    rnd.shuffle(parts)
    text = " , ".join(p.replace("-", " - ") if rnd.random() < 0.5 else p for p in parts) + ("," if rnd.random() < .3 else "")
    assert grid.parse_cell_indices(text, geometry.CELLS) == want


@given(st.text(alphabet="0123456789-, x+_.e", max_size=30) | st.text(max_size=30))
def test_cell_text_accepted_or_config_error(text):
    got = total(lambda t: grid.parse_cell_indices(t, geometry.CELLS), text)
    if got is not None:
        assert got == sorted(set(got)) and all(0 <= i < geometry.CELLS for i in got)
        assert grid.parse_cell_indices(grid.format_cell_indices(got), geometry.CELLS) == got


@given(st.lists(scalars | st.integers(-5, 1300), max_size=8))
def test_cell_sequence_accepted_or_config_error(items):
    got = total(lambda t: grid.parse_cell_indices(t, geometry.CELLS), items)
    if got is not None:
        assert got == sorted({int(i) for i in items})


# -- results loading -------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def valid_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("valid") / "res"
    cfg = build_config({"max_trials": 20, "success_steps": 100})
    cells = grid.make_cells(1, [0, 611, 612])
    grid.run_grid(cfg, cells, threads=1, progress=False)
    store.save(out, cells, cfg, condition="ico", seed=1, wall_time=0.1, threads=1, cell_indices=[0, 611, 612])
    return out


def _load_with(valid_dir, name, data: bytes):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp) / "r"
        shutil.copytree(valid_dir, d)
        (d / name).write_bytes(data)
        got = total(results.load, d)
    if got is not None:
        cells, record = got
        assert cells.dtype == B.CELL_DTYPE and cells.ndim == 1 and 1 <= cells.size <= geometry.CELLS
        assert np.isin(cells["outcome"], list(B.OUTCOME_NAMES)).all()
        assert np.isfinite(cells["x0"]).all() and np.isfinite(cells["theta0"]).all()
        rows, cols = metrics.grid_index(cells)
        assert ((rows >= 0) & (rows < geometry.THETAS) & (cols >= 0) & (cols < geometry.XS)).all()
        assert isinstance(record, dict) and isinstance(record["config"], dict)
        config_from_dict(record["config"])
    return got


def _mutations(blob: bytes):
    return st.one_of(
        st.integers(0, len(blob)).map(lambda k: blob[:k]),                                 # truncated
        st.tuples(st.integers(0, len(blob) - 1), st.integers(1, 255)).map(
            lambda t: blob[:t[0]] + bytes([blob[t[0]] ^ t[1]]) + blob[t[0] + 1:]),          # one byte flipped
        st.tuples(st.integers(0, len(blob)), st.binary(min_size=1, max_size=16)).map(
            lambda t: blob[:t[0]] + t[1] + blob[t[0]:]),                                    # bytes inserted
        st.binary(max_size=300))                                                           # anything


@given(data=st.data())
def test_load_arbitrary_cells_bytes(valid_dir, data):
    blob = (valid_dir / "cells.npz").read_bytes()
    _load_with(valid_dir, "cells.npz", data.draw(_mutations(blob)))


@given(data=st.data())
def test_load_arbitrary_run_json_bytes(valid_dir, data):
    blob = (valid_dir / "run.json").read_bytes()
    _load_with(valid_dir, "run.json", data.draw(_mutations(blob)))


@given(st.sampled_from(["condition", "seed", "cells", "config", "wall_time", "complete", "summary", "git",
                        "prior_info", "format_version", "threads"]), json_values, st.booleans())
def test_load_edited_run_record(valid_dir, key, value, delete):
    record = json.loads((valid_dir / "run.json").read_text())
    if delete:
        record.pop(key, None)
    else:
        record[key] = value
    _load_with(valid_dir, "run.json", json.dumps(record).encode())


@given(st.sampled_from(["x0", "theta0", "seed", "outcome", "status", "trials"]),
       st.integers(0, 2), floats | ints)
def test_load_edited_cells(valid_dir, field, index, value):
    with np.load(valid_dir / "cells.npz") as z:
        cells = z["cells"]
    try:
        with np.errstate(all="ignore"):
            cells[field][index] = value
    except (OverflowError, ValueError, TypeError):
        assume(False)
    buf = io.BytesIO()
    np.savez(buf, cells=cells)
    got = _load_with(valid_dir, "cells.npz", buf.getvalue())
    if got is not None:
        assert got[0].tobytes() == cells.tobytes()
