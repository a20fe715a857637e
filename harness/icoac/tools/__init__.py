# SPDX-License-Identifier: Apache-2.0
"""The maintainers' tools: the import checker, the generated tables of the docs, the sweeps behind
the defaults, the Dask overhead measurement."""
