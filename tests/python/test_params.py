# SPDX-License-Identifier: Apache-2.0
"""The C parameter table (icoac_params.h, the run's rows) as the harness reads it: it covers the
structs, its statuses and ranges are the C checks', and docs/design.md's table and the command
line's listing are made from it."""
import ctypes
import math
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from icoac.core import binding as B
from icoac.core import params as P
from icoac.core.config import CONTROLLER_FIELDS, RUN_FIELDS
from icoac.tools import params_table as PT

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "design.md"
MODE_OF_BIT = {B.PARAM_MODES[name]: B.MODES[name] for name in B.MODES}


def test_rows_cover_the_structs():
    """Every member of icoac_config_t and icoac_sim_run_t is a row, in struct order, at the C offset."""
    assert tuple(B.params_of("icoac_config_t")) == CONTROLLER_FIELDS == tuple(B.FIELDS["icoac_config_t"])
    assert tuple(B.params_of("icoac_sim_run_t")) == RUN_FIELDS == tuple(B.FIELDS["icoac_sim_run_t"])
    for name, row in B.PARAMS.items():
        assert (row["offset"], row["size"]) == B.FIELDS[row["type"]][name]
        assert row["tier"] in ("essential", "advanced") and row["doc"] and row["modes"]


def _struct(row, mode_bit):
    if row["type"] == "icoac_sim_run_t":
        run = B.Run()
        B.lib.icoac_sim_run_default(ctypes.byref(run))
        return run, B.lib.icoac_sim_run_check
    cfg = B.Config()
    B.lib.icoac_config_default(ctypes.byref(cfg))
    if row["name"] != "mode":
        cfg.mode = MODE_OF_BIT[mode_bit]
    return cfg, B.lib.icoac_config_check


def _set(struct, name, value):
    *path, leaf = name.split(".")
    for part in path:
        struct = getattr(struct, part)
    if isinstance(getattr(struct, leaf), ctypes.Array):
        getattr(struct, leaf)[0] = value
    else:
        setattr(struct, leaf, value)


def _inside(row):
    """The row's closed bounds that hold alone (task.n_inputs sizes the other groups' arrays; an
    index's, the units' and an at_least's maximum depend on other fields or the type)."""
    if row["name"] == "task.n_inputs":
        return []
    lo = [] if row["check"] == "real_open_lo" else [row["min"]]
    hi = [] if row["check"] in ("real_open_hi", "index", "at_least", "units") else [row["max"]]
    return lo + hi


def _outside(row):
    """Values just outside the row's range (none above an at_least's, the type's maximum; a sign's
    0 between its two values)."""
    lo, hi, check = row["min"], row["max"], row["check"]
    if row["ctype"] in ("int32_t", "int64_t"):
        return [lo - 1] + ([] if check == "at_least" else [hi + 1]) + ([0] if check == "sign" else [])
    out = [lo * 0.5 if lo > 0 else lo - 1, hi * 2 if hi > 0 else hi + 1]
    return out + ([lo] if check == "real_open_lo" else []) + ([hi] if check == "real_open_hi" else [])


@pytest.mark.parametrize("name", list(B.PARAMS))
def test_each_row_is_its_check(name):
    """In every mode that reads it, the C check accepts the row's bounds and refuses values just
    outside them and NaN, with the row's status: the table the harness reads is the check's."""
    row = B.PARAMS[name]
    integral = row["ctype"] in ("int32_t", "int64_t")
    for bit in (b for b in B.PARAM_MODES.values() if row["modes"] & b):
        for value in _inside(row):
            struct, check = _struct(row, bit)
            _set(struct, name, value)
            assert check(ctypes.byref(struct)) == B.OK, (name, value)
        for value in _outside(row) + ([] if integral else [math.nan]):
            struct, check = _struct(row, bit)
            _set(struct, name, value)
            assert check(ctypes.byref(struct)) == row["status"], (name, value)


def test_scalar_defaults_are_the_c_defaults():
    cfg = B.Config()
    B.lib.icoac_config_default(ctypes.byref(cfg))
    run = B.Run()
    B.lib.icoac_sim_run_default(ctypes.byref(run))
    for name, row in B.PARAMS.items():
        if row["dim"] != "scalar":
            continue
        struct = run if row["type"] == "icoac_sim_run_t" else cfg
        *path, leaf = name.split(".")
        for part in path:
            struct = getattr(struct, part)
        assert getattr(struct, leaf) == pytest.approx(row["default"], rel=1e-7), name


def test_design_page_agrees_with_the_c_table():
    assert PT.main([str(PAGE), "--check"]) == 0


def test_plants_page_has_every_plant_table_from_c(tmp_path):
    """docs/plants.md holds one generated table per registry plant, each row a descriptor
    parameter (then dt and the integrator, then its task's knobs) with its tier and description."""
    page = ROOT / "docs" / "plants.md"
    assert PT.main([str(page), "--check"]) == 0
    text = page.read_text()
    for index in range(int(B.lib.icoac_sim_plant_count())):
        info = B.plant_info(index)
        assert f"<!-- plant-params {info['name']}:begin -->" in text
        rows = P.plant_rows(info["name"])
        knobs = [k["name"] for k in (info["task"] or {}).get("knobs", [])]
        assert [r["name"] for r in rows] == [p["name"] for p in info["params"]] + ["dt", "integrator"] + knobs
        assert all(r["tier"] in ("essential", "advanced") and r["description"] for r in rows)
    stale = text.replace("| essential | gravitational acceleration |", "| advanced | gravitational acceleration |", 1)
    copy = tmp_path / "plants.md"
    copy.write_text(stale)
    assert PT.main([str(copy), "--check"]) == 1


def test_a_changed_row_is_caught(tmp_path):
    page = tmp_path / "design.md"
    shutil.copy(PAGE, page)
    page.write_text(page.read_text().replace("| 10 | [0, 10000] |", "| 12 | [0, 10000] |", 1))
    assert PT.main([str(page), "--check"]) == 1
    assert PT.main([str(page), "--update"]) == 0
    assert page.read_text() == PAGE.read_text()


def test_cli_lists_every_parameter():
    out = subprocess.run([sys.executable, "-m", "icoac", "params"], cwd=ROOT, check=True, capture_output=True,
                         text=True).stdout
    names = [line.split()[0] for line in out.splitlines()[1:]]
    assert names == list(B.PARAMS)
    essential = subprocess.run([sys.executable, "-m", "icoac", "params", "--tier", "essential"], cwd=ROOT,
                               check=True, capture_output=True, text=True).stdout
    assert [line.split()[0] for line in essential.splitlines()[1:]] == [
        n for n, r in B.PARAMS.items() if r["tier"] == "essential"]
