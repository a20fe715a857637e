# SPDX-License-Identifier: Apache-2.0
"""The fuzzing ledger: tests/fuzz/run_fuzzer.sh appends one line per run, parsed from libFuzzer's
output, and tests/fuzz/ledger.py adds up the runs of one source id per target. A stand-in for
the fuzz executable prints what libFuzzer prints at the end of a run."""
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
RUN = REPO / "tests" / "fuzz" / "run_fuzzer.sh"
LEDGER = REPO / "tests" / "fuzz" / "ledger.py"


def fake_fuzzer(path: Path, executions: int, cov: int, ft: int, status: int) -> Path:
    path.write_text("#!/bin/sh\n"
                    f"printf '#2\\tINITED cov: 5 ft: 6 corp: 1/1b exec/s: 0 rss: 30Mb\\n'\n"
                    f"printf '#{executions}\\tDONE   cov: {cov} ft: {ft} corp: 3/9b exec/s: 9 rss: 31Mb\\n'\n"
                    f"printf 'stat::number_of_executed_units: {executions}\\n'\n"
                    f"exit {status}\n")
    path.chmod(0o755)
    return path


def fuzz(exe: Path, work: Path, sources: str, ledger: Path | None = None) -> subprocess.CompletedProcess:
    corpus = work.parent / "seed"
    corpus.mkdir(parents=True, exist_ok=True)
    env = {"PATH": "/usr/bin:/bin", "ICOAC_FUZZ_SOURCES": sources,
           **({} if ledger is None else {"ICOAC_FUZZ_LEDGER": str(ledger)})}
    return subprocess.run(["sh", str(RUN), "fuzz", "7", str(exe), str(corpus), str(work)], capture_output=True,
                          text=True, env=env)


def ledger(root: Path, sources: str) -> dict[str, list[str]]:
    out = subprocess.run([sys.executable, str(LEDGER), str(root), sources], capture_output=True, text=True,
                         check=True).stdout
    return {cols[1].strip(): [c.strip() for c in cols[2:-1]]
            for cols in (line.split("|") for line in out.splitlines()) if len(cols) > 3 and cols[1].strip()
            not in ("target", "---")}


def test_runs_add_up_per_source_id(tmp_path):
    work, book = tmp_path / "work", tmp_path / "ledger"
    a, b = work / "fuzz_a", work / "fuzz_b"
    assert fuzz(fake_fuzzer(tmp_path / "a1", 1200, 40, 90, 0), a, "src1", book / "fuzz_a.tsv").returncode == 0
    assert fuzz(fake_fuzzer(tmp_path / "a2", 3400, 44, 99, 0), a, "src1", book / "fuzz_a.tsv").returncode == 0
    assert fuzz(fake_fuzzer(tmp_path / "a3", 5000000, 50, 120, 0), a, "src2", book / "fuzz_a.tsv").returncode == 0
    failed = fuzz(fake_fuzzer(tmp_path / "b1", 77, 3, 4, 1), b, "src1", book / "fuzz_b.tsv")
    assert failed.returncode == 1 and "FAILED" in failed.stdout
    assert not (a / "ledger.tsv").exists()
    lines = (book / "fuzz_a.tsv").read_text().splitlines()
    assert lines[0].split("\t") == ["utc", "sources", "seconds", "executions", "cov", "ft", "corpus", "status"]
    assert [line.split("\t")[1:6] for line in lines[1:]] == [["src1", "7", "1200", "40", "90"],
                                                             ["src1", "7", "3400", "44", "99"],
                                                             ["src2", "7", "5000000", "50", "120"]]
    rows = ledger(book, "src1")
    # runs, hours, executions, goal, coverage and features of the last run, corpus, findings
    assert rows["fuzz_a"][:6] == ["2", "0.00", "4,600", "0%", "44", "99"] and rows["fuzz_a"][7] == "0"
    assert rows["fuzz_b"][2] == "77" and rows["fuzz_b"][7] == "1"
    assert ledger(book, "src2")["fuzz_a"][2:4] == ["5,000,000", "50%"]
    assert ledger(book, "src3") == {}


def test_comment_lines_are_skipped(tmp_path):
    book = tmp_path / "ledger"
    book.mkdir()
    (book / "fuzz_d.tsv").write_text("# transcribed from an earlier checkout\n"
                                     "utc\tsources\tseconds\texecutions\tcov\tft\tcorpus\tstatus\n"
                                     "2026-01-01T00:00:00Z\tsrc1\t60\t900\t5\t6\t7\t0\n")
    assert fuzz(fake_fuzzer(tmp_path / "d1", 100, 8, 9, 0), tmp_path / "work" / "fuzz_d", "src1",
                book / "fuzz_d.tsv").returncode == 0
    assert ledger(book, "src1")["fuzz_d"][:3] == ["2", "0.02", "1,000"]


def test_without_a_ledger_path_the_line_goes_to_the_work_directory(tmp_path):
    work = tmp_path / "work" / "fuzz_c"
    assert fuzz(fake_fuzzer(tmp_path / "c1", 500, 7, 8, 0), work, "src1").returncode == 0
    lines = (work / "ledger.tsv").read_text().splitlines()
    assert len(lines) == 2 and lines[1].split("\t")[1:4] == ["src1", "7", "500"]
