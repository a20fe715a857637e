# SPDX-License-Identifier: Apache-2.0
"""firmware/port/tick_profile.py's trace reader: per timed tick loop of the port example, the library's
instructions per function (C runtime calls counted for their caller's side), stub loops skipped."""
import importlib.util
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("tick_profile", REPO / "firmware" / "port" / "tick_profile.py")
tick_profile = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tick_profile)

LIBRARY = {"icoac_step", "icoac_priv_rl_tick", "mean_step"}


def trace(*runs):
    """Trace lines as QEMU's -d exec prints them, one per instruction: (symbol, instructions)."""
    lines = [b"Stopped execution of TB chain before 0x7f5bd8125c40 [0000b186] icoac_step\n"]
    for symbol, n in (item for run in runs for item in run):
        lines += [f"Trace 0: 0x7f00 [00800400/0000{i:04x}/00000010/ff020201] {symbol}\n".encode() for i in range(n)]
    return lines


def loop(step, ticks):
    body = [("port_ticks_begin", 5)]
    for _ in range(ticks):
        body += [("replay_run", 3), ("port_tick_start", 2), ("replay_run", 1), ("memcpy", 4), ("replay_run", 1), *step,
                 ("replay_run", 1), ("port_tick_done", 6)]
    return body + [("replay_run", 2), ("port_ticks_end", 4)]


def test_loops_count_the_library_per_function_and_skip_stub_loops():
    tick = [("icoac_step", 10), ("icoac_priv_rl_tick", 20), ("memset", 3), ("icoac_priv_rl_tick", 2),
            ("mean_step.isra.0", 7), ("icoac_step", 1)]
    stub = [("step_stub", 4)]
    got = list(tick_profile.loops_of(iter(trace(loop(stub, 3), loop(tick, 3), [("main", 9)], loop(stub, 2),
                                           loop(tick, 2))), LIBRARY))
    assert [ticks for _, ticks in got] == [3, 2]
    counts, ticks = got[0]
    # memcpy called by the example is not counted; memset called by the library is
    assert dict(counts) == {"icoac_step": 33, "icoac_priv_rl_tick": 66, "memset": 9, "mean_step.isra.0": 21}
    assert sum(got[1][0].values()) == 2 * 43
