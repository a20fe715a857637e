# SPDX-License-Identifier: Apache-2.0
"""Numbers written as text - options of the command line, ``--set`` and ``--param`` values, ``--cells``
indices, ``--w`` weights - read by one grammar (pure Python, no dependencies).

Digits are ASCII everywhere: ``[+-]digits`` for integers, ``[+-]digits[.digits][e[+-]digits]``
for reals, plus ``inf`` / ``nan`` (which the callers refuse as not finite). Python's int() and
float() would also take other Unicode digits (fullwidth, Arabic-Indic, ...) and underscores
("1_000"); these are refused here, in every option alike.

A real literal that is not zero but rounds to 0 or to a subnormal double (``1e-400``,
``1e-310``) is refused: the value it stands for cannot be represented, and zero is written 0.
Fields of the controller's real type (float by default) are checked against that type by
icoac.core.config.
"""
from __future__ import annotations

import re
import sys

INTEGER = re.compile(r"[+-]?[0-9]{1,30}", re.ASCII)   # longer: through real(), so never a huge int()
_REAL = re.compile(r"[+-]?(?P<mantissa>[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?", re.ASCII)
_NON_FINITE = re.compile(r"[+-]?(?:inf|infinity|nan)", re.ASCII | re.IGNORECASE)
_SPACE = " \t\n\r\f\v"


class NumberError(ValueError):
    """Text that is not a number of this grammar, or a literal its type cannot represent. The
    message says why and is written to follow the value: ``f"value {text!r} {exc}"``."""


def real(text: str) -> float:
    """The float of a decimal literal in ASCII (surrounding ASCII blanks allowed); NumberError for
    anything else and for a nonzero literal that rounds to 0 or to a subnormal double."""
    t = text.strip(_SPACE) if isinstance(text, str) else None
    if t is not None and _NON_FINITE.fullmatch(t):
        return float(t)
    m = _REAL.fullmatch(t) if t is not None else None
    if m is None:
        raise NumberError("is not a number (ASCII digits, e.g. 1.5e-3)")
    value = float(t)
    if value == 0.0 and m.group("mantissa").strip("0.") != "":
        raise NumberError(f"rounds to 0 (|value| must be 0 or at least {sys.float_info.min:.4g})")
    if value != 0.0 and abs(value) < sys.float_info.min:
        raise NumberError(f"rounds to a subnormal number (|value| must be 0 or at least {sys.float_info.min:.4g})")
    return value


def integer(text: str) -> int:
    """An integer written as ASCII digits, or as a real literal with an integral value ('1e5');
    NumberError for anything else (inf and nan included)."""
    t = text.strip(_SPACE) if isinstance(text, str) else None
    if t is not None and INTEGER.fullmatch(t):
        return int(t, 10)
    value = real(text)
    if value != value or value in (float("inf"), float("-inf")) or not value.is_integer():
        raise NumberError("is not an integer")
    return int(value)


def is_integer_text(text: str) -> bool:
    """ASCII digits with an optional sign (and surrounding ASCII blanks)."""
    return isinstance(text, str) and INTEGER.fullmatch(text.strip(_SPACE)) is not None
