"""A weight vector w = (w_x, w_xdot, w_theta, w_thetadot) as the controller acts with it: rounded to
its real type, checked as the C prior check would, parsed from text, named and printed."""
from __future__ import annotations

import hashlib
from typing import Any, Sequence

import numpy as np

from .. import _binding as B
from .. import literals
from ..errors import UsageError

W_NAMES = ("w_x", "w_xdot", "w_theta", "w_thetadot")


def as_weights(values: Any, what: str = "w") -> tuple[float, ...]:
    """4 finite numbers rounded to the controller's real type (what the controller acts with), as
    a tuple of Python floats; UsageError for anything the C prior check would refuse."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise UsageError(f"{what}: expected {B.N_INPUTS} numbers, got {values!r:.60}") from None
    if arr.shape != (B.N_INPUTS,):
        raise UsageError(f"{what}: expected {B.N_INPUTS} numbers (w_x, w_xdot, w_theta, w_thetadot), "
                         f"got {values!r:.60}")
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > 1e6):
        raise UsageError(f"{what}: every weight must be finite with |w_i| <= 1e6, got {values!r:.60}")
    with np.errstate(under="ignore"):
        rounded = arr.astype(B.real_dtype)
    tiny = np.finfo(B.real_dtype).tiny
    if np.any((rounded != 0) & (np.abs(rounded) < tiny)) or np.any((arr != 0) & (rounded == 0)):
        raise UsageError(f"{what}: a weight is subnormal in the controller's reals (|w_i| must be 0 "
                         f"or >= {tiny:.3g})")
    return tuple(float(v) for v in rounded)


def parse_weights(text: str, what: str = "--w") -> tuple[float, ...]:
    """'w1,w2,w3,w4' -> as_weights."""
    parts = [p.strip() for p in str(text).strip().strip("()[]").split(",")]
    try:
        values = [literals.real(p) for p in parts]
    except literals.NumberError as exc:
        raise UsageError(f"{what} expects {B.N_INPUTS} comma-separated numbers w_x,w_xdot,w_theta,w_thetadot, "
                         f"got {text!r:.60} (a value {exc})") from None
    return as_weights(values, what)


def weights_key(w: Sequence[float]) -> str:
    """Short stable name of a w (hash of its real-typed bytes)."""
    return hashlib.sha1(np.asarray(w, dtype=B.real_dtype).tobytes()).hexdigest()[:12]


def format_w(w: Sequence[float], digits: int = 4) -> str:
    return "(" + ", ".join(f"{v:.{digits}g}" for v in w) + ")"
