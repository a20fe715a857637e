# SPDX-License-Identifier: Apache-2.0
"""Exception types of the harness (no dependencies, so the command line can catch them before the
shared library is loaded).

Every error the harness reports is a HarnessError; the command line prints it as one line and
exits with status 2. Errors carrying a C status (IcoacError, ConfigError, Cancelled) are defined
by the binding, on top of HarnessError; the ones below are the harness's own.
"""
from __future__ import annotations


class HarnessError(Exception):
    """Base of every error the harness reports as one line (exit status 2)."""


class UsageError(HarnessError):
    """A mistake on the command line or in the options given to a command."""


class LibraryError(HarnessError):
    """The shared library is missing or does not match this binding."""


class WorkerError(HarnessError):
    """A Dask worker that cannot run the harness: the library missing or unloadable there, another
    ABI than the client's, the harness not importable, no worker at all, or a chunk that killed
    its workers. The message names the worker and, where it applies, the library path."""


class ResultsError(HarnessError):
    """A missing, unreadable or mismatching results directory."""


class PriorError(HarnessError):
    """No (or too few) ICO-successful cells to build a prior from, or a bad prior option."""


class SweepError(UsageError):
    """A malformed sweep parameter list or sweep directory."""


class MissingExtra(UsageError):
    """A feature whose optional dependencies (an extra of the package) are not installed."""

    def __init__(self, what: str, extra: str, exc: ImportError):
        super().__init__(f"{what} needs the {extra!r} extra ({exc.name or exc}): pip install 'icoac[{extra}]'")
