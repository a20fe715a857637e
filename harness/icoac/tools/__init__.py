# SPDX-License-Identifier: Apache-2.0
"""Developer tools of the harness that need neither the shared library nor the harness modules."""
