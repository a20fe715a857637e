# SPDX-License-Identifier: Apache-2.0
"""One w for all cells, held out: each optimiser of `ceiling` (--optimiser) searches on the plant's
tuning cells (`--cells tuning`, icoac.studies.heldout) with the same budget and seed, and the w it
chooses is evaluated on every cell; success is reported on the tuning cells, the held-out cells and
all cells, under both protocols (first trial, retries).

    python -m icoac.tools.one_w --plant cart_pole --out results/one-w-cart_pole --threads 1 \\
        --data docs/data/one-w-cart_pole.json

Every step is a `python -m icoac ceiling` command (printed and recorded): OUT/<optimiser>/tuning/
(the search, its confirmation and evaluation on the tuning cells), then OUT/<optimiser>/all/
(`--w` of the chosen w, every cell). A rerun reuses what finished (the ceiling command resumes).
The tuning cells' numbers come from the all-cells evaluation and are checked against the tuning
run's own."""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

import icoac
from icoac.core import geometry, metrics, results, store
from icoac.core.errors import ResultsError
from icoac.core.metrics import percent
from icoac.core.options import CEILING_FILE, CEILING_OPTIMISERS, CEILING_PROTOCOLS
from icoac.studies import heldout
from icoac.studies.ceiling.weights import format_w
from icoac.tools.resumable import guarded

SPLITS = ("tuning", "heldout", "all")


def ceiling_args(plant: str, out: Path, seed: int, threads: int, optimiser: str | None = None,
                 w: Sequence[float] | None = None) -> list[str]:
    """The ceiling command of one step: the search on the tuning cells, or the evaluation of w on every cell."""
    head = ["ceiling", "--plant", plant, "--seed", str(seed), "--threads", str(threads), "--out", str(out)]
    if w is None:
        return head + ["--optimiser", optimiser, "--cells", heldout.TUNING_CELLS]
    return head + ["--w", ",".join(repr(v) for v in w)]


def run_ceiling(args: list[str]) -> dict[str, Any]:
    """`python -m icoac ceiling ARGS` with this harness; its ceiling.json."""
    print("python -m icoac " + " ".join(args), file=sys.stderr, flush=True)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(Path(icoac.__file__).parents[1]),
                                                                      os.environ.get("PYTHONPATH")]))}
    status = subprocess.run([sys.executable, "-m", "icoac", *args], env=env).returncode
    if status == 130:
        raise KeyboardInterrupt
    if status != 0:
        raise ResultsError(f"`ceiling {' '.join(args[:2])} ...` exited with status {status}")
    return json.loads((Path(args[args.index("--out") + 1]) / CEILING_FILE).read_text())


def split_success(cells: np.ndarray, plant: str) -> dict[str, dict[str, Any]]:
    """Successes on the tuning, held-out and all cells of an every-cell evaluation (grid order)."""
    held = heldout.heldout_mask(plant)
    if cells.size != held.size:
        raise ResultsError(f"an all-cells evaluation has {cells.size} cells, the grid {held.size}")
    ok = metrics.success_mask(cells)
    out = {}
    for split, mask in zip(SPLITS, (~held, held, np.ones_like(held))):
        n = int(mask.sum())
        out[split] = {"n_success": int((ok & mask).sum()), "n_cells": n, "success_rate": float((ok & mask).sum()) / n}
    return out


def one_optimiser(plant: str, optimiser: str, root: Path, seed: int, threads: int) -> dict[str, Any]:
    """Search on the tuning cells, evaluation on every cell; the optimiser's entry of the data."""
    tuning_args = ceiling_args(plant, root / optimiser / "tuning", seed, threads, optimiser)
    tuned = run_ceiling(tuning_args)
    w = tuned["best"]["w"]
    all_args = ceiling_args(plant, root / optimiser / "all", seed, threads, w=w)
    every = run_ceiling(all_args)
    success = {}
    for protocol in CEILING_PROTOCOLS:
        cells, _ = results.load(root / optimiser / "all" / every["best"]["protocols"][protocol]["dir"])
        success[protocol] = split_success(cells, plant)
        own = tuned["best"]["protocols"][protocol]["n_success"]
        if success[protocol]["tuning"]["n_success"] != own:
            raise ResultsError(f"{optimiser}, {protocol}: the all-cells evaluation succeeds in "
                               f"{success[protocol]['tuning']['n_success']} tuning cells, the tuning run in {own}")
    s = tuned["search"]
    return {"optimiser": optimiser, "budget": s["candidates"], "screened": s["screened"], "stop": s["stop"],
            "screen_steps": s["screen_steps"], "confirm": s["confirm"],
            "settings": {k: v for k, v in s["optimiser"].items() if k != "runs"},
            "cma_runs": len(s["optimiser"].get("runs", [])), "w": w, "success": success,
            "wall_time": {"search": tuned["wall_time"], "screens": s["screen_wall_time"],
                          "evaluation": every["wall_time"]},
            "commands": ["python -m icoac " + " ".join(a) for a in (tuning_args, all_args)],
            "git": {"tuning": tuned["git"], "all": every["git"]}}


def table(datas: Sequence[Mapping[str, Any]]) -> list[str]:
    """The two optimisers per plant (docs/results.md, block one-w): success of the chosen w, first
    trial / retries, on the tuning, held-out and all cells."""
    first = datas[0]
    head = " | ".join(f"{name} cells ({first['n_' + key]})" for name, key in
                      (("tuning", "tuning_cells"), ("held-out", "heldout_cells"), ("all", "cells")))
    lines = [f"| plant | optimiser | candidates screened | chosen w | {head} | wall time (s) |",
             "|---|---|---|---|---|---|---|---|"]
    for data in datas:
        for e in data["optimisers"].values():
            rates = " | ".join(" / ".join(percent(e["success"][p][split]["success_rate"]) for p in CEILING_PROTOCOLS)
                               for split in SPLITS)
            wall = e["wall_time"]["search"] + e["wall_time"]["evaluation"]
            lines.append(f"| {data['plant']} | {e['optimiser']} | {e['screened']} of {e['budget']} | "
                         f"{format_w(e['w'], 3)} | {rates} | {wall:.0f} |")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.one_w", description=__doc__.split("\n")[0])
    ap.add_argument("--plant", default="cart_pole")
    ap.add_argument("--out", required=True, type=Path, help="OUT/<optimiser>/{tuning,all}/: ceiling directories")
    ap.add_argument("--optimisers", nargs="+", choices=CEILING_OPTIMISERS, default=list(CEILING_OPTIMISERS))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--data", type=Path, help="write the summary's data here (docs/data/one-w-<plant>.json)")
    args = ap.parse_args(argv)
    command = "python -m icoac.tools.one_w " + " ".join(argv if argv is not None else sys.argv[1:])

    def body() -> dict[str, Any]:
        entries = {o: one_optimiser(args.plant, o, args.out, args.seed, args.threads) for o in args.optimisers}
        held = heldout.heldout_mask(args.plant)
        builds = {json.dumps(g, sort_keys=True) for e in entries.values() for g in e["git"].values()}
        data = {"plant": args.plant, "profile": "default", "configuration": "default", "set": [],
                "seeds": [args.seed], "n_cells": int(geometry.of(args.plant).cells),
                "n_tuning_cells": int((~held).sum()), "n_heldout_cells": int(held.sum()),
                "command": command, "git": results.git_info(), "cell_builds": [json.loads(b) for b in sorted(builds)],
                "optimisers": entries}
        if args.data is not None:
            store.write_json(args.data, data, indent=1)
        print("\n".join(table([data])))
        return data

    status, _ = guarded(body)
    return status


if __name__ == "__main__":
    raise SystemExit(main())
