# SPDX-License-Identifier: Apache-2.0
"""Baselines that run outside the controller's own learning: optimisers over its fixed policy."""
