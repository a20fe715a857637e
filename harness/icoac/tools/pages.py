# SPDX-License-Identifier: Apache-2.0
"""A documentation page whose generated parts a tool rewrites (--update) or checks (--check)."""
from __future__ import annotations

import sys
from pathlib import Path

from icoac.core import store


def update_or_check(page: Path, text: str, new: str, check: bool, stale: str, command: str) -> int:
    """With ``check``: 0 when the page's text equals ``new``, else 1 and one line saying ``stale``
    and how to update it. Otherwise the page is rewritten as ``new`` (if it differs) and named."""
    if check:
        if new != text:
            print(f"{page}: {stale}; run {command} --update {page}", file=sys.stderr)
            return 1
        return 0
    if new != text:
        store.write_text(page, new)
    print(page)
    return 0
