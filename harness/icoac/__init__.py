# SPDX-License-Identifier: Apache-2.0
"""Python harness of the icoac controller: ctypes binding of libicoac_sim, grid runs, results, figures.

Layers (no import cycle; `python -m icoac.tools.imports` prints the graph): errors, options, registry,
literals (no dependencies) < _binding (the C library, its constants and checked struct mirrors)
< geometry, config < metrics, grid < results < store (every write into an output directory),
prior < figures, conditions < bench, sweep < cli (arguments and reports only; imported by
__main__ alone). The Dask backend: _worker (what a worker runs;
errors and options at import, the binding only inside a task) < cluster (the client side, after
grid; imported by bench and sweep, and by conditions inside a function).
Gymnasium: gym (the simulator's plants as envs, the controller as a policy; after config) is
imported by no other module.
"""

def _version() -> str:
    """The project's one version, project(icoac VERSION x.y.z) of the top-level CMakeLists.txt: in a
    wheel, harness/icoac/_version.py written from it by the build (pyproject.toml); in a checkout, read
    from the file."""
    try:
        from icoac._version import __version__ as version
        return version
    except ImportError:
        import re
        from pathlib import Path
        try:
            text = (Path(__file__).resolve().parents[2] / "CMakeLists.txt").read_text(encoding="utf-8")
        except OSError:  # neither a wheel nor a checkout
            return "unknown"
        match = re.search(r"^project\(icoac VERSION ([0-9]+\.[0-9]+\.[0-9]+)", text, re.MULTILINE)
        return match.group(1) if match else "unknown"


__version__ = _version()
