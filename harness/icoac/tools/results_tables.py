# SPDX-License-Identifier: Apache-2.0
"""The tables of docs/results.md, written from the committed bench summaries (docs/data/*.json,
written by `bench --data`): every block

    <!-- table: NAME FILE -->
    ...
    <!-- end table -->

is replaced by the table NAME of icoac.studies.tables computed from docs/data/FILE. With --check it
writes nothing and exits 1 when a block differs from its summary (tests/python/test_results_tables.py
runs the check).

    python -m icoac.tools.results_tables --update docs/results.md
"""
from __future__ import annotations

import argparse
import json
import re
from pathlib import Path
from typing import Any, Callable, Mapping

from icoac.studies import tables
from icoac.studies.bench import summary_markdown
from icoac.tools import heldout_tuning, ico_ablation, one_w, rl_baselines, speed_ab
from icoac.tools.pages import update_or_check

BLOCK = re.compile(r"(<!-- table: (?P<name>[a-z-]+) (?P<file>[\w.-]+\.json(,[\w.-]+\.json)*) -->\n)(?P<body>.*?)"
                   r"(?P<end><!-- end table -->)", re.S)


def _summary(data: Mapping[str, Any]) -> list[str]:
    """The bench's own comparison table (its first table of summary.md)."""
    text = summary_markdown(data["aggregate"])
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("| condition"))
    end = next(i for i in range(start, len(lines)) if not lines[i].startswith("|"))
    return lines[start:end]


# Tables of several summaries (a block naming FILE1,FILE2,...): one row group per file.
MULTI_TABLES: dict[str, Callable[[list[Mapping[str, Any]]], list[str]]] = {
    "headline": tables.headline_table,
    "one-w": one_w.table,
}
TABLES: dict[str, Callable[[Mapping[str, Any]], list[str]]] = {
    "comparison": _summary,
    "paired": lambda d: tables.paired_table(d["aggregate"]),
    "cost": lambda d: tables.cost_table(d["aggregate"]),
    "priors": lambda d: tables.prior_table(d["aggregate"]),
    "within": lambda d: tables.within_table(d["aggregate"], d.get("ceiling")),
    "trials-quantiles": lambda d: tables.quantile_table(d["aggregate"]),
    "time-quantiles": lambda d: tables.quantile_table(d["aggregate"], "elapsed_time_quantiles"),
    "ico-ablation": ico_ablation.table,
    "tuning": heldout_tuning.choices_table,
    "prior-reading": heldout_tuning.prior_reading_table,
    "tuning-evaluation": heldout_tuning.evaluation_table,
    "rl-baselines": rl_baselines.table,
    "baseline-tuning": rl_baselines.tuning_table,
    "speed-ab": speed_ab.table,
    "speed-lanes": speed_ab.lanes_table,
}


def _commit(git: Mapping[str, Any]) -> str:
    return (git.get("commit") or "unknown")[:7] + ("+dirty" if git.get("dirty") else "")


def provenance(data: Mapping[str, Any]) -> str:
    """The line under a table: what the summary was made from, and the builds that wrote its cells
    when they are not the summarising commit."""
    if data.get("kind") == "speed":
        return speed_ab.provenance(data)
    commit = _commit(data.get("git") or {})
    builds = [_commit(b) for b in data.get("cell_builds") or []]
    cells = f" (cells by {', '.join(builds)})" if builds and builds != [commit] else ""
    plant = f"plant {data['plant']}, " if data.get("plant") else ""
    configuration = "each learner's held-out choice (docs/tuning.md)" if data.get("tuned") else data["configuration"]
    return (f"*From docs/data: {plant}profile {data['profile']}, seeds {data['seeds']}, configuration "
            f"{configuration}{' ' + ' '.join(data['set']) if data.get('set') else ''}, commit {commit}{cells}.*")


def render(text: str, data_dir: Path) -> str:
    """text with every table block rewritten from its summary."""
    cache: dict[str, Mapping[str, Any]] = {}

    def load(file: str) -> Mapping[str, Any]:
        if file not in cache:
            cache[file] = json.loads((data_dir / file).read_text())
        return cache[file]

    def block(m: re.Match) -> str:
        name, files = m.group("name"), m.group("file").split(",")
        if name in MULTI_TABLES:
            lines = MULTI_TABLES[name]([load(f) for f in files])
            for f in files:
                lines += ["", provenance(load(f))]
        elif name in TABLES and len(files) == 1:
            lines = TABLES[name](load(files[0])) + ["", provenance(load(files[0]))]
        else:
            raise SystemExit(f"unknown table {name!r} of {len(files)} file(s) in a block; known: "
                             f"{', '.join(TABLES)} (one file), {', '.join(MULTI_TABLES)} (several)")
        return m.group(1) + "\n".join(lines) + "\n" + m.group("end")

    return BLOCK.sub(block, text)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.results_tables", description=__doc__.split("\n")[0])
    ap.add_argument("page", type=Path, nargs="?", default=Path("docs/results.md"))
    ap.add_argument("--data", type=Path, default=None, help="summaries directory (default: docs/data beside the page)")
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--update", action="store_true", help="rewrite the page's tables")
    mode.add_argument("--check", action="store_true", help="exit 1 when a table differs from its summary")
    args = ap.parse_args(argv)
    data_dir = args.data or args.page.parent / "data"
    text = args.page.read_text()
    new = render(text, data_dir)
    return update_or_check(args.page, text, new, args.check, f"a table differs from its summary in {data_dir}",
                           "python -m icoac.tools.results_tables")


if __name__ == "__main__":
    raise SystemExit(main())
