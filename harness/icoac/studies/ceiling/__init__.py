# SPDX-License-Identifier: Apache-2.0
"""`ceiling`: what the policy class F = G * w^T x~ + U can reach on the plant's grid, with no
learning (method.md, L5, "the best single w found"). Every simulation runs in C through the engine.

Modules, each one concern (imports go down the list, never up):

- ``weights``: a w as the controller acts with it (rounded to its real type), parsed, named, printed;
- ``fixed``: fixed-w evaluation, the configuration and the two protocols (first trial, retries);
- ``search``: the seeded search for the best single w, screening each candidate once;
- ``cma_search``: CMA-ES as the search's optimiser (``--optimiser cma-es``), on the same screening;
- ``lqr``: the LQR starting points of the search, from the plant linearised at the upright state;
- ``bound``: the first-step bound, which holds for any controller;
- ``records``: the files of OUT (search.json, ceiling.json, ceiling.md) and what the bench reads back;
- ``command``: `python -m icoac ceiling`, which runs them in turn.
"""
