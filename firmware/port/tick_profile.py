#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Where a tick's instructions go on a microcontroller target, function by function.

Builds a cross preset, runs the port example under QEMU with one instruction per translation
block and every executed instruction logged with its function (-singlestep -d exec), and counts
the instructions of each function inside each timed tick loop of the example (ico, rl,
rl_literal, rl_batch, search), per tick. The counts are exact, not sampled. A C runtime function (memset,
sqrtf, expf, a soft-float helper, ...) is counted as the library's when the library called it.
The library's total per tick is what report.py measures with the SysTick, give or take the
example's loop and the few instructions of each call.

  python3 firmware/port/tick_profile.py [--preset cortex-m4f] [--top 15] [--loop rl_literal]

The trace is read through a pipe (about 16 million instructions, one to two minutes).
"""
import argparse
import collections
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests", "target"))
import target_check  # noqa: E402

# The example's timed tick loops, in the order main_target.c runs them (each after its stub run).
LOOPS = ("ico", "rl", "rl_literal", "rl_batch", "search")
# The example's own functions inside a timed loop (replay.c, main_target.c): not the library's.
EXAMPLE = {"replay_run", "step_stub", "reset_stub", "port_tick_start", "port_tick_done", "port_ticks_begin",
           "port_ticks_end", "port_read_sp", "timer_now", "timer_elapsed", "stack_paint", "stack_keep_low",
           "stack_scan", "spin"}


def library_functions(preset):
    """The functions libicoac.a defines (static ones included)."""
    out = subprocess.run(["arm-none-eabi-nm", "--defined-only", target_check.lib(preset)], check=True,
                         stdout=subprocess.PIPE, text=True).stdout
    return {f[2].split(".")[0] for f in (line.split() for line in out.splitlines()) if len(f) == 3 and f[1] in "Tt"}


def loops_of(trace, library):
    """Yield (counter of library instructions per function, ticks) for each timed loop that ran
    icoac_step (a loop that ran the example's stub is skipped)."""

    def is_library(symbol):
        return symbol.split(".")[0] in library

    counts, ticks, previous, owner, in_loop, stub = None, 0, "", "", False, False
    for line in trace:
        if not line.startswith(b"Trace"):
            continue
        symbol = line.rsplit(b"]", 1)[-1].strip().decode()
        if symbol != previous:
            if symbol == "port_ticks_begin":
                counts, ticks, in_loop, stub = collections.Counter(), 0, True, False
            elif symbol == "port_ticks_end" and in_loop:
                in_loop = False
                if not stub:
                    yield counts, ticks
            elif symbol == "port_tick_done" and previous == "replay_run":
                ticks += 1
            elif symbol == "step_stub":
                stub = True
            if symbol in EXAMPLE or is_library(symbol):
                owner = symbol
        previous = symbol
        if in_loop and symbol not in EXAMPLE and (is_library(symbol) or is_library(owner)):
            counts[symbol] += 1


def profile(preset):
    target_check.cmd_build(preset)
    with tempfile.TemporaryDirectory() as tmp:
        fifo = os.path.join(tmp, "trace")
        os.mkfifo(fifo)
        qemu = subprocess.Popen(["qemu-system-arm", "-M", target_check.BOARDS[preset], "-nographic",
                                 "-monitor", "none", "-serial", "none",
                                 "-semihosting-config", "enable=on,target=native", "-icount", "shift=0",
                                 "-singlestep", "-d", "exec,nochain", "-D", fifo, "-kernel", target_check.elf(preset)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with open(fifo, "rb", buffering=1 << 20) as trace:
            loops = list(loops_of(trace, library_functions(preset)))
        if qemu.wait(timeout=600) != 0:
            sys.exit(f"qemu exited with status {qemu.returncode}")
    # ico, rl, rl_literal and rl_batch run once; the search's phases each run its loop again: add them up
    out = {}
    for i, (counts, ticks) in enumerate(loops):
        name = LOOPS[min(i, len(LOOPS) - 1)]
        total, n = out.get(name, (collections.Counter(), 0))
        out[name] = (total + counts, n + ticks)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--preset", default="cortex-m4f", choices=sorted(target_check.BOARDS))
    ap.add_argument("--top", type=int, default=15, help="functions shown per loop")
    ap.add_argument("--loop", action="append", choices=LOOPS, help="loops shown (default: all)")
    args = ap.parse_args(argv)
    result = profile(args.preset)
    for name in args.loop or LOOPS:
        counts, ticks = result[name]
        total = sum(counts.values())
        print(f"\n{args.preset}, loop {name}: {total / ticks:.1f} library instructions per tick ({ticks} ticks)")
        print("| function | instructions per tick | share |")
        print("|---|---|---|")
        for symbol, n in counts.most_common(args.top):
            print(f"| {symbol} | {n / ticks:.1f} | {n / total:.1%} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
