# SPDX-License-Identifier: Apache-2.0
"""A deep fuzzing campaign (`make fuzz-campaign`): fuzz the targets still short of the ledger's
goal, JOBS at a time, in runs of at most CHUNK seconds, until every target meets the goal or the
time is up. Each run resumes from the inputs the earlier ones found and adds its line to the
ledger as it ends, so a stopped campaign loses at most the runs in progress.

    python3 tests/fuzz/campaign.py --sources ID --ledger DIR --build DIR --corpus DIR --work DIR
                                   --hours H [--jobs N] [--chunk S] [--goal E] TARGET...

The target nearest its goal (in seconds at its past rate) goes first, so that targets meet it
one after the other; a target without runs gets a full chunk, which measures its rate. A run
that fails (a finding) takes its target out of the campaign, and the exit status is then 1."""
import argparse
import math
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import ledger

RUN_FUZZER = Path(__file__).resolve().parent / "run_fuzzer.sh"
MARGIN = 1.04  # a run aims this much past the goal at the past rate, plus SLACK seconds
SLACK = 20
SHORTEST_RUN = 300  # s: below this, a run cut short by the deadline is not started


def tally(ledger_file: Path, sources: str) -> tuple[int, float]:
    """Executions and seconds of the runs of `sources` in one target's ledger."""
    if not ledger_file.exists():
        return 0, 0.0
    runs = ledger.rows(ledger_file, sources)
    return sum(int(r["executions"]) for r in runs), sum(float(r["seconds"]) for r in runs)


def next_run(tallies: dict[str, tuple[int, float]], skip: set[str], goal: int, chunk: int,
             left: float) -> tuple[str, int] | None:
    """The target to fuzz next and for how many seconds, or None when none is left or time is up."""
    def seconds_to_goal(target):
        executions, seconds = tallies[target]
        return math.inf if executions == 0 or seconds == 0 else (goal - executions) * seconds / executions

    short = [t for t in tallies if t not in skip and tallies[t][0] < goal]
    if not short:
        return None
    target = min(short, key=lambda t: (-math.inf if tallies[t][0] == 0 else seconds_to_goal(t), t))
    want = chunk if tallies[target][0] == 0 else min(chunk, math.ceil(seconds_to_goal(target) * MARGIN) + SLACK)
    if left < min(want, SHORTEST_RUN):
        return None
    return target, int(min(want, left))


class Campaign:
    def __init__(self, args):
        self.args = args
        self.deadline = time.monotonic() + args.hours * 3600
        self.lock = threading.Lock()
        self.busy: set[str] = set()
        self.failed: set[str] = set()

    def ledger_file(self, target: str) -> Path:
        return Path(self.args.ledger) / f"{target}.tsv"

    def claim(self) -> tuple[str, int] | None:
        with self.lock:
            tallies = {t: tally(self.ledger_file(t), self.args.sources) for t in self.args.targets}
            pick = next_run(tallies, self.busy | self.failed, self.args.goal, self.args.chunk,
                            self.deadline - time.monotonic())
            if pick:
                self.busy.add(pick[0])
            return pick

    def fuzz(self, target: str, seconds: int) -> None:
        a = self.args
        env = dict(os.environ, ICOAC_FUZZ_SOURCES=a.sources, ICOAC_FUZZ_LEDGER=str(self.ledger_file(target)))
        print(f"{time.strftime('%H:%M:%S')} {target}: {seconds} s", flush=True)
        run = subprocess.run(["sh", str(RUN_FUZZER), "fuzz", str(seconds), str(Path(a.build) / target),
                              str(Path(a.corpus) / target), str(Path(a.work) / target)],
                             env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        executions, _ = tally(self.ledger_file(target), a.sources)
        with self.lock:
            self.busy.discard(target)
            if run.returncode:
                self.failed.add(target)
                print(run.stdout, end="", flush=True)
            print(f"{time.strftime('%H:%M:%S')} {target}: {'FAILED' if run.returncode else 'done'}, "
                  f"{executions:,} executions of these sources", flush=True)

    def worker(self) -> None:
        while pick := self.claim():
            self.fuzz(*pick)

    def run(self) -> int:
        workers = [threading.Thread(target=self.worker) for _ in range(self.args.jobs)]
        for w in workers:
            w.start()
        for w in workers:
            w.join()
        print()
        ledger.main(self.args.ledger, self.args.sources, self.args.goal)
        return 1 if self.failed else 0


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    for name in ("sources", "ledger", "build", "corpus", "work"):
        p.add_argument(f"--{name}", required=True)
    p.add_argument("--hours", type=float, required=True)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--chunk", type=int, default=1800, help="longest run, in seconds")
    p.add_argument("--goal", type=int, default=ledger.GOAL, help="executions per target")
    p.add_argument("targets", nargs="+")
    args = p.parse_args(argv)
    if args.jobs < 1 or args.chunk < 1 or args.goal < 1 or not args.hours >= 0:
        p.error("--jobs, --chunk and --goal must be positive, --hours not negative")
    return Campaign(args).run()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
