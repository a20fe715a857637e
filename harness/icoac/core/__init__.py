# SPDX-License-Identifier: Apache-2.0
"""The core: the C library's binding, parameters and plants, the grid driver, results and their store."""
