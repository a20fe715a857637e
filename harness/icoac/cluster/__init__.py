# SPDX-License-Identifier: Apache-2.0
"""The Dask backend: grids on a dask.distributed cluster (an extra: pip install icoac[dask])."""
