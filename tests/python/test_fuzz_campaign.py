# SPDX-License-Identifier: Apache-2.0
"""The fuzzing campaign (tests/fuzz/campaign.py): which target runs next and for how long, and a
whole campaign over stand-in fuzz executables that stops when every target meets its goal."""
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CAMPAIGN = REPO / "tests" / "fuzz" / "campaign.py"


@pytest.fixture
def campaign(monkeypatch):
    monkeypatch.syspath_prepend(str(CAMPAIGN.parent))
    import campaign
    return campaign


def test_a_target_without_runs_goes_first_for_a_full_chunk(campaign):
    tallies = {"a": (9_000, 100.0), "b": (0, 0.0)}
    assert campaign.next_run(tallies, set(), 10_000, 600, 1e9) == ("b", 600)


def test_the_target_nearest_its_goal_goes_next_for_the_seconds_it_needs(campaign):
    # a needs 1,000 executions at 10/s (100 s), c needs 500 at 1/s (500 s)
    tallies = {"a": (9_000, 900.0), "c": (9_500, 9_500.0), "met": (10_000, 5.0)}
    target, seconds = campaign.next_run(tallies, set(), 10_000, 3600, 1e9)
    assert target == "a" and 0 <= seconds - (100 * campaign.MARGIN + campaign.SLACK) < 1
    assert campaign.next_run(tallies, {"a"}, 10_000, 3600, 1e9)[0] == "c"
    assert campaign.next_run(tallies, {"a"}, 10_000, 60, 1e9) == ("c", 60)  # at most a chunk
    assert campaign.next_run(tallies, {"a", "c"}, 10_000, 3600, 1e9) is None  # busy, failed or met


def test_the_deadline_cuts_a_run_short_or_stops_the_campaign(campaign):
    tallies = {"a": (0, 0.0)}
    assert campaign.next_run(tallies, set(), 10, 1800, 900.5) == ("a", 900)
    assert campaign.next_run(tallies, set(), 10, 1800, campaign.SHORTEST_RUN - 1) is None
    nearly = {"a": (5, 1.0)}  # needs 1 s, so a run of 1.04 s + SLACK, rounded up
    assert campaign.next_run(nearly, set(), 10, 1800, 30) == ("a", 2 + campaign.SLACK)
    assert campaign.next_run(nearly, set(), 10, 1800, 2 + campaign.SLACK - 1) is None


def fake_fuzzer(path: Path, executions: int, status: int = 0) -> None:
    """Prints what libFuzzer prints at the end of a run of `executions` inputs."""
    path.write_text("#!/bin/sh\n"
                    f"printf '#{executions}\\tDONE   cov: 7 ft: 8 corp: 3/9b exec/s: 9 rss: 31Mb\\n'\n"
                    f"printf 'stat::number_of_executed_units: {executions}\\n'\n"
                    f"exit {status}\n")
    path.chmod(0o755)


def run_campaign(tmp_path: Path, targets: dict[str, tuple[int, int]], hours: str = "1"):
    for name in ("build", "corpus", "work", "ledger"):
        (tmp_path / name).mkdir()
    for target, (executions, status) in targets.items():
        fake_fuzzer(tmp_path / "build" / target, executions, status)
        (tmp_path / "corpus" / target).mkdir()
    args = [sys.executable, str(CAMPAIGN), "--sources", "src1", "--goal", "10000", "--chunk", "40",
            "--hours", hours, "--jobs", "2"]
    for name in ("ledger", "build", "corpus", "work"):
        args += [f"--{name}", str(tmp_path / name)]
    return subprocess.run(args + list(targets), capture_output=True, text=True, timeout=120)


def ledger_lines(tmp_path: Path, target: str) -> list[list[str]]:
    path = tmp_path / "ledger" / f"{target}.tsv"
    return [line.split("\t") for line in path.read_text().splitlines()[1:]] if path.exists() else []


def test_a_campaign_runs_each_target_until_it_meets_its_goal(tmp_path):
    out = run_campaign(tmp_path, {"fast": (6000, 0), "slow": (1000, 0)})
    assert out.returncode == 0, out.stdout + out.stderr
    fast, slow = ledger_lines(tmp_path, "fast"), ledger_lines(tmp_path, "slow")
    # fast: a 40 s chunk (6,000), then 4,000 short at 150/s wants 48 s, cut to the 40 s chunk
    assert [r[2:4] for r in fast] == [["40", "6000"], ["40", "6000"]]
    assert len(slow) == 10 and all(r[1] == "src1" and r[3] == "1000" for r in slow)
    assert "| fast | 2 |" in out.stdout and "| slow | 10 |" in out.stdout and out.stdout.count("| met |") == 2


def test_a_finding_takes_its_target_out_and_fails_the_campaign(tmp_path):
    out = run_campaign(tmp_path, {"crashes": (100, 77), "fine": (5000, 0)})
    assert out.returncode == 1
    assert [r[7] for r in ledger_lines(tmp_path, "crashes")] == ["77"]
    assert len(ledger_lines(tmp_path, "fine")) == 2 and "crashes: FAILED" in out.stdout


def test_no_time_no_runs(tmp_path):
    out = run_campaign(tmp_path, {"a": (5000, 0)}, hours="0")
    assert out.returncode == 0 and ledger_lines(tmp_path, "a") == []
