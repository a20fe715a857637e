# SPDX-License-Identifier: Apache-2.0
"""A weight vector w (one weight per task input; the cart-pole's w_x, w_xdot, w_theta, w_thetadot) as
the controller acts with it: rounded to its real type, checked as the C prior check would, parsed
from text, named and printed."""
from __future__ import annotations

import hashlib
from typing import Any, Sequence

import numpy as np

from icoac.core import binding as B
from icoac.core import literals
from icoac.core.errors import UsageError
from icoac.core.options import TYPICAL_ICO_WEIGHTS

W_NAMES = ("w_x", "w_xdot", "w_theta", "w_thetadot")


def as_weights(values: Any, what: str = "w", n: int | None = None) -> tuple[float, ...]:
    """n finite numbers (a task of n inputs; None: 1 to MAX_INPUTS) rounded to the controller's
    real type (what the controller acts with), as a tuple of Python floats; UsageError for anything
    the C prior check would refuse."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise UsageError(f"{what}: expected {n or 'up to ' + str(B.MAX_INPUTS)} numbers, got {values!r:.60}") from None
    if n is None and arr.ndim == 1 and 1 <= arr.size <= B.MAX_INPUTS:
        n = arr.size
    if arr.shape != (n,):
        names = f" ({', '.join(W_NAMES)})" if n == len(W_NAMES) else ""
        raise UsageError(f"{what}: expected {n} numbers{names}, got {values!r:.60}")
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > 1e6):
        raise UsageError(f"{what}: every weight must be finite with |w_i| <= 1e6, got {values!r:.60}")
    with np.errstate(under="ignore"):
        rounded = arr.astype(B.real_dtype)
    tiny = np.finfo(B.real_dtype).tiny
    if np.any((rounded != 0) & (np.abs(rounded) < tiny)) or np.any((arr != 0) & (rounded == 0)):
        raise UsageError(f"{what}: a weight is subnormal in the controller's reals (|w_i| must be 0 "
                         f"or >= {tiny:.3g})")
    return tuple(float(v) for v in rounded)


def parse_weights(text: str, what: str = "--w", n: int | None = None) -> tuple[float, ...]:
    """'w1,...,wn' -> as_weights."""
    parts = [p.strip() for p in str(text).strip().strip("()[]").split(",")]
    try:
        values = [literals.real(p) for p in parts]
    except literals.NumberError as exc:
        raise UsageError(f"{what} expects {n} comma-separated numbers, got {text!r:.60} (a value {exc})") from None
    return as_weights(values, what, n)


def typical_weights(n: int) -> tuple[float, ...]:
    """A typical ICO w of a task of n inputs: the cart-pole's for 4 inputs, else all ones."""
    return tuple(TYPICAL_ICO_WEIGHTS) if n == len(TYPICAL_ICO_WEIGHTS) else (1.0,) * n


def weight_name(i: int, n: int) -> str:
    """The name of weight i of n: the cart-pole's names for 4 inputs, else w<i>."""
    return W_NAMES[i] if n == len(W_NAMES) else f"w{i}"


def weights_key(w: Sequence[float]) -> str:
    """Short stable name of a w (hash of its real-typed bytes)."""
    return hashlib.sha1(np.asarray(w, dtype=B.real_dtype).tobytes()).hexdigest()[:12]


def format_w(w: Sequence[float], digits: int = 4) -> str:
    return "(" + ", ".join(f"{v:.{digits}g}" for v in w) + ")"
