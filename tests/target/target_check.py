#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Checks of the microcontroller target, run by ctest (tests/target/CMakeLists.txt).

  build   <preset>                         configure + build a cross preset (cmake --preset)
  run     <preset> <out>                   run the example under QEMU (-icount shift=0), save output
  nm      <preset>                         no heap allocator in the library or the example
  compare <host-exe|out> <target-out>      ICO bit-exact, RL and search within tolerance of the host build
  stack   <target-out> <preset> <doc>      painted peak stack of the tick loops (the search update and the
                                           other public calls too) within the preset's budget in doc
"""
import os
import re
import struct
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "firmware", "port"))
import stack_bound  # noqa: E402  (the budget's one description: docs/porting.md)
BOARDS = {"cortex-m4f": "mps2-an386", "cortex-m0plus": "microbit"}
FORBIDDEN = ("malloc", "free", "calloc", "realloc", "_sbrk", "_malloc_r", "_free_r",
             "_calloc_r", "_realloc_r", "sbrk")
# RL outputs may differ from the host: newlib's logf/cosf/sqrtf/expf vs glibc's can differ by
# one ulp, and the learning loop carries the difference forward. Bound: |d| <= ATOL + RTOL*|host|.
# The same bound holds for search (its trial draws of w go through logf, the updates carry a
# difference forward); every other section (ICO) must be bit-exact.
RL_RTOL = 1e-3
RL_ATOL = 1e-5
TOLERANT_SECTIONS = ("rl", "rl_batch", "search")


def build_dir(preset):
    return os.path.join(ROOT, "build", preset)


def elf(preset):
    return os.path.join(build_dir(preset), "firmware", "port", "icoac_port_example.elf")


def lib(preset):
    return os.path.join(build_dir(preset), "firmware", "libicoac.a")


def cmd_build(preset):
    subprocess.run(["cmake", "--preset", preset], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", "--preset", preset], cwd=ROOT, check=True)


def qemu_command(preset, kernel, options=()):
    return ["qemu-system-arm", "-M", BOARDS[preset], "-nographic", "-monitor", "none", "-serial", "none",
            "-semihosting-config", "enable=on,target=native", *options, "-kernel", kernel]


def run_qemu(preset):
    r = subprocess.run(qemu_command(preset, elf(preset), ("-icount", "shift=0")),
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=120, text=True)
    out = r.stdout + r.stderr  # QEMU writes semihosting SYS_WRITE0 output to stderr
    if r.returncode != 0 or "END" not in out.splitlines():
        sys.exit("qemu run failed (rc=%d):\n%s" % (r.returncode, out[-2000:]))
    return out


def cmd_run(preset, out_path):
    out = run_qemu(preset)
    with open(out_path, "w") as f:
        f.write(out)
    print("".join(l + "\n" for l in out.splitlines() if l[:1] in "BZCM"))


def cmd_nm(preset):
    bad = []
    for path in (lib(preset), elf(preset)):
        syms = subprocess.run(["arm-none-eabi-nm", path], check=True, stdout=subprocess.PIPE,
                              text=True).stdout
        for line in syms.splitlines():
            name = line.split()[-1] if line.split() else ""
            if name in FORBIDDEN:
                bad.append("%s: %s" % (os.path.basename(path), line.strip()))
    if bad:
        sys.exit("heap allocator symbols found:\n" + "\n".join(bad))
    print("no heap allocator symbols in libicoac.a and icoac_port_example.elf")


def parse_ticks(text):
    """{(section, key): [float bits...]} for T and P lines, in order."""
    rows, section = [], None
    for line in text.splitlines():
        f = line.split()
        if not f:
            continue
        if f[0] == "S":
            section = f[1]
        elif f[0] in ("T", "P"):
            vals = [tok for tok in f if ":" in tok]
            head = f[:3] if f[0] == "T" else ["P"]
            bits = [int(v.split(":")[0], 16) for v in vals]
            rows.append((section, " ".join(head), bits))
    return rows


def as_float(bits):
    return struct.unpack("<f", struct.pack("<I", bits))[0]


def cmd_compare(host_path, target_path):
    if os.access(host_path, os.X_OK):  # the host reference executable: run it
        host_text = subprocess.run([host_path], check=True, stdout=subprocess.PIPE, text=True).stdout
    else:
        host_text = open(host_path).read()
    host = parse_ticks(host_text)
    target = parse_ticks(open(target_path).read())
    if len(host) != len(target) or len(host) == 0:
        sys.exit("row count differs: host %d, target %d" % (len(host), len(target)))
    stats = {}
    fail = []
    for (sh, kh, bh), (st, kt, bt) in zip(host, target):
        if (sh, kh) != (st, kt) or len(bh) != len(bt):
            fail.append("row mismatch: %s %s vs %s %s" % (sh, kh, st, kt))
            continue
        s = stats.setdefault(sh, {"rows": 0, "exact_rows": 0, "max_abs": 0.0, "max_rel": 0.0})
        s["rows"] += 1
        s["exact_rows"] += bh == bt
        for a, b in zip(bh, bt):
            if a == b:
                continue
            fa, fb = as_float(a), as_float(b)
            d = abs(fa - fb)
            s["max_abs"] = max(s["max_abs"], d)
            if fa != 0.0:
                s["max_rel"] = max(s["max_rel"], d / abs(fa))
            if sh not in TOLERANT_SECTIONS:
                fail.append("%s not bit-exact: %s %08x vs %08x" % (sh, kh, a, b))
            elif not d <= RL_ATOL + RL_RTOL * abs(fa):
                fail.append("%s out of tolerance: %s host %r target %r" % (sh, kh, fa, fb))
    for sec, s in sorted(stats.items()):
        print("%s: %d rows, %d bit-exact, max |diff| %.3g, max rel %.3g"
              % (sec, s["rows"], s["exact_rows"], s["max_abs"], s["max_rel"]))
    if fail:
        sys.exit("\n".join(fail[:20]))


def measurements(text):
    """{mode: {key: int}} from the target's "M <mode> key=value ..." lines."""
    return {m.group(1): {k: int(v) for k, v in (kv.split("=") for kv in m.group(2).split())}
            for m in re.finditer(r"^M (\w+) (.*)$", text, re.M)}


def painted_peaks(meas):
    """[(what, bytes)] of the painted measurements: the tick loops, then the other calls."""
    peaks = [("ICO", meas.get("ico", {}).get("stack")), ("RL", meas.get("rl", {}).get("stack")),
             ("RL literal", meas.get("rl_literal", {}).get("stack")),
             ("RL batch", meas.get("rl_batch", {}).get("stack")),
             ("search", meas.get("search", {}).get("stack")),
             ("search update", meas.get("search", {}).get("stack_update"))]
    calls = meas.get("calls", {})
    return peaks + [(k, calls.get(k)) for k in ("icoac_config_check", "icoac_init", "icoac_reset", "icoac_retune",
                                                "icoac_get_posterior")]


def cmd_stack(target_path, preset, doc):
    budget = stack_bound.read_budget(doc, preset)
    peaks = painted_peaks(measurements(open(target_path).read()))
    if any(v is None for _, v in peaks):
        sys.exit("stack measurements missing in " + target_path)
    print("painted peak stack: %s (budget %d B, %s)" % (", ".join("%s %d B" % p for p in peaks), budget, doc))
    if max(v for _, v in peaks) > budget:
        sys.exit("stack budget exceeded")


def main(argv):
    cmd = argv[1] if len(argv) > 1 else ""
    if cmd == "build":
        cmd_build(argv[2])
    elif cmd == "run":
        cmd_run(argv[2], argv[3])
    elif cmd == "nm":
        cmd_nm(argv[2])
    elif cmd == "compare":
        cmd_compare(argv[2], argv[3])
    elif cmd == "stack":
        cmd_stack(argv[2], argv[3], argv[4])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
