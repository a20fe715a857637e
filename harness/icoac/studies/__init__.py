# SPDX-License-Identifier: Apache-2.0
"""The studies: conditions and priors, the bench, sweeps, the ceiling, figures and tables."""
