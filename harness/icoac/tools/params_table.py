# SPDX-License-Identifier: Apache-2.0
"""The parameter tables of the docs, written from the C tables (icoac_params.h, the run's rows and
each registry plant's, through icoac.core.params): a page's blocks

    <!-- params:begin --> ... <!-- params:end -->                         (docs/design.md)
    <!-- plant-params NAME:begin --> ... <!-- plant-params NAME:end -->  (docs/plants.md)

are replaced by icoac.core.params.markdown_table() and plant_markdown(NAME). With --check it
writes nothing and exits 1 when a block differs (tests/python/test_params.py runs the check).

    python -m icoac.tools.params_table --update docs/design.md docs/plants.md
"""
from __future__ import annotations

import argparse
import re
from pathlib import Path

from icoac.core import params
from icoac.tools.pages import update_or_check

BLOCK = re.compile(r"(<!-- (?P<what>params|plant-params (?P<plant>\w+)):begin -->\n)(?P<body>.*?)"
                   r"(<!-- (?P=what):end -->)", re.S)


def _table(m: re.Match) -> str:
    lines = params.plant_markdown(m["plant"]) if m["plant"] else params.markdown_table()
    return m.group(1) + "\n".join(lines) + "\n" + m.group(5)


def render(text: str) -> str:
    """text with its parameter blocks rewritten from the C tables; SystemExit when it has none."""
    if not BLOCK.search(text):
        raise SystemExit("no <!-- params:begin --> or <!-- plant-params NAME:begin --> block")
    return BLOCK.sub(_table, text)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.params_table", description=__doc__.split("\n")[0])
    ap.add_argument("pages", type=Path, nargs="*", default=[Path("docs/design.md"), Path("docs/plants.md")])
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--update", action="store_true", help="rewrite the pages' parameter tables")
    mode.add_argument("--check", action="store_true", help="exit 1 when a table differs from the C tables")
    args = ap.parse_args(argv)
    status = 0
    for page in args.pages:
        text = page.read_text()
        status |= update_or_check(page, text, render(text), args.check,
                                  "a parameter table differs from the C tables",
                                  "python -m icoac.tools.params_table")
    return status


if __name__ == "__main__":
    raise SystemExit(main())
