# SPDX-License-Identifier: Apache-2.0
"""icoac.tools.speed_ab: it reads what the real programs print, runs the builds in alternating
order round after round, and its tables are the rounds' medians."""
import json
import subprocess

import pytest

from icoac.core import binding as B
from icoac.core.plants import PLANTS
from icoac.tools import results_tables, speed_ab

SIM_HOST = B.LIBRARY_PATH.parent


def test_it_reads_the_real_programs():
    bench = speed_ab.parse_bench(subprocess.run([str(SIM_HOST / "icoac_bench"), "--quick"], capture_output=True,
                                                text=True, check=True).stdout)
    for key in ("ico_engine", "ico_alone", "rl_engine", "rl_alone", "grid_s"):
        assert bench[key] > 0, key
    assert bench["ico_lanes"] == bench["rl_lanes"] == 16 and bench["grid_cells"] == 1225
    assert bench["lanes"] == [1, 2, 8, 16, 64]
    assert sorted(bench["by_lanes"]) == sorted(f"{p} {m}" for p in PLANTS for m in ("ico", "rl", "search"))
    assert all(len(v) == 5 and min(v) > 0 for v in bench["by_lanes"].values())
    reference = subprocess.run([str(SIM_HOST / "reference_tick"), "1600"], capture_output=True, text=True, check=True)
    assert speed_ab.parse_reference(reference.stdout) > 0


BENCH_TEXT = """icoac_bench: 4-byte reals, reference build (no fast-math)
ICO tick, one core:   {ico:.1f} ns in the engine ({lanes} cells in lockstep; target <= 25 ns),   80.0 ns for one cell alone  [1 ticks]
RL  tick, one core:  200.0 ns in the engine ({lanes} cells in lockstep; target <= 150 ns),  250.0 ns for one cell alone  [1 ticks]
{table}ICO grid, 1225 cells, max_trials 2000, all cores: 1.50 s, 1e+07 ticks/s, 1e+05 trials/s
"""
LANES_TEXT = """ns per tick on one core, by block size (the run's lanes): every 7-th cell
plant              mode          1       2
cart_pole          ico        {ico:.1f}    60.0
"""


def _program(path, log, name, lines):
    """A stand-in program that prints its next line of ``lines`` at each call and logs its name."""
    path.parent.mkdir(parents=True, exist_ok=True)
    data = path.with_suffix(".json")
    data.write_text(json.dumps(lines))
    path.write_text(f"""#!/usr/bin/env python3
import json, pathlib
lines = json.loads(pathlib.Path({str(data)!r}).read_text())
log = pathlib.Path({str(log)!r})
n = log.read_text().split().count({name!r}) if log.exists() else 0
with log.open("a") as f:
    f.write({name!r} + " ")
print(lines[n], end="")
""")
    path.chmod(0o755)


def test_rounds_alternate_and_the_tables_are_medians(tmp_path):
    log = tmp_path / "calls.log"
    before, after = tmp_path / "before", tmp_path / "after"
    _program(before / speed_ab.BENCH, log, "before",
             [BENCH_TEXT.format(ico=v, lanes=2, table="") for v in (30.0, 50.0, 40.0)])
    _program(after / speed_ab.BENCH, log, "after",
             [BENCH_TEXT.format(ico=v, lanes=16, table=LANES_TEXT.format(ico=v + 10)) for v in (22.0, 20.0, 90.0)])
    _program(after / speed_ab.REFERENCE, log, "reference",
             [f"reference ICO tick (plain C, scalar, libm): {v} ns  [5 ticks, 0]\n" for v in (33.0, 35.0, 31.0)])
    out = tmp_path / "speed.json"
    assert speed_ab.main(["--before", str(before), "--after", str(after), "--rounds", "3", "--data", str(out)]) == 0
    assert log.read_text().split() == ["reference", "before", "after", "reference", "after", "before",
                                       "reference", "before", "after"]
    record = json.loads(out.read_text())
    assert record["before"]["commit"] is None and record["rounds"] == 3
    rows = speed_ab.table(record)
    assert rows[2] == "| plain-C reference ICO tick (ns) | 33.0 (31.0-35.0) | (the same program) | 1 |"
    assert rows[3] == "| ICO tick, engine (ns) | 40.0 (30.0-50.0); 2 lanes | 22.0 (20.0-90.0); 16 lanes | 0.67 |"
    assert rows[4] == "| ICO tick, one cell alone (ns) | 80.0 (80.0-80.0) | 80.0 (80.0-80.0) | 2.42 |"
    assert speed_ab.lanes_table(record)[2] == "| cart_pole | ico | 32.0 | 60.0 |"
    assert "medians of 3 rounds interleaved" in results_tables.provenance(record)


def test_a_missing_or_failing_program_is_a_one_line_error(tmp_path, capsys):
    args = ["--before", str(tmp_path / "nowhere"), "--after", str(SIM_HOST.parent), "--data", str(tmp_path / "x.json")]
    assert speed_ab.main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "is not an executable" in err and len(err.splitlines()) == 1
    failing = tmp_path / "failing"
    for program in (speed_ab.BENCH, speed_ab.REFERENCE):
        (failing / program).parent.mkdir(parents=True, exist_ok=True)
        (failing / program).write_text("#!/bin/sh\necho broken >&2\nexit 3\n")
        (failing / program).chmod(0o755)
    assert speed_ab.main(["--before", str(failing), "--after", str(failing), "--data", str(tmp_path / "y.json")]) == 2
    err = capsys.readouterr().err
    assert "exited with status 3: broken" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "y.json").exists()


def test_rounds_below_one_are_refused(tmp_path, capsys):
    assert speed_ab.main(["--before", str(tmp_path), "--after", str(tmp_path), "--rounds", "0",
                          "--data", str(tmp_path / "z.json")]) == 2
    assert "--rounds 0" in capsys.readouterr().err
    with pytest.raises(speed_ab.UsageError, match="no table by block size"):
        speed_ab.lanes_table({"runs": {"after": [{}]}})
