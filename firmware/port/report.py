#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Resource report of the microcontroller targets.

Builds the cortex-m4f and cortex-m0plus presets, runs the port example under QEMU with
-icount shift=0 (1 instruction = 1 ns of virtual time) and tabulates flash/RAM
(arm-none-eabi-size), struct sizes, peak stack and instructions per tick (and, for the search
learner, per update and per trial start); and the stack table: the static bound of each public
function (stack_bound.py) beside its painted peak.

  python3 firmware/port/report.py                      # print the table
  python3 firmware/port/report.py --update docs/porting.md   # rewrite the table between markers
(`make target-report` runs the second form.)
"""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests", "target"))
import target_check  # noqa: E402
import stack_bound  # noqa: E402  (firmware/port, on target_check's path)

BEGIN, END = "<!-- target-report:begin -->", "<!-- target-report:end -->"
STACK_BEGIN, STACK_END = "<!-- stack-report:begin -->", "<!-- stack-report:end -->"
GOALS = {"cortex-m4f": 3000, "cortex-m0plus": 100000}
DOC = os.path.join(ROOT, "docs", "porting.md")
PRESETS = ("cortex-m4f", "cortex-m0plus")
BUDGETS = {p: stack_bound.read_budget(DOC, p) for p in PRESETS}
# the public functions of the stack table: the painted ones first (main_target.c, "M calls")
STACK_FUNCTIONS = ("icoac_step", "icoac_init", "icoac_reset", "icoac_retune", "icoac_config_check",
                   "icoac_get_posterior", "icoac_prior_check", "icoac_rng_normal")


def search_batch():
    """REPLAY_SEARCH_BATCH of the recorded inputs (search.batch of the replay)."""
    path = os.path.join(ROOT, "firmware", "port", "common", "recorded_inputs.h")
    return int(re.search(r"^#define REPLAY_SEARCH_BATCH (\d+)", open(path).read(), re.M).group(1))


BATCH = search_batch()


def size_of(path):
    """(text, data, bss) summed over every object / the ELF."""
    out = subprocess.run(["arm-none-eabi-size", "-t", path], check=True, stdout=subprocess.PIPE,
                         text=True).stdout.splitlines()
    line = out[-1] if path.endswith(".a") else out[1]
    text, data, bss = (int(v) for v in line.split()[:3])
    return text, data, bss


def linked_sizes(map_path):
    """Flash bytes of the example's input sections from libicoac.a and from the C runtime
    libraries (libm, libc, libgcc), after --gc-sections, read from the linker map."""
    sums = {"icoac": 0, "runtime": 0}
    pending = None
    in_memory_map = False
    for line in open(map_path):
        if line.startswith("Linker script and memory map"):
            in_memory_map = True
            continue
        if not in_memory_map or line.startswith("/DISCARD/"):
            continue
        m = re.match(r"^ (\.\S+)\s*$", line)
        if m:
            pending = m.group(1)
            continue
        m = re.match(r"^ (\.\S+)?\s+0x[0-9a-f]+\s+0x([0-9a-f]+)\s+(\S+)\s*$", line)
        if m:
            sect = m.group(1) or pending
            pending = None
            if not sect or not sect.startswith((".text", ".rodata", ".data")):
                continue
            size, obj = int(m.group(2), 16), m.group(3)
            if "libicoac.a(" in obj:
                sums["icoac"] += size
            elif re.search(r"lib(m|c|c_nano|gcc)\.a\(", obj):
                sums["runtime"] += size
        else:
            pending = None
    return sums


def step_frame(preset):
    """Own frame of icoac_step from the library's -fstack-usage output."""
    su_dir = os.path.join(target_check.build_dir(preset), "firmware", "CMakeFiles", "icoac.dir", "src")
    for line in open(os.path.join(su_dir, "icoac_step.c.su")):
        if ":icoac_step\t" in line:
            return int(line.split("\t")[1])
    return -1


def measure(preset):
    target_check.cmd_build(preset)
    out = target_check.run_qemu(preset)
    z = dict(kv.split("=") for kv in re.search(r"^Z (.*)$", out, re.M).group(1).split())
    cal = dict(kv.split("=") for kv in re.search(r"^C (.*)$", out, re.M).group(1).split())
    insn_per_count = int(cal["insns"]) / int(cal["systick"])
    meas = target_check.measurements(out)
    ticks = {}
    for mode in ("ico", "rl", "rl_literal", "rl_batch"):
        kv = meas[mode]
        net = (kv["systick_total"] - kv["systick_base"]) * insn_per_count / kv["ticks"]
        worst = (kv["systick_max"] - kv["systick_base_max"]) * insn_per_count
        ticks[mode] = (net, kv["stack"], worst)
    # Search: the update ticks (terminal ticks that close a batch) apart from the others; every
    # SysTick sum is over `phases` runs.
    kv = meas["search"]
    phases, updates = kv["phases"], kv["updates"]
    update = kv["systick_update"] - kv["systick_update_base"]
    search = {
        "ticks": kv["ticks"], "updates": updates, "phases": phases,
        "tick": (kv["systick_total"] - kv["systick_base"] - update) * insn_per_count
                / (phases * (kv["ticks"] - updates)),
        "update": update * insn_per_count / (phases * updates),
        "resets": kv["resets"],
        "reset": (kv["systick_reset"] - kv["systick_reset_base"]) * insn_per_count / kv["resets"],
        "stack": kv["stack"], "stack_update": kv["stack_update"],
    }
    return {
        "lib": size_of(target_check.lib(preset)),
        "linked": linked_sizes(target_check.elf(preset)[:-4] + ".map"),
        "elf": size_of(target_check.elf(preset)),
        "frame": step_frame(preset),
        "config": int(z["config"]), "state": int(z["state"]),
        "ico": ticks["ico"], "rl": ticks["rl"], "rl_literal": ticks["rl_literal"], "rl_batch": ticks["rl_batch"],
        "search": search, "board": target_check.BOARDS[preset],
        "painted": dict(target_check.painted_peaks(meas)), "calls": meas["calls"],
        "static": {fn: b for fn, (b, _) in stack_bound.analyse(preset)[0].items()},
        "recorded": sum(meas[m]["ticks"] for m in ("ico", "rl", "search")),  # the sequences in flash
        "insn_per_count": insn_per_count,
    }


def table(results):
    p = list(results)
    rows = [("", "goal") + tuple("%s (QEMU `%s`)" % (k, results[k]["board"]) for k in p)]
    rows.append(("---",) * (len(p) + 2))

    def row(name, goal, fn):
        rows.append((name, goal) + tuple(fn(results[k], k) for k in p))

    row("library flash: text + data (whole `libicoac.a`)", "", lambda r, k: "%d B" % (r["lib"][0] + r["lib"][1]))
    row("library flash linked into the example (after --gc-sections)", "",
        lambda r, k: "%d B" % r["linked"]["icoac"])
    row("libm/libc/libgcc flash in the example (float math for the library, memcpy)", "",
        lambda r, k: "%d B" % r["linked"]["runtime"])
    row("library RAM: data + bss", "", lambda r, k: "%d B" % (r["lib"][1] + r["lib"][2]))
    first = results[p[0]]
    row("example flash: text + data (incl. %d recorded ticks)" % first["recorded"], "",
        lambda r, k: "%d B" % (r["elf"][0] + r["elf"][1]))
    row("example RAM: data + bss (excl. stack)", "", lambda r, k: "%d B" % (r["elf"][1] + r["elf"][2]))
    row("`sizeof(icoac_config_t)`", "", lambda r, k: "%d B" % r["config"])
    row("`sizeof(icoac_state_t)`", "", lambda r, k: "%d B" % r["state"])
    row("state + config", "<= 4096 B", lambda r, k: "%d B %s" % (r["config"] + r["state"],
        "ok" if r["config"] + r["state"] <= 4096 else "**over**"))
    stack_goal = "; ".join("%s <= %d B" % ({"cortex-m4f": "M4F", "cortex-m0plus": "M0+"}[k], BUDGETS[k]) for k in p)

    def stack_row(name, fn):
        row(name, stack_goal, lambda r, k: "%d B %s" % (fn(r), "ok" if fn(r) <= BUDGETS[k] else "**over**"))

    stack_row("peak stack of a tick, ICO (painted)", lambda r: r["ico"][1])
    stack_row("peak stack of a tick, RL (painted)", lambda r: r["rl"][1])
    stack_row("peak stack of a tick, RL literal reading (painted)", lambda r: r["rl_literal"][1])
    stack_row("peak stack of a tick, RL batch (`actor.batch = 1`, posterior; painted)", lambda r: r["rl_batch"][1])
    stack_row("peak stack of a search tick (painted; update ticks excluded)", lambda r: r["search"]["stack"])
    stack_row("peak stack of a search update tick (painted)", lambda r: r["search"]["stack_update"])
    stack_row("static stack bound, every public function (`stack_bound.py`)", lambda r: max(r["static"].values()))
    row("`icoac_step` own frame (`-fstack-usage`)", "",
        lambda r, k: "%d B" % r["frame"])
    row("instructions per ICO tick (mean of 400)", "", lambda r, k: "%.0f" % r["ico"][0])
    row("instructions per RL tick (mean of 400)", "M4F <= 3,000; M0+ <= 100,000",
        lambda r, k: "%.0f %s" % (r["rl"][0], "ok" if r["rl"][0] <= GOALS[k] else "**over goal**"))
    row("instructions per RL tick, literal reading (posterior actor; mean of 400)", "M4F <= 3,000; M0+ <= 100,000",
        lambda r, k: "%.0f %s" % (r["rl_literal"][0], "ok" if r["rl_literal"][0] <= GOALS[k] else "**over goal**"))
    row("instructions per RL tick, batch (`actor.batch = 1`, posterior; mean of 400)", "",
        lambda r, k: "%.0f" % r["rl_batch"][0])
    sr = first["search"]
    row("instructions per search tick (mean of the %d that do not close a batch)"
        % (sr["ticks"] - sr["updates"]), "", lambda r, k: "%.0f" % r["search"]["tick"])
    row("instructions per search update (terminal tick closing a batch of %d trials; mean of %d x %d runs)"
        % (BATCH, sr["updates"], sr["phases"]), "",
        lambda r, k: "%.0f +- %.0f" % (r["search"]["update"], 2 * r["insn_per_count"] / r["search"]["phases"]))
    row("instructions per search trial start (`icoac_reset`: the draw of w; mean of %d)" % sr["resets"], "",
        lambda r, k: "%.0f" % r["search"]["reset"])
    row("slowest ICO tick (instructions, approx.)", "",
        lambda r, k: "%.0f +- %.0f" % (r["ico"][2], 2 * r["insn_per_count"]))
    row("slowest RL tick (instructions, approx.)", "",
        lambda r, k: "%.0f +- %.0f" % (r["rl"][2], 2 * r["insn_per_count"]))
    return "\n".join("| " + " | ".join(r) + " |" for r in rows) + "\n"


def stack_table(results):
    """Static bound vs painted peak per public function and core."""
    p = list(results)
    rows = [("public function",) + tuple("%s static / painted" % k for k in p), ("---",) * (len(p) + 1)]
    for fn in STACK_FUNCTIONS:
        cells = []
        for k in p:
            r = results[k]
            painted = r["painted"].get(fn)
            if fn == "icoac_step":
                painted = max(v for name, v in r["painted"].items() if not name.startswith("icoac_"))
            cells.append("%d B / %s" % (r["static"][fn], "%d B" % painted if painted is not None else "-"))
        rows.append(("`%s`" % fn,) + tuple(cells))
    rows.append(("every public function (largest)",) + tuple(
        "%d B (`%s`)" % max((b, fn) for fn, b in results[k]["static"].items()) for k in p))
    rows.append(("budget (table above)",) + tuple("%d B" % BUDGETS[k] for k in p))
    return "\n".join("| " + " | ".join(r) + " |" for r in rows) + "\n"


def replace_between(doc, begin, end, text):
    a, b = doc.index(begin) + len(begin), doc.index(end)
    return doc[:a] + "\n" + text + doc[b:]


def main(argv):
    results = {p: measure(p) for p in PRESETS}
    text, stack = table(results), stack_table(results)
    if len(argv) > 2 and argv[1] == "--update":
        path = argv[2]
        doc = replace_between(open(path).read(), BEGIN, END, text)
        open(path, "w").write(replace_between(doc, STACK_BEGIN, STACK_END, stack))
        print("updated", path)
    print(text)
    print(stack)


if __name__ == "__main__":
    main(sys.argv)
