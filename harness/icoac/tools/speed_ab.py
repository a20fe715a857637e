# SPDX-License-Identifier: Apache-2.0
"""The tick speed of two builds side by side: each round runs the plain-C reference
(`reference_tick`, of the after build) and then both builds' `icoac_bench`, their order alternating
from round to round; the figures are medians over the rounds, with their range. Run it on a quiet
machine (the load average is recorded at the start and the end).

    python -m icoac.tools.speed_ab --before ../old/build/release --after build/release \\
        --data docs/data/speed-NAME.json

A build directory is a CMake build of the release preset (its programs in sim_host/); its commit is
the git tree holding it. The record keeps every round's figures; `python -m
icoac.tools.results_tables` writes its tables (speed-ab, speed-lanes) into docs/results.md."""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any, Mapping, Sequence

from icoac.core import results
from icoac.core.errors import UsageError
from icoac.tools.resumable import guarded

BENCH = Path("sim_host") / "icoac_bench"
REFERENCE = Path("sim_host") / "reference_tick"

# The figures of icoac_bench's first lines, (key, pattern); both builds print them alike.
_FIGURES = (
    ("ico_engine", r"ICO tick, one core:\s+([\d.]+) ns in the engine \((\d+) cells"),
    ("ico_alone", r"ICO tick, one core:.*?,\s+([\d.]+) ns for one cell alone"),
    ("rl_engine", r"RL  tick, one core:\s+([\d.]+) ns in the engine \((\d+) cells"),
    ("rl_alone", r"RL  tick, one core:.*?,\s+([\d.]+) ns for one cell alone"),
    ("grid", r"ICO grid, (\d+) cells, max_trials (\d+), all cores: ([\d.]+) s"),
)
_REFERENCE = re.compile(r"reference ICO tick .*?: ([\d.]+) ns")
_LANES_HEADER = re.compile(r"^plant\s+mode((?:\s+\d+)+)\s*$", re.M)


def parse_bench(text: str) -> dict[str, Any]:
    """icoac_bench's figures: ns a tick (engine, one cell alone; the engine's lanes), the ICO grid's
    seconds, cells and trial cap, and the table by block size when the build prints it."""
    out: dict[str, Any] = {}
    for key, pattern in _FIGURES:
        m = re.search(pattern, text)
        if m is None:
            raise UsageError(f"icoac_bench printed no {key.replace('_', ' ')} figure")
        if key == "grid":
            out["grid_cells"], out["grid_max_trials"], out["grid_s"] = int(m[1]), int(m[2]), float(m[3])
        else:
            out[key] = float(m[1])
            if key.endswith("engine"):
                out[key.replace("engine", "lanes")] = int(m[2])
    header = _LANES_HEADER.search(text)
    if header:
        out["lanes"] = [int(n) for n in header[1].split()]
        out["by_lanes"] = {}
        for line in text[header.end():].splitlines()[1:]:
            parts = line.split()
            if len(parts) != 2 + len(out["lanes"]):
                break
            out["by_lanes"][f"{parts[0]} {parts[1]}"] = [float(v) for v in parts[2:]]
    return out


def parse_reference(text: str) -> float:
    m = _REFERENCE.search(text)
    if m is None:
        raise UsageError("reference_tick printed no figure")
    return float(m[1])


def _run(program: Path) -> str:
    res = subprocess.run([str(program)], capture_output=True, text=True)
    if res.returncode != 0:
        raise UsageError(f"{program} exited with status {res.returncode}: {res.stderr.strip()[:200]}")
    return res.stdout


def _tree(build: Path) -> dict[str, Any]:
    """The commit of the git tree holding a build directory, and whether its sources differ from it."""
    res = subprocess.run(["git", "-C", str(build), "rev-parse", "--show-toplevel"], capture_output=True, text=True)
    if res.returncode != 0:
        return {"commit": None, "dirty": None}
    return results.git_info(Path(res.stdout.strip()))


def _machine() -> dict[str, Any]:
    model, flags = platform.processor() or "unknown", set()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
            elif line.startswith("flags"):
                flags = set(line.split(":", 1)[1].split())
    except OSError:
        pass
    vector = [f for f in ("sse2", "avx2", "avx512f") if f in flags]
    return {"cpu": model, "cores": os.cpu_count(), "vector": vector}


def measure(before: Path, after: Path, rounds: int, log=print) -> dict[str, Any]:
    """Both builds' figures over ``rounds`` interleaved rounds (the record of --data)."""
    programs = {"before": before / BENCH, "after": after / BENCH, "reference": after / REFERENCE}
    for program in programs.values():
        if not os.access(program, os.X_OK):
            raise UsageError(f"{program} is not an executable: build the release preset there first")
    runs: dict[str, list] = {"reference": [], "before": [], "after": []}
    load_start = os.getloadavg()[0]
    for r in range(rounds):
        runs["reference"].append(parse_reference(_run(programs["reference"])))
        for name in ("before", "after") if r % 2 == 0 else ("after", "before"):
            runs[name].append(parse_bench(_run(programs[name])))
        log(f"round {r + 1}/{rounds}: reference {runs['reference'][-1]:.1f} ns, ICO engine before "
            f"{runs['before'][-1]['ico_engine']:.1f} ns, after {runs['after'][-1]['ico_engine']:.1f} ns")
    return {"kind": "speed", "rounds": rounds, "machine": _machine(),
            "load_average": {"start": load_start, "end": os.getloadavg()[0]},
            "before": {"build": str(before), **_tree(before)}, "after": {"build": str(after), **_tree(after)},
            "timestamp": results.timestamp(), "runs": runs}


def _median(values: Sequence[float], digits: int = 1) -> str:
    return f"{statistics.median(values):.{digits}f} ({min(values):.{digits}f}-{max(values):.{digits}f})"


def _commit(side: Mapping[str, Any]) -> str:
    return (side.get("commit") or "unknown")[:7] + ("+dirty" if side.get("dirty") else "")


def table(data: Mapping[str, Any]) -> list[str]:
    """Medians (ranges) of the rounds: the reference, each build's ticks and ICO grid, and the
    after build's ratio to the reference."""
    runs, ref = data["runs"], statistics.median(data["runs"]["reference"])
    b, a = runs["before"], runs["after"]

    def lanes(side: Sequence[Mapping[str, Any]], key: str) -> str:
        return f"; {side[0][key]} lanes" if key.endswith("_lanes") else ""

    rows = [f"| measurement | before ({_commit(data['before'])}) | after ({_commit(data['after'])}) "
            "| after ÷ reference |", "|---|---|---|---|",
            f"| plain-C reference ICO tick (ns) | {_median(runs['reference'])} | (the same program) | 1 |"]
    for key, label in (("ico_engine", "ICO tick, engine (ns)"), ("ico_alone", "ICO tick, one cell alone (ns)"),
                       ("rl_engine", "RL tick, engine (ns)"), ("rl_alone", "RL tick, one cell alone (ns)")):
        lane_key = key.replace("engine", "lanes")
        after = [r[key] for r in a]
        rows.append(f"| {label} | {_median([r[key] for r in b])}{lanes(b, lane_key)} | "
                    f"{_median(after)}{lanes(a, lane_key)} | {statistics.median(after) / ref:.2f} |")
    rows.append(f"| ICO grid, {a[0]['grid_cells']} cells, {a[0]['grid_max_trials']}-trial cap, all cores (s) | "
                f"{_median([r['grid_s'] for r in b], 2)} | {_median([r['grid_s'] for r in a], 2)} | |")
    return rows


def lanes_table(data: Mapping[str, Any]) -> list[str]:
    """The after build's ns a tick by block size, medians over the rounds."""
    a = data["runs"]["after"]
    if "by_lanes" not in a[0]:
        raise UsageError("the after build printed no table by block size")
    lanes = a[0]["lanes"]
    rows = ["| plant | mode | " + " | ".join(f"{n} lane{'s' if n > 1 else ''}" for n in lanes) + " |",
            "|---|---|" + "---|" * len(lanes)]
    for key in a[0]["by_lanes"]:
        medians = [statistics.median(r["by_lanes"][key][i] for r in a) for i in range(len(lanes))]
        rows.append(f"| {' | '.join(key.split())} | " + " | ".join(f"{m:.1f}" for m in medians) + " |")
    return rows


def provenance(data: Mapping[str, Any]) -> str:
    """The line under a speed table: the builds, the rounds and the machine."""
    m, load = data["machine"], data["load_average"]
    return (f"*From docs/data: `icoac_bench` of {_commit(data['before'])} (before) and {_commit(data['after'])} "
            f"(after), `reference_tick` of the after build, medians of {data['rounds']} rounds interleaved; "
            f"{m['cpu']}, {m['cores']} cores, {', '.join(m['vector']).upper()}; 1-minute load "
            f"average {load['start']:.1f} at the start, {load['end']:.1f} at the end; {data['timestamp']}.*")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.speed_ab", description=__doc__.split("\n")[0])
    ap.add_argument("--before", type=Path, required=True, help="the build directory to compare against")
    ap.add_argument("--after", type=Path, required=True, help="the build directory measured (and its reference)")
    ap.add_argument("--rounds", type=int, default=7, help="interleaved rounds (default 7)")
    ap.add_argument("--data", type=Path, required=True, help="the record to write (docs/data/speed-NAME.json)")
    args = ap.parse_args(argv)

    def body() -> None:
        if args.rounds < 1:
            raise UsageError(f"--rounds {args.rounds}: at least 1")
        record = measure(args.before, args.after, args.rounds, log=lambda s: print(s, file=sys.stderr))
        args.data.parent.mkdir(parents=True, exist_ok=True)
        args.data.write_text(json.dumps(record, indent=1) + "\n")
        print("\n".join(table(record)))
    return guarded(body)[0]


if __name__ == "__main__":
    raise SystemExit(main())
