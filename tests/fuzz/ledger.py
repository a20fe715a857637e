# SPDX-License-Identifier: Apache-2.0
"""What the long fuzzing runs (`make fuzz`) add up to: one row per target, from each target's
ledger LEDGER_DIR/<target>.tsv (tests/fuzz/run_fuzzer.sh), over the runs of the given C sources
only.

    python3 tests/fuzz/ledger.py LEDGER_DIR SOURCES

A run that ended with a non-zero status is a finding (its reproducer is in WORK/artifacts/)."""
import csv
import sys
from pathlib import Path

GOAL = 10_000_000  # executions per target for a deep fuzzing campaign


def rows(ledger: Path, sources: str) -> list[dict]:
    """The runs of the given sources; lines starting with '#' are comments."""
    with ledger.open(newline="") as f:
        lines = (line for line in f if not line.startswith("#"))
        return [r for r in csv.DictReader(lines, delimiter="\t") if r["sources"] == sources]


def main(ledger_dir: str, sources: str, goal: int = GOAL) -> int:
    print(f"fuzzing of sources {sources} (runs of other sources are not counted)\n")
    print(f"| target | runs | hours | executions | goal {goal:,} | coverage (last run) | features | corpus | findings |")
    print("|---|---|---|---|---|---|---|---|---|")
    for ledger in sorted(Path(ledger_dir).glob("*.tsv")):
        runs = rows(ledger, sources)
        if not runs:
            continue
        executions = sum(int(r["executions"]) for r in runs)
        hours = sum(float(r["seconds"]) for r in runs) / 3600
        findings = sum(r["status"] != "0" for r in runs)
        last = runs[-1]
        print(f"| {ledger.stem} | {len(runs)} | {hours:.2f} | {executions:,} | "
              f"{'met' if executions >= goal else f'{executions / goal:.0%}'} | {last['cov']} | {last['ft']} | "
              f"{last['corpus']} | {findings} |")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
