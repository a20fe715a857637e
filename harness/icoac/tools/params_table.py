# SPDX-License-Identifier: Apache-2.0
"""docs/design.md's parameter table, written from the C parameter table (icoac_params.h and the
run's rows, through icoac.core.params): the block

    <!-- params:begin -->
    ...
    <!-- params:end -->

is replaced by icoac.core.params.markdown_table(). With --check it writes nothing and exits 1 when
the block differs (tests/python/test_params.py runs the check).

    python -m icoac.tools.params_table --update docs/design.md
"""
from __future__ import annotations

import argparse
import re
from pathlib import Path

from icoac.core import params
from icoac.tools.pages import update_or_check

BLOCK = re.compile(r"(<!-- params:begin -->\n)(?P<body>.*?)(<!-- params:end -->)", re.S)


def render(text: str) -> str:
    """text with its parameter block rewritten from the C table; SystemExit when it has none."""
    if not BLOCK.search(text):
        raise SystemExit("no <!-- params:begin --> ... <!-- params:end --> block")
    body = "\n".join(params.markdown_table()) + "\n"
    return BLOCK.sub(lambda m: m.group(1) + body + m.group(3), text)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.params_table", description=__doc__.split("\n")[0])
    ap.add_argument("page", type=Path, nargs="?", default=Path("docs/design.md"))
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--update", action="store_true", help="rewrite the page's parameter table")
    mode.add_argument("--check", action="store_true", help="exit 1 when the table differs from the C table")
    args = ap.parse_args(argv)
    text = args.page.read_text()
    new = render(text)
    return update_or_check(args.page, text, new, args.check, "the parameter table differs from the C table",
                           "python -m icoac.tools.params_table")


if __name__ == "__main__":
    raise SystemExit(main())
