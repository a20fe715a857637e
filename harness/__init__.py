"""Python harness of the icoac controller: ctypes binding of libicoac_sim, grid runs, results, figures.

Layers (no import cycle; `python -m harness.tools.imports` prints the graph): errors, options (no
dependencies) < _binding (the C library, its constants and checked struct mirrors) < geometry,
config < metrics, grid < results < prior < figures, conditions < bench, sweep < cli (arguments
and reports only; imported by __main__ alone).
"""
__version__ = "0.1.0"
