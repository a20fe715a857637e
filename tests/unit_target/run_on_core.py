#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The firmware unit tests on a Cortex-M core, run by ctest (tests/target/CMakeLists.txt).

  build <preset> <dir> <unity-src>   configure <dir> from a cross preset with ICOAC_BUILD_TARGET_TESTS
                                     (this directory) and Unity's sources, build the tests' ELFs
  run   <preset> <elf> <timeout>     run one test under QEMU, print Unity's lines with each test's wall
                                     time; passes on exit 0, a summary of 0 failures, 0 ignored and OK,
                                     no FAIL line, within timeout (s)
"""
import os
import re
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "target"))
from target_check import BOARDS, ROOT, qemu_command  # noqa: E402  (the boards and QEMU's options)


def cmd_build(preset, directory, unity_src):
    subprocess.run(["cmake", "--preset", preset, "-B", directory, "-DICOAC_BUILD_TARGET_TESTS=ON",
                    "-DFETCHCONTENT_SOURCE_DIR_UNITY=" + unity_src],
                   cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", directory, "--target", "icoac_unit_target_tests"], check=True)


# Unity's closing lines: "<n> Tests <f> Failures <i> Ignored", then OK or FAIL.
UNITY_SUMMARY = re.compile(r"^(\d+) Tests (\d+) Failures (\d+) Ignored *\n(OK|FAIL)$", re.M)
# A test's result line: "<file>:<line>:<test>:PASS" (or FAIL, IGNORE, with a message).
UNITY_RESULT = re.compile(r":(PASS|FAIL|IGNORE)\b")


def cmd_run(preset, kernel, timeout):
    start = time.monotonic()
    proc = subprocess.Popen(qemu_command(preset, kernel), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)  # semihosting output is on stderr
    lines = []

    def read():  # each line with the seconds since the previous test's result line
        last = start
        for line in proc.stdout:
            now = time.monotonic()
            lines.append((line.rstrip("\n"), now - last))
            if UNITY_RESULT.search(line):
                last = now

    reader = threading.Thread(target=read)
    reader.start()
    try:
        returncode = proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        returncode = None
    reader.join()
    for line, seconds in lines:
        print("%s  [%.2f s]" % (line, seconds) if UNITY_RESULT.search(line) else line)
    out = "".join(line + "\n" for line, _ in lines)
    if returncode is None:
        sys.exit("FAILED: timeout, no exit within %g s on %s" % (timeout, BOARDS[preset]))
    print("%s on %s: %.2f s wall, exit %d" % (os.path.basename(kernel), BOARDS[preset],
                                             time.monotonic() - start, returncode))
    summary = UNITY_SUMMARY.findall(out)
    problems = []
    if returncode != 0:
        problems.append("exit status %d" % returncode)
    if any(":FAIL" in line for line, _ in lines):
        problems.append("a test failed")
    if not summary:
        problems.append("no Unity summary line")
    elif summary[-1][1] != "0" or summary[-1][3] != "OK":
        problems.append("the summary counts failures")
    elif summary[-1][2] != "0":  # a skip is no pass: leave such a test out of the core's build
        problems.append("ignored tests")
    if problems:
        sys.exit("FAILED: " + ", ".join(problems))


def main(argv):
    cmd = argv[1] if len(argv) > 1 else ""
    if cmd == "build" and len(argv) == 5:
        cmd_build(argv[2], argv[3], argv[4])
    elif cmd == "run" and len(argv) == 5:
        cmd_run(argv[2], argv[3], float(argv[4]))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
