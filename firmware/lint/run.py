#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Static analysis of the controller library (firmware/src, firmware/include): `make lint`.

Three tools, each over every build variant of the library (float, double, ICOAC_FAST_EXP; sparse
and dense critic kernel):
  gcc -fanalyzer   at -O0 and -O2, clean: any analyzer warning fails;
  clang-tidy       with firmware/.clang-tidy, clean: any finding fails;
  cppcheck         with its MISRA C:2012 addon: an error or warning of cppcheck's own fails, and
                   each MISRA rule's count must stay within the ceiling of the record in
                   docs/misra.md, a ceiling above 0 must name a written deviation there, and a
                   rule not in the record fails.
A finding seen in several variants counts once (file, line, column, rule). Prints a table per tool;
exit status 1 when a tool fails. Python 3 standard library only.
"""
import argparse
import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
import time
from collections import Counter

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MISRA_RECORD = os.path.join(ROOT, "docs", "misra.md")
# The generated headers (icoac_version.h; icoac_build_config.h, which sets the build maxima to
# CMake's defaults) come from a configure of the library alone: see generated_include().
GENERATED = os.path.join("build", "lint", "library")
INCLUDES = ["-Ifirmware/include", "-Ifirmware/src",
            "-I" + os.path.join(GENERATED, "firmware", "generated", "include")]
VARIANTS = {
    "float-sparse": ["-DICOAC_REAL_DOUBLE=0", "-DICOAC_CRITIC_DENSE=0"],
    "float-dense": ["-DICOAC_REAL_DOUBLE=0", "-DICOAC_CRITIC_DENSE=1"],
    "double-sparse": ["-DICOAC_REAL_DOUBLE=1", "-DICOAC_CRITIC_DENSE=0"],
    "double-dense": ["-DICOAC_REAL_DOUBLE=1", "-DICOAC_CRITIC_DENSE=1"],
    "fast_exp-sparse": ["-DICOAC_REAL_DOUBLE=0", "-DICOAC_CRITIC_DENSE=0", "-DICOAC_FAST_EXP=1"],
    "fast_exp-dense": ["-DICOAC_REAL_DOUBLE=0", "-DICOAC_CRITIC_DENSE=1", "-DICOAC_FAST_EXP=1"],
}
ANALYZER_LEVELS = ["-O0", "-O2"]
# file:line:col: warning|error: message [check]
DIAGNOSTIC = re.compile(r"^(?P<file>[^:\s]+):(?P<line>\d+):(?P<col>\d+): (?P<severity>warning|error): "
                        r"(?P<message>.*?)(?: \[(?P<check>[^\]]+)\])?$")
CPPCHECK_TEMPLATE = "{file}:{line}:{column}:{severity}:{id}:{message}"
# A deviation's paragraph starts "**D<n>, rule(s) ...": the record's resolutions name them.
DEVIATION = re.compile(r"^\*\*(D\d+),")
MISRA_ROW = re.compile(r"^\|\s*(?P<rule>\d+\.\d+)\s*\|\s*(?P<category>Mandatory|Required|Advisory)\s*\|"
                       r"\s*(?P<before>\d+)\s*\|\s*(?P<ceiling>\d+)\s*\|(?P<resolution>.*)\|\s*$")


def sources():
    src = os.path.join(ROOT, "firmware", "src")
    return sorted(os.path.join("firmware", "src", f) for f in os.listdir(src) if f.endswith(".c"))


def generated_include():
    """Configure the library alone (no host parts, no install rules) into GENERATED, which writes
    the headers the sources include; True when CMake succeeded."""
    status, output = run(["cmake", "-S", ".", "-B", GENERATED, "-DICOAC_BUILD_HOST=OFF", "-DICOAC_INSTALL=OFF"])
    if status != 0:
        print("cmake configure of the library failed:\n" + output)
    return status == 0


def run(cmd):
    """(exit status, stdout + stderr) of cmd, run from the repository root."""
    proc = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, check=False)
    return proc.returncode, proc.stdout


def relative(path):
    return os.path.relpath(os.path.join(ROOT, path), ROOT)


def parse_diagnostics(output):
    """{(file, line, col, check): message} of compiler-style diagnostics."""
    found = {}
    for line in output.splitlines():
        m = DIAGNOSTIC.match(line)
        if m:
            check = m.group("check") or m.group("severity")
            found[(relative(m.group("file")), int(m.group("line")), int(m.group("col")), check)] = m.group("message")
    return found


def map_jobs(jobs, commands):
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(run, commands))


def run_diagnostics(jobs, commands):
    """({location: diagnostic}, failed runs) of compiler-style tools: a run that fails without a
    diagnostic (a crash, a missing header) is a failed run."""
    found = {}
    failed = []
    for cmd, (status, output) in zip(commands, map_jobs(jobs, commands)):
        diagnostics = parse_diagnostics(output)
        found.update(diagnostics)
        if status != 0 and not diagnostics:
            failed.append(" ".join(cmd) + "\n" + output)
    return found, failed


def gcc_analyzer(jobs):
    return run_diagnostics(jobs, [["gcc", "-std=c99", level, "-fanalyzer", "-Werror", *INCLUDES, *defines,
                                   "-c", src, "-o", os.devnull]
                                  for defines in VARIANTS.values() for level in ANALYZER_LEVELS
                                  for src in sources()])


def clang_tidy(jobs):
    return run_diagnostics(jobs, [["clang-tidy", "--quiet", "--header-filter=firmware/", src, "--",
                                   "-std=c99", *INCLUDES, *defines]
                                  for defines in VARIANTS.values() for src in sources()])


def cppcheck(jobs):
    """({(file, line, col, id): (severity, message)}, failed runs) over every variant. Each variant
    has its own build directory (emptied first), where cppcheck and the addon write their dump and
    whole-program files: next to the sources, variants run at once would overwrite each other's."""
    build = os.path.join(ROOT, "build", "lint")
    for name in VARIANTS:
        shutil.rmtree(os.path.join(build, name), ignore_errors=True)
        os.makedirs(os.path.join(build, name))
    commands = [["cppcheck", "--cppcheck-build-dir=" + os.path.join(build, name), "--addon=misra", "--std=c99", "--enable=warning,portability", "--inline-suppr",
                 "--error-exitcode=0", "--quiet", "--template=" + CPPCHECK_TEMPLATE, *INCLUDES,
                 *defines, *sources()]
                for name, defines in VARIANTS.items()]
    found = {}
    failed = []
    for cmd, (status, output) in zip(commands, map_jobs(jobs, commands)):
        for line in output.splitlines():
            parts = line.split(":", 5)
            if len(parts) == 6 and parts[1].isdigit():
                found[(relative(parts[0]), int(parts[1]), int(parts[2]), parts[4])] = (parts[3], parts[5])
        if status != 0:
            failed.append(" ".join(cmd) + "\n" + output)
    return found, failed


def read_misra_record(path=MISRA_RECORD):
    """({rule: (category, before, ceiling, resolution)}, {deviation ids}) from docs/misra.md."""
    record = {}
    deviations = set()
    if not os.path.exists(path):
        return record, deviations
    with open(path, encoding="utf-8") as f:
        for line in f:
            m = MISRA_ROW.match(line.strip())
            if m:
                record[m.group("rule")] = (m.group("category"), int(m.group("before")), int(m.group("ceiling")),
                                           m.group("resolution").strip())
            m = DEVIATION.match(line)
            if m:
                deviations.add(m.group(1))
    return record, deviations


def rule_key(rule):
    return tuple(int(x) for x in rule.split("."))


def table(rows, header):
    widths = [max(len(str(r[i])) for r in rows + [header]) for i in range(len(header))]
    line = lambda r: "  ".join(str(c).rjust(w) if isinstance(c, int) else str(c).ljust(w) for c, w in zip(r, widths))
    return "\n".join([line(header), line(["-" * w for w in widths])] + [line(r) for r in rows])


def report_findings(title, found, failed, show=20):
    """Prints a tool's table (findings per check) and its findings; True when clean."""
    counts = Counter(key[3] for key in found)
    print(f"== {title}: {len(found)} finding(s)")
    if counts:
        print(table(sorted(([c, n] for c, n in counts.items()), key=lambda r: -r[1]), ["check", "count"]))
        for (path, line, col, check), message in sorted(found.items())[:show]:
            print(f"  {path}:{line}:{col}: [{check}] {message}")
        if len(found) > show:
            print(f"  ... and {len(found) - show} more")
    for run_output in failed:
        print("run failed:\n" + run_output)
    print()
    return not found and not failed


def misra_check(found, failed, record, deviations, show_rules):
    """Prints cppcheck's own findings and the MISRA table against the record; True when it passes."""
    own = {k: v for k, v in found.items() if not k[3].startswith("misra-")}
    misra = Counter(k[3][len("misra-c2012-"):] for k in found if k[3].startswith("misra-"))
    ok = report_findings("cppcheck (own checks: error, warning, portability)", {k: v[1] for k, v in own.items()},
                         failed)
    rows = []
    problems = []
    for rule in sorted(set(misra) | set(record), key=rule_key):
        count = misra.get(rule, 0)
        if rule not in record:
            rows.append([rule, "?", "-", "-", count, "NEW RULE: not in docs/misra.md"])
            problems.append(rule)
            continue
        category, before, ceiling, resolution = record[rule]
        named = re.findall(r"deviation (D\d+)", resolution)
        verdict = "ok"
        if ceiling > 0 and (not named or not set(named) <= deviations):
            verdict = "FAIL: findings allowed without a written deviation"
            problems.append(rule)
        elif count > ceiling:
            verdict = f"FAIL: {count - ceiling} over the ceiling"
            problems.append(rule)
        elif category == "Mandatory" and count:
            verdict = "FAIL: Mandatory rule"
            problems.append(rule)
        elif count < ceiling:
            verdict = f"below the ceiling: lower it to {count}"
        rows.append([rule, category, before, ceiling, count, verdict])
    by_category = Counter()
    for rule, count in misra.items():
        by_category[record.get(rule, ("unrecorded",))[0]] += count
    print(f"== cppcheck MISRA C:2012: {sum(misra.values())} finding(s) over {len(misra)} rule(s) "
          f"({', '.join(f'{c} {n}' for c, n in sorted(by_category.items()))}); record: docs/misra.md")
    print(table(rows, ["rule", "category", "before", "ceiling", "now", "verdict"]))
    listed = [(rule_key(rule_id[len("misra-c2012-"):]), path, line, col) for path, line, col, rule_id in found
              if rule_id.startswith("misra-c2012-")
              and (rule_id[len("misra-c2012-"):] in show_rules or "all" in show_rules)]
    for key, path, line, col in sorted(listed):
        print(f"  {path}:{line}:{col}: [{'.'.join(map(str, key))}]")
    print()
    return ok and not problems


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--jobs", type=int, default=2, help="tool runs at once (default 2)")
    parser.add_argument("--tools", default="gcc,clang-tidy,cppcheck", help="comma-separated subset to run")
    parser.add_argument("--show-misra", default="", help="comma-separated rules whose findings to list, or all")
    args = parser.parse_args()
    tools = args.tools.split(",")
    start = time.monotonic()
    ok = True
    print(f"variants: {', '.join(VARIANTS)}; sources: {len(sources())} files of firmware/src\n")
    if not generated_include():
        return 1
    if "gcc" in tools:
        ok &= report_findings(f"gcc -fanalyzer ({' and '.join(ANALYZER_LEVELS)})", *gcc_analyzer(args.jobs))
    if "clang-tidy" in tools:
        ok &= report_findings("clang-tidy (firmware/.clang-tidy)", *clang_tidy(args.jobs))
    if "cppcheck" in tools:
        found, failed = cppcheck(args.jobs)
        record, deviations = read_misra_record()
        ok &= misra_check(found, failed, record, deviations, [r for r in args.show_misra.split(",") if r])
    print(f"lint {'passed' if ok else 'FAILED'} in {time.monotonic() - start:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
