# SPDX-License-Identifier: Apache-2.0
"""Bit-for-bit comparison of grid cells against committed reference cells.

Runs a spread subset of the paper grid's cells (CELLS, failing and successful ones) for every
learning condition and its no-learning control, and a few variants (VARIANTS: the literal
reading, batch updates, the dense threshold 0, ...), with small caps, through the harness and the
library it loads, and compares every result field of every cell (outcome, status, trials, steps,
elapsed time, final weights and covariance) bit for bit with the reference.

    python -m tests.tools.compare_cells            # compare (exit 1 on any difference)
    python -m tests.tools.compare_cells --generate # rewrite the reference (from the checkout's library)

The reference (tests/python/fixtures/reference_cells.npz) records the commit it was generated
from. The ICO prior of the conditions that take one is part of the reference: the ICO->RL prior
of a default-profile ICO grid (seed 0), stored as numbers, so the comparison needs no ICO grid.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "tests" / "python" / "fixtures" / "reference_cells.npz"

# 39 cells: every 41st of the 1225 (corners and edges included) and a run through the centre.
CELLS = sorted(set(range(0, 1225, 41)) | set(range(596, 630, 4)))
SEED = 3
CAPS = {"max_trials": 100, "success_steps": 5000}
ICO_CAPS = {"max_trials": 3000, "success_steps": 5000}
# Further readings and switches, each on a condition: name -> (condition, overrides).
VARIANTS = {
    "ico-rl literal": ("ico-rl", {"actor.update": "posterior", "actor.noise_std": 1, "actor.scale": 0.5,
                                  "actor.likelihood_std": 0, "actor.batch": 0, "actor.explore_ticks": 0,
                                  "critic.quirks": 0}),
    "ico-rl batch sample": ("ico-rl", {"actor.batch": 1, "actor.act_with_sample": 1, "actor.update": "mean",
                                       "actor.likelihood_std": 0.1}),
    "ico-rl quirks dense": ("ico-rl", {"critic.quirks": 1, "critic.threshold": 0.0}),
    "ico literal timing": ("ico", {"ico.timing": "literal", "policy.reflex_mode": "gain"}),
    "search small batch": ("ico-search", {"search.batch": 3, "search.elite_fraction": 0.5}),
}
RESULT_FIELDS = ("outcome", "status", "trials", "total_steps", "last_trial_steps", "elapsed_time", "weights",
                 "cov")
CART_POLE_INPUTS = 4

# The ICO prior: the ICO->RL prior (default frame and ridge) of an ICO grid of the default profile
# (results/ico-seed0: seed 0, 1e5 trials, at ad0bc3e), stored in the reference by --generate and
# kept by a --generate without --ico-prior-from.


def _run_condition(name: str, ico_prior) -> np.ndarray:
    from icoac.core import binding as B
    from icoac.core import grid
    from icoac.studies import prior as P
    from icoac.core.config import CONDITION_OVERRIDES, build_config, make_prior
    condition, extra = VARIANTS.get(name, (name, {}))
    caps = ICO_CAPS if condition == "ico" else CAPS
    info = None
    base = {"ico-rl-control": "ico-rl", "ico-mean-rl-control": "ico-mean-rl", "rl-ico-cov-control": "rl-ico-cov",
            "rl-control": "rl", "ico-search-control": "ico-search", "search-control": "search"}.get(condition, condition)
    if base != "ico":
        info = P.condition_prior(base, ico_prior)
    prior = None
    if info is not None:
        n = B.N_INPUTS
        mean = np.zeros(n)
        cov = np.eye(n)
        mean[:CART_POLE_INPUTS] = info.mean[:CART_POLE_INPUTS]
        cov[:CART_POLE_INPUTS, :CART_POLE_INPUTS] = info.cov[:CART_POLE_INPUTS, :CART_POLE_INPUTS]
        prior = make_prior(mean, cov)
    cfg = build_config({**CONDITION_OVERRIDES[condition], **extra, **caps}, prior=prior)
    cells = grid.make_cells(SEED, CELLS)
    grid.run_grid(cfg, cells, threads=2, progress=False)
    out = np.zeros(cells.size, dtype=[(f, np.float64 if f in ("elapsed_time",) else np.int64)
                                      for f in RESULT_FIELDS if f not in ("weights", "cov")]
                   + [("weights", np.float64, (CART_POLE_INPUTS,)),
                      ("cov", np.float64, (CART_POLE_INPUTS, CART_POLE_INPUTS))])
    for f in RESULT_FIELDS:
        if f == "weights":
            out[f] = cells[f][:, :CART_POLE_INPUTS]
        elif f == "cov":
            out[f] = cells[f][:, :CART_POLE_INPUTS, :CART_POLE_INPUTS]
        else:
            out[f] = cells[f]
    return out


def _ico_prior_from_reference(data):
    from icoac.studies import prior as P
    return P.PriorInfo(mean=np.asarray(data["ico_prior_mean"]), cov=np.asarray(data["ico_prior_cov"]),
                       frame=None, n_cells=0, ridge=0.0)


def _commit() -> str:
    try:
        return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def generate(ico_prior_from: Path | None, reference: Path = REFERENCE) -> None:
    """Rewrite the reference; its ICO prior from an ICO results directory, or (None) the one it
    holds, so that a deliberate change of the results' bits needs no new ICO grid."""
    from icoac.core.registry import CONDITIONS
    from icoac.studies import prior as P
    if ico_prior_from is None:
        ico = _ico_prior_from_reference(np.load(reference))
        source = "the previous reference's prior"
    else:
        ico = P.from_results(ico_prior_from)
        source = str(ico_prior_from)
    arrays = {"ico_prior_mean": ico.mean[:CART_POLE_INPUTS],
              "ico_prior_cov": ico.cov[:CART_POLE_INPUTS, :CART_POLE_INPUTS]}
    for name in (*CONDITIONS, *VARIANTS):
        arrays[name] = _run_condition(name, ico)
    meta = {"commit": _commit(), "cells": CELLS, "seed": SEED, "caps": CAPS, "ico_caps": ICO_CAPS,
            "command": "python -m tests.tools.compare_cells --generate"
                       + (f" --ico-prior-from {ico_prior_from}" if ico_prior_from is not None else ""),
            "ico_prior": source}
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez_compressed(reference, **arrays)
    print(f"wrote {reference} ({meta['commit']})")


def load_conditions(reference: Path = REFERENCE) -> list[str]:
    """The conditions of the reference."""
    return [name for name in np.load(reference).files if name not in ("meta", "ico_prior_mean", "ico_prior_cov")]


def compare(conditions=None, reference: Path = REFERENCE) -> dict[str, dict[str, int]]:
    """{condition: {"cells": compared, "identical": bit-identical cells, "outcome_or_trials": cells
    whose outcome or trial count differs, "successes" and "new_successes": the reference's and
    this library's successful cells}}."""
    data = np.load(reference)
    ico = _ico_prior_from_reference(data)
    report = {}
    for condition in conditions or load_conditions(reference):
        ref = data[condition]
        new = _run_condition(condition, ico)
        same = np.ones(ref.size, dtype=bool)
        for f in RESULT_FIELDS:
            a = np.ascontiguousarray(ref[f]).view(np.uint8).reshape(ref.size, -1)
            b = np.ascontiguousarray(new[f]).view(np.uint8).reshape(new.size, -1)
            same &= (a == b).all(axis=1)
        coarse = (ref["outcome"] != new["outcome"]) | (ref["trials"] != new["trials"])
        report[condition] = {"cells": int(ref.size), "identical": int(same.sum()),
                             "outcome_or_trials": int(coarse.sum()),
                             "successes": int((ref["outcome"] == 1).sum()),
                             "new_successes": int((new["outcome"] == 1).sum())}
    return report


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generate", action="store_true", help="rewrite the reference cells")
    parser.add_argument("--ico-prior-from", type=Path, default=None,
                        help="ICO results directory of the prior (--generate only; default: the reference's own)")
    parser.add_argument("--condition", action="append", help="compare only these conditions")
    parser.add_argument("--reference", type=Path, default=REFERENCE, help="reference file (default: the committed one)")
    args = parser.parse_args(argv)
    if args.generate:
        generate(args.ico_prior_from, args.reference)
        return 0
    report = compare(args.condition, args.reference)
    meta = json.loads(str(np.load(args.reference)["meta"]))
    print(f"reference: commit {meta['commit']}, {len(meta['cells'])} cells, seed {meta['seed']}")
    for condition, row in report.items():
        print(f"{condition:24s} {row['identical']:3d} / {row['cells']} bit-identical, "
              f"{row['outcome_or_trials']} differ in outcome or trials (successes: {row['successes']} in the "
              f"reference, {row['new_successes']} now)")
    return 0 if all(r["identical"] == r["cells"] for r in report.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
