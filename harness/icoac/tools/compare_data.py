# SPDX-License-Identifier: Apache-2.0
"""Two bench summaries (docs/data/*.json) side by side: each condition's success rate over all
cells and over the interior cells, before and after, as mean ± sd over the seeds, the change, and
whether the change stays within the seed spread (|after - before| <= the larger of the two sds,
or both sds are 0 and nothing changed). A summary is a path, or REV:PATH for the committed file of
a git revision, so that a table of a change that moved the results' bits is bound to both commits.

    python -m icoac.tools.compare_data 16d6ea5:docs/data/bench-default.json docs/data/bench-default.json
"""
from __future__ import annotations

import argparse
import json
import subprocess
from pathlib import Path
from typing import Any, Mapping

ROOT = Path(__file__).resolve().parents[3]
RATES = (("success_rate", "all cells"), ("success_rate_interior", "interior"))


def load(spec: str) -> Mapping[str, Any]:
    """A summary from a path, or from REV:PATH in the repository's history."""
    if Path(spec).exists():
        return json.loads(Path(spec).read_text())
    rev, sep, path = spec.partition(":")
    if not sep:
        raise SystemExit(f"compare_data: no file {spec}")
    out = subprocess.run(["git", "-C", str(ROOT), "show", f"{rev}:{path}"], capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"compare_data: {spec}: {out.stderr.strip()}")
    return json.loads(out.stdout)


def _cell(stat: Mapping[str, Any]) -> str:
    return f"{100 * stat['mean']:.1f} ± {100 * stat['sd']:.1f}"


def rows(before: Mapping[str, Any], after: Mapping[str, Any]) -> list[dict[str, Any]]:
    """One row per condition of both summaries and rate: its name, the two stats, the change (in
    percentage points) and whether it is within the seed spread."""
    out = []
    for condition, new in after["aggregate"].items():
        old = before["aggregate"].get(condition)
        if old is None:
            continue
        for key, label in RATES:
            a, b = old[key], new[key]
            change = b["mean"] - a["mean"]
            spread = max(a["sd"] or 0.0, b["sd"] or 0.0)
            out.append({"condition": condition, "rate": label, "before": a, "after": b,
                        "change": 100 * change, "within": abs(change) <= spread})
    return out


def markdown(before: Mapping[str, Any], after: Mapping[str, Any]) -> str:
    lines = [f"| condition | cells | before ({before['git']['commit'][:7]}, %) | after ({after['git']['commit'][:7]}, %) "
             "| change (points) | within the seed spread |", "|---|---|---|---|---|---|"]
    for r in rows(before, after):
        lines.append(f"| {r['condition']} | {r['rate']} | {_cell(r['before'])} | {_cell(r['after'])} | "
                     f"{r['change']:+.2f} | {'yes' if r['within'] else '**no**'} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", help="summary before: a path or REV:PATH")
    parser.add_argument("after", help="summary after: a path or REV:PATH")
    args = parser.parse_args(argv)
    print(markdown(load(args.before), load(args.after)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
