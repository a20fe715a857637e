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
    for _, file in found:
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
    file = blocks(page.read_text())[0][1]
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
