# SPDX-License-Identifier: Apache-2.0
"""The run of a long, resumable tool: a harness error as one line and exit status 2, Ctrl-C as 130
with how to resume (its finished grids are kept)."""
from __future__ import annotations

import sys
from typing import Callable, TypeVar

from icoac.core.errors import HarnessError

T = TypeVar("T")


def guarded(body: Callable[[], T]) -> tuple[int, T | None]:
    """(0, body()) or (the exit status, None)."""
    try:
        return 0, body()
    except HarnessError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2, None
    except KeyboardInterrupt:
        print("interrupted; rerun the same command to resume", file=sys.stderr)
        return 130, None
