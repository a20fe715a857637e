# SPDX-License-Identifier: Apache-2.0
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import results, store
from icoac.core.config import build_config, make_prior

from conftest import SMALL, SMALL_CELLS


def test_save_load_round_trip(tmp_path, small_cfg, small_run):
    rec = store.save(tmp_path / "r", small_run, small_cfg, condition="ico", seed=7, wall_time=1.5,
                       threads=2, cell_indices=SMALL_CELLS)
    cells, record = results.load(tmp_path / "r")
    assert cells.dtype == B.CELL_DTYPE
    assert all(np.array_equal(cells[f], small_run[f]) for f in B.CELL_DTYPE.names)
    assert record == json.loads(json.dumps(rec))
    for key in ("condition", "seed", "config", "git", "abi", "timestamp", "wall_time", "threads", "summary"):
        assert key in record
    assert record["config"]["run"]["max_trials"] == SMALL["max_trials"]
    assert record["config"]["controller"]["policy"]["gain"] == 10.0
    assert set(record["git"]) == {"commit", "dirty"}
    assert record["abi"]["abi_version"] == B.ABI_VERSION and record["complete"] is True
    assert record["summary"]["n_success"] == int((small_run["outcome"] == B.SUCCESS).sum())
    cfg = results.load_config(record)
    assert cfg.to_dict() == small_cfg.to_dict()
    store.check_resumable(record, condition="ico", seed=7, cfg=cfg, cell_indices=SMALL_CELLS)
    with pytest.raises(results.ResultsError, match="policy.gain 10.0 != 5.0"):
        store.check_resumable(record, condition="ico", seed=7, cfg=build_config({**SMALL, "policy.gain": 5}),
                                cell_indices=SMALL_CELLS)
    with pytest.raises(results.ResultsError, match="seed"):
        store.check_resumable(record, condition="ico", seed=8, cfg=cfg, cell_indices=SMALL_CELLS)


def test_prior_recorded(tmp_path, small_run):
    cfg = build_config(SMALL, prior=make_prior([0.1, 0.05, 0.3, 0.08], np.eye(4) * 0.5))
    store.save(tmp_path, small_run, cfg, condition="rl", seed=7, wall_time=0, threads=1, cell_indices=SMALL_CELLS)
    _, record = results.load(tmp_path)
    assert record["config"]["prior"]["mean"] == pytest.approx([0.1, 0.05, 0.3, 0.08])
    assert results.load_config(record).to_dict() == cfg.to_dict()


def test_load_missing(tmp_path):
    with pytest.raises(results.ResultsError, match="does not exist"):
        results.load(tmp_path / "nope")
    with pytest.raises(results.ResultsError, match="not a results directory"):
        results.load(tmp_path)


def test_git_info_is_the_checkout_or_nothing(tmp_path, monkeypatch):
    """The commit of the checkout the harness runs from; None for a folder that is not the top of
    a git work tree (site-packages in a venv inside some repository); for an installed package,
    what its wheel build recorded."""
    here = results.git_info()
    if here["commit"] is not None:   # a git checkout (not an unpacked archive)
        assert len(here["commit"]) == 40 and isinstance(here["dirty"], bool)
        assert results.git_info(B.REPO_ROOT / "tests") == {"commit": None, "dirty": None}
    assert results.git_info(tmp_path) == {"commit": None, "dirty": None}
    info = tmp_path / "build_info.json"
    info.write_text('{"commit": "' + "a" * 40 + '", "dirty": false}')
    monkeypatch.setattr(B, "BUILD_INFO", info)
    assert results.git_info() == {"commit": "a" * 40, "dirty": False}
    info.write_text("not json")
    assert results.git_info() == {"commit": None, "dirty": None}


def test_what_runs_write_does_not_make_the_tree_dirty(tmp_path):
    """A change under RUN_OUTPUTS (the bench's data and figures, the fuzzing ledger) leaves the tree
    clean; a change anywhere else makes it dirty."""
    def git(*args):
        subprocess.run(["git", "-C", str(tmp_path), *args], check=True, capture_output=True)
    git("init", "-q")
    files = [Path(p) / "f.txt" for p in results.RUN_OUTPUTS] + [Path("harness") / "f.txt"]
    for f in files:
        (tmp_path / f).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / f).write_text("a\n")
    git("add", "-A")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "c")
    assert results.git_info(tmp_path)["dirty"] is False
    for f in files[:-1]:
        (tmp_path / f).write_text("b\n")
    assert results.git_info(tmp_path)["dirty"] is False
    (tmp_path / files[-1]).write_text("b\n")
    assert results.git_info(tmp_path)["dirty"] is True
