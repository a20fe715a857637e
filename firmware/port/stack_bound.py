#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Static worst-case stack depth of every public function of the icoac library.

The bound of a function is its own frame plus the largest bound of its callees, over GCC's call
graph of the built library: frames from `-fstack-usage` (.su), calls from `-fcallgraph-info=su`
(.ci, VCG). A static call graph covers every mode, reading, batch and error path. The script
fails on a cycle (recursion), an indirect call, a frame that is not "static" (the host accepts
"dynamic,bounded", a reliable maximum in GCC's words: x86-64 pushes a call's stack arguments),
and a callee outside the library whose frame it cannot bound.

Tail calls (Cortex-M): a callee that the disassembly of the link below reaches only by a branch
to its entry (GCC's sibling call, after the caller's epilogue) adds its bound in place of the
caller's frame. Every call of the disassembly must be in the .ci.

Callees outside the library (libm, libc, libgcc):
- Cortex-M presets: the library is linked whole (--whole-archive, the preset's flags,
  newlib-nano as the port example) and every such callee is read from the disassembly
  (arm-none-eabi-objdump -d): its frame is the sum of every stack-pointer decrement in its body
  (push, vpush, stmdb/vstmdb sp!, pre-indexed stores to sp, sub sp), its callees are its bl/blx
  targets, the functions its branches leave to (tail calls) and the next function when it falls
  through. Assumed: no loop in these runtime routines decrements sp; any other write of sp or an
  indirect branch fails the analysis.
- Host (x86-64, glibc): the C library's routines are not in the build. Each call into glibc
  (expf, logf, sqrtf, their double versions, memcpy, memmove, memset, memcmp) counts HOST_RUNTIME_FRAME
  bytes, an assumption (these are leaf routines: a return address and a few saved registers),
  not a measurement.

  stack_bound.py <config> [--build DIR] [--check DOC] [--json]
    config  cortex-m4f | cortex-m0plus (build/<config>, the cross preset)
            host | host-double (the host build's float / double library, build/release)
    --check DOC  fail when a bound exceeds the budget of <config> stated in DOC
                 (docs/porting.md, the table between the stack-budget markers)
"""
import argparse
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
HEADERS = os.path.join(ROOT, "firmware", "include", "icoac")
CONFIGS = {
    "cortex-m4f": ("build/cortex-m4f", "icoac"),
    "cortex-m0plus": ("build/cortex-m0plus", "icoac"),
    "host": ("build/release", "icoac"),
    "host-double": ("build/release", "icoac_double"),
}
HOST_RUNTIME = ("expf", "logf", "sqrtf", "exp", "log", "sqrt", "memcpy", "memmove", "memset", "memcmp")
HOST_RUNTIME_FRAME = 128  # bytes assumed per glibc routine (not measured)
BUDGET_BEGIN, BUDGET_END = "<!-- stack-budget:begin -->", "<!-- stack-budget:end -->"
BUDGET_COLUMNS = {"cortex-m4f": "cortex-m4f", "cortex-m0plus": "cortex-m0plus", "host": "host",
                  "host-double": "host"}


# Public functions built only with a CMake option (firmware/CMakeLists.txt): not in the call
# graph of a build that turned the option off, and required in any other.
OPTIONAL_FUNCTIONS = {"icoac_batch_init": "ICOAC_BATCH", "icoac_step_batch": "ICOAC_BATCH"}


class AnalysisError(Exception):
    pass


def public_functions(header_dir=HEADERS):
    """Names of the functions the public headers declare."""
    names = []
    for fname in sorted(os.listdir(header_dir)):
        if not fname.endswith(".h"):
            continue
        text = open(os.path.join(header_dir, fname)).read()
        text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
        text = re.sub(r"//[^\n]*", " ", text)
        text = re.sub(r"^\s*#(?:[^\n]*\\\n)*[^\n]*", " ", text, flags=re.M)
        for decl in text.split(";"):
            decl = " ".join(decl.split())
            if decl.startswith("typedef") or "{" in decl:
                continue
            m = re.search(r"\b(icoac_\w+)\s*\([^()]*\)$", decl)
            if m:
                names.append(m.group(1))
    return names


# --- the library's call graph (.su, .ci) -------------------------------------------------------

def read_callgraph(obj_dir):
    """({node: (frame bytes, qualifier, name)}, {node: [callee node, ...]}) of every function
    compiled in obj_dir. A node is the .ci title: "name" for an external symbol, "file:name"
    for a static one."""
    frames, edges, su = {}, {}, {}
    ci_files = []
    for d, _, files in os.walk(obj_dir):
        for f in files:
            path = os.path.join(d, f)
            if f.endswith(".su"):
                for line in open(path):
                    loc_name, size, qual = line.rstrip("\n").split("\t")
                    su[loc_name] = (int(size), qual)
            elif f.endswith(".ci"):
                ci_files.append(path)
    if not ci_files:
        raise AnalysisError("no -fcallgraph-info output (.ci) under %s: build the library first" % obj_dir)
    node_re = re.compile(r'^node: \{ title: "([^"]*)" label: "([^"]*)"')
    edge_re = re.compile(r'^edge: \{ sourcename: "([^"]*)" targetname: "([^"]*)"')
    for path in sorted(ci_files):
        for line in open(path):
            m = node_re.match(line)
            if m:
                title, label = m.group(1), m.group(2).split("\\n")
                if len(label) >= 3:  # a definition: name, location, frame
                    fm = re.match(r"^(\d+) bytes \(([\w,]+)\)$", label[2])
                    if not fm:
                        raise AnalysisError("unreadable frame of %s: %s" % (title, label[2]))
                    key = "%s:%s" % (label[1], label[0])
                    if su.get(key) != (int(fm.group(1)), fm.group(2)):
                        raise AnalysisError("%s: .ci frame %s, .su %s" % (key, label[2], su.get(key)))
                    if title in frames:
                        raise AnalysisError("%s defined twice" % title)
                    frames[title] = (int(fm.group(1)), fm.group(2), label[0])
                    edges.setdefault(title, [])
                continue
            m = edge_re.match(line)
            if m:
                edges.setdefault(m.group(1), []).append(m.group(2))
    return frames, multiversioned(frames, edges)


def multiversioned(frames, edges):
    """edges with a call to a function GCC compiled for several targets (target_clones: the
    clones "f.default", "f.avx2"..., reached through the ifunc "f") replaced by calls to each of
    its clones; its resolver's calls dropped (the loader runs it, before any call of the API)."""
    clones = {}
    for node in frames:
        base, dot, suffix = node.rpartition(".")
        if dot and base not in frames and suffix != "resolver" and base + ".resolver" in frames:
            clones.setdefault(base, []).append(node)
    resolvers = {base + ".resolver" for base in clones}
    return {caller: [] if caller in resolvers else [c for callee in callees for c in clones.get(callee, [callee])]
            for caller, callees in edges.items()}


# --- runtime routines from a Cortex-M disassembly ----------------------------------------------

def reg_count(reglist):
    """Registers of "{r4, r5, lr}" or "{s16-s21}" / "{d8-d9}", and the bytes of each."""
    count, width = 0, 4
    for item in reglist.strip("{} ").split(","):
        item = item.strip()
        m = re.match(r"^([sdr])(\d+)-[sdr](\d+)$", item)
        if m:
            count += int(m.group(3)) - int(m.group(2)) + 1
            width = 8 if m.group(1) == "d" else 4
        elif item:
            count += 1
            width = 8 if item.startswith("d") else 4
    return count * width


def disassemble(objdump, elf):
    """({address: (name, [(address, mnemonic, operands)])} of every function of elf,
    {address: value} of the literal pools' words)."""
    out = subprocess.run([objdump, "-d", "--no-show-raw-insn", elf], check=True,
                         stdout=subprocess.PIPE, text=True).stdout
    funcs, words, current = {}, {}, None
    for line in out.splitlines():
        m = re.match(r"^([0-9a-f]+) <(.+)>:$", line)
        if m:
            current = int(m.group(1), 16)
            funcs[current] = (m.group(2), [])
            continue
        m = re.match(r"^\s+([0-9a-f]+):\s+(\S+)\s*(.*)$", line)
        if m and current is not None:
            mnem, ops = m.group(2), m.group(3).split(";")[0].strip()
            if mnem == ".word":
                words[int(m.group(1), 16)] = int(ops.split()[0], 16)
            elif not mnem.startswith("."):
                funcs[current][1].append((int(m.group(1), 16), mnem, ops))
    return funcs, words


def read_words(objdump, elf, addr, count):
    """count little-endian words of elf's image at addr."""
    out = subprocess.run([objdump, "-s", "--start-address=%d" % addr, "--stop-address=%d" % (addr + 4 * count),
                          elf], check=True, stdout=subprocess.PIPE, text=True).stdout
    data = b""
    for line in out.splitlines():
        m = re.match(r"^ ([0-9a-f]+) ((?:[0-9a-f]{1,8} ){1,4})", line + " ")
        if m:
            data += bytes.fromhex("".join(m.group(2).split()))
    if len(data) < 4 * count:
        raise AnalysisError("cannot read %d words at %#x" % (count, addr))
    return [int.from_bytes(data[4 * i:4 * i + 4], "little") for i in range(count)]


def jump_table(insns, i, words, table_reader):
    """Targets of the Thumb-1 switch `cmp rI, #K; ...; ldr rB, [pc, ...]; lsls rI, rI, #2;
    ldr rX, [rB, rI]; mov pc, rX` ending at insns[i], or None when it is not one."""
    x = insns[i][2].split(",")[1].strip()
    if i < 3:
        return None
    load, shift, base = insns[i - 1], insns[i - 2], insns[i - 3]
    m = re.match(r"^%s, \[(r\d+), (r\d+)\]$" % x, load[2]) if load[1] == "ldr" else None
    if not m or not re.match(r"^%s, %s, #2$" % (m.group(2), m.group(2)), shift[2]):
        return None
    lit = re.match(r"^%s, \[pc, #\d+\]\s*@ \(([0-9a-f]+)" % m.group(1), base[2]) if base[1] == "ldr" else None
    if not lit or int(lit.group(1), 16) not in words:
        return None
    for _, mnem, ops in reversed(insns[max(0, i - 12):i - 3]):
        k = re.match(r"^%s, #(\d+)$" % m.group(2), ops)
        if mnem == "cmp" and k:
            return table_reader(words[int(lit.group(1), 16)], int(k.group(1)) + 1)
    return None


def symbol_addresses(nm, elf):
    """{symbol: address} of every defined text symbol, aliases included."""
    out = subprocess.run([nm, "--defined-only", elf], check=True, stdout=subprocess.PIPE, text=True).stdout
    syms = {}
    for line in out.splitlines():
        f = line.split()
        if len(f) == 3 and f[1] in "TtWw":
            syms[f[2]] = int(f[0], 16) & ~1
    return syms


def runtime_graph(funcs, words, table_reader):
    """{address: (name, own frame bytes, [callee address, ...], problems, tails)} from the
    disassembly; tails: the callees that a branch reaches at their entry (GCC's sibling calls,
    made after the epilogue), a subset of the callees."""
    starts = sorted(funcs)
    graph = {}
    for idx, addr in enumerate(starts):
        name, insns = funcs[addr]
        # one past the routine: the next one's start, or past the last instruction of the last one
        end = starts[idx + 1] if idx + 1 < len(starts) else (insns[-1][0] + 4 if insns else addr)
        frame, callees, problems, tails = 0, set(), [], set()

        def owner(target):
            pos = [s for s in starts if s <= target]
            return pos[-1] if pos else None

        for i, (_, mnem, ops) in enumerate(insns):
            ops = ops.split("@")[0].strip() if not (mnem == "ldr" and "[pc" in ops) else ops
            base = re.sub(r"(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le)$", "", mnem) \
                if mnem.startswith(("b", "bx")) and mnem not in ("bl", "blx", "bic", "bics") else mnem
            target = re.match(r"^([0-9a-f]+) <", ops)
            if mnem in ("bl", "blx"):
                if target:
                    t = int(target.group(1), 16)
                    if not (addr <= t and t < end):
                        callees.add(owner(t))
                else:
                    problems.append("indirect call: %s %s" % (mnem, ops))
                continue
            if base in ("b", "b.n", "b.w", "cbz", "cbnz", "bx") or mnem in ("cbz", "cbnz"):
                if target:
                    t = int(target.group(1), 16)
                    if not (addr <= t and t < end):
                        callees.add(owner(t))  # tail call, or a branch into another routine
                        if t in funcs and mnem in ("b", "b.n", "b.w"):
                            tails.add(t)
                elif mnem.startswith("bx") and ops != "lr":
                    problems.append("indirect branch: %s %s" % (mnem, ops))
                continue
            if mnem == "mov" and ops.startswith("pc,"):
                table = jump_table(insns, i, words, table_reader)
                if table is None or any(not (addr <= t & ~1 and t & ~1 < end) for t in table):
                    problems.append("indirect branch: %s %s" % (mnem, ops))
                continue  # a switch inside the routine
            if re.match(r"^ldr(\.w)?$", mnem) and ops.startswith("pc,") and "[sp]" not in ops:
                problems.append("indirect branch: %s %s" % (mnem, ops))
                continue
            operands = [o.strip() for o in ops.split(",")]
            if mnem.startswith(("push", "vpush")):
                frame += reg_count(ops)
            elif re.match(r"^v?stm(db|fd)(\.w)?$", mnem) and operands[0] == "sp!":
                frame += reg_count(ops[ops.index("{"):])
            elif re.search(r"\[sp, #-(\d+)\]!", ops):
                frame += int(re.search(r"\[sp, #-(\d+)\]!", ops).group(1))
            elif mnem.startswith(("tbb", "tbh")):
                problems.append("table branch: %s %s" % (mnem, ops))
            elif operands and operands[0] == "sp" and not mnem.startswith(("cmp", "str")):
                imm = re.match(r"^#(-?\d+)$", operands[-1])
                if re.match(r"^sub(s|w|\.w)?$", mnem) and imm and operands[1:2] in (["sp"], [operands[-1]]):
                    frame += int(imm.group(1))
                elif re.match(r"^add(s|w|\.w)?$", mnem) and imm and operands[1:2] in (["sp"], [operands[-1]]):
                    if int(imm.group(1)) < 0:
                        frame -= int(imm.group(1))
                else:
                    problems.append("unbounded write of sp: %s %s" % (mnem, ops))
        body = [ins for ins in insns if ins[1] != "nop"]  # alignment padding at the end
        if body:
            last_mnem, last_ops = body[-1][1], body[-1][2]
            far_jump = re.match(r"^([0-9a-f]+) <", last_ops)  # Thumb-1: bl inside the function
            ends = (last_mnem in ("b", "b.n", "b.w") or (last_mnem == "bx") or
                    (last_mnem.startswith(("pop", "ldmia", "ldr")) and "pc" in last_ops) or
                    (last_mnem == "bl" and far_jump and addr <= int(far_jump.group(1), 16) < end))
            if not ends and end in funcs:
                callees.add(end)  # falls through into the next routine
        callees.discard(None)
        graph[addr] = (name, frame, sorted(callees), problems, tails)
    return graph


def function_addresses(readelf, elf):
    """{node: address} of every function of elf, by the .ci's node names: "name" for a global,
    "<file>:name" (file: the source's base name) for a static one (the symbols after a FILE
    symbol are its object's)."""
    out = subprocess.run([readelf, "-sW", elf], check=True, stdout=subprocess.PIPE, text=True).stdout
    nodes, source = {}, None
    for line in out.splitlines():
        f = line.split()
        if len(f) < 8 or not f[0].endswith(":"):
            continue
        if f[3] == "FILE":
            source = f[7]
        elif f[3] == "FUNC":
            key = f[7] if f[4] != "LOCAL" else "%s:%s" % (source, f[7])
            nodes[key] = int(f[1], 16) & ~1
    return nodes


def tail_edges(frames, edges, graph, nodes, syms):
    """{(caller node, callee node)} of the library's calls that are tail calls only (every call
    instruction from the caller to the callee a branch to its entry after the epilogue). Fails
    when the disassembly has a call the .ci has not."""
    tails = set()
    for node in frames:
        key = node if ":" not in node else "%s:%s" % (os.path.basename(node.rsplit(":", 1)[0]), node.rsplit(":", 1)[1])
        if key not in nodes:
            raise AnalysisError("%s is not in the link" % node)
        _, _, callees, _, tail_addrs = graph[nodes[key]]
        by_addr = {}
        for callee in edges.get(node, []):
            ckey = callee if ":" not in callee else "%s:%s" % (
                os.path.basename(callee.rsplit(":", 1)[0]), callee.rsplit(":", 1)[1])
            addr = nodes.get(ckey, syms.get(callee))
            if addr is None:
                raise AnalysisError("callee %s of %s is not in the link" % (callee, node))
            by_addr[addr] = callee
        missing = [graph[a][0] for a in callees if a not in by_addr]
        if missing:
            raise AnalysisError("%s calls %s, which -fcallgraph-info does not list" % (node, ", ".join(missing)))
        nested = set(callees) - set(tail_addrs)
        for addr, callee in by_addr.items():
            if addr in tail_addrs and addr not in nested:
                tails.add((node, callee))
    return tails


def runtime_bounds(graph, roots):
    """{address: (bound bytes, [names along the deepest path])} for roots and what they reach."""
    memo, active = {}, []

    def visit(addr):
        if addr in memo:
            return memo[addr]
        name, frame, callees, problems, _ = graph[addr]
        if problems:
            raise AnalysisError("%s: %s" % (name, "; ".join(problems)))
        if addr in active:
            raise AnalysisError("recursion in the runtime: %s" % " -> ".join(graph[a][0] for a in active + [addr]))
        active.append(addr)
        best = (0, [])
        for c in callees:
            b = visit(c)
            if b[0] > best[0]:
                best = b
        active.pop()
        memo[addr] = (frame + best[0], ["%s (%d)" % (name, frame)] + best[1])
        return memo[addr]

    return {r: visit(r) for r in roots}


def cmake_cache(build):
    cache = {}
    for line in open(os.path.join(build, "CMakeCache.txt")):
        m = re.match(r"^([\w-]+):\w+=(.*)$", line)
        if m:
            cache[m.group(1)] = m.group(2)
    return cache


def check_method(graph, frames):
    """The disassembly's frame of every library function (by a name defined once) must be
    GCC's: the check of the method the runtime routines are bounded by."""
    names = [f[2] for f in frames.values()]
    seen = {}
    for name, frame, _, problems, _ in graph.values():
        seen.setdefault(name, []).append((frame, problems))
    checked = 0
    for frame, qual, name in frames.values():
        if names.count(name) == 1 and len(seen.get(name, [])) == 1:
            got = seen[name][0][0]  # (a GCC switch's table branch is no problem here)
            if got != frame:
                raise AnalysisError("disassembly method: %s has %d B, -fstack-usage %d B" % (name, got, frame))
            checked += 1
    if checked < len(frames) // 2:
        raise AnalysisError("disassembly method checked on %d library functions only" % checked)
    return checked


def target_runtime(build, externals, frames, edges):
    """({symbol: (bound, path)} of the runtime routines the library calls, {(caller, callee)}
    of the library's tail calls), from a whole link of the library with the preset's compiler
    and flags."""
    cache = cmake_cache(build)
    cc = cache["ICOAC_ARM_GCC"]  # cmake/toolchain/arm-none-eabi.cmake
    prefix = cc[:-3] if cc.endswith("gcc") else cc
    # the library whole, newlib-nano and libm, linked by the preset (firmware/port/CMakeLists.txt)
    elf = build_path(build, "firmware", "port", "icoac_stack_link.elf")
    syms = symbol_addresses(prefix + "nm", elf)
    funcs, words = disassemble(prefix + "objdump", elf)
    graph = runtime_graph(funcs, words, lambda addr, n: read_words(prefix + "objdump", elf, addr, n))
    check_method(graph, frames)
    missing = [e for e in externals if e not in syms]
    if missing:
        raise AnalysisError("runtime routines not in the link: %s" % ", ".join(missing))
    tails = tail_edges(frames, edges, graph, function_addresses(prefix + "readelf", elf), syms)
    bounds = runtime_bounds(graph, sorted({syms[e] for e in externals}))
    return {e: bounds[syms[e]] for e in externals}, tails


def host_runtime(externals):
    unknown = [e for e in externals if e not in HOST_RUNTIME]
    if unknown:
        raise AnalysisError("calls out of the library with no stated bound: %s" % ", ".join(unknown))
    return {e: (HOST_RUNTIME_FRAME, ["%s (glibc, assumed)" % e]) for e in externals}


# --- the bound ---------------------------------------------------------------------------------

def bounds(frames, edges, runtime, accept_bounded, tails=frozenset()):
    """{node: (bound bytes, [function names along the deepest path])}. A frame must be static,
    or "dynamic,bounded" (GCC: then the figure is a reliable maximum) when accept_bounded. A
    callee in tails ((caller, callee) pairs: tail calls only) runs after the caller's frame is
    released."""
    memo, active = {}, []

    def visit(node):
        if node in memo:
            return memo[node]
        if node in active:
            cycle = active[active.index(node):] + [node]
            raise AnalysisError("recursion: %s" % " -> ".join(cycle))
        if node == "__indirect_call":
            raise AnalysisError("indirect call in %s" % active[-1])
        if node not in frames:
            return runtime[node]
        frame, qual, name = frames[node]
        if qual != "static" and not (accept_bounded and qual == "dynamic,bounded"):
            raise AnalysisError("%s: %s frame (%d bytes)" % (name, qual, frame))
        active.append(node)
        best = (frame, ["%s (%d)" % (name, frame)])
        for callee in edges.get(node, []):
            b = visit(callee)
            if (node, callee) in tails:
                b = (b[0], ["%s (%d, tail call to:)" % (name, frame)] + b[1])
            else:
                b = (frame + b[0], ["%s (%d)" % (name, frame)] + b[1])
            if b[0] > best[0]:
                best = b
        active.pop()
        memo[node] = best
        return memo[node]

    for node in frames:  # every function, reachable from the API or not
        visit(node)
    return memo


def build_path(build, *parts):
    """A path the build makes (the library's object directory, the link of the cross presets)."""
    path = os.path.join(build, *parts)
    if not os.path.exists(path):
        raise AnalysisError("%s: not found (build the library first)" % path)
    return path


def option_off(build, option):
    """True when the CMake cache of build sets the boolean option off."""
    cache = os.path.join(build, "CMakeCache.txt")
    if not os.path.exists(cache):
        return False
    m = re.search(r"^%s:BOOL=(\S*)$" % re.escape(option), open(cache).read(), re.M)
    return m is not None and m.group(1).upper() in ("OFF", "0", "FALSE", "NO", "N")


def analyse(config, build=None):
    build_rel, lib = CONFIGS[config]
    build = build or os.path.join(ROOT, build_rel)
    obj_dir = build_path(build, "firmware", "CMakeFiles", lib + ".dir")
    frames, edges = read_callgraph(obj_dir)
    externals = sorted({c for cs in edges.values() for c in cs if c not in frames and c != "__indirect_call"})
    tails = set()
    if config.startswith("cortex"):
        runtime, tails = target_runtime(build, externals, frames, edges)
        runtime = {e: (b, [p[0].replace(")", ", runtime)")] + p[1:]) for e, (b, p) in runtime.items()}
    else:
        runtime = host_runtime(externals)
    # x86-64 pushes the stack arguments of a call (icoac's 9-argument kernels): "dynamic,bounded"
    all_bounds = bounds(frames, edges, runtime, accept_bounded=not config.startswith("cortex"), tails=tails)
    result = {}
    for fn in public_functions():
        if fn not in all_bounds and fn in OPTIONAL_FUNCTIONS and option_off(build, OPTIONAL_FUNCTIONS[fn]):
            continue
        if fn not in all_bounds:
            raise AnalysisError("public function %s not in the call graph of %s" % (fn, obj_dir))
        result[fn] = all_bounds[fn]
    return result, {e: runtime[e][0] for e in externals}


def read_budget(doc, config):
    """The budget (bytes) of config in the stack-budget table of doc."""
    text = open(doc).read()
    try:
        table = text[text.index(BUDGET_BEGIN) + len(BUDGET_BEGIN):text.index(BUDGET_END)]
    except ValueError:
        raise AnalysisError("%s has no %s ... %s table" % (doc, BUDGET_BEGIN, BUDGET_END))
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in table.splitlines()
            if line.strip().startswith("|")]
    head = rows[0]
    col = BUDGET_COLUMNS[config]
    for row in rows[2:]:
        if row[0].lower().startswith("budget"):
            m = re.match(r"^([\d,]+) B$", row[head.index(col)])
            if m:
                return int(m.group(1).replace(",", ""))
    raise AnalysisError("no budget for %s in %s" % (col, doc))


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("config", choices=sorted(CONFIGS))
    ap.add_argument("--build", help="build directory (default: %s)" % ", ".join(
        "%s for %s" % (v[0], k) for k, v in CONFIGS.items()))
    ap.add_argument("--check", metavar="DOC", help="fail above the budget DOC states")
    ap.add_argument("--json", action="store_true", help="print the bounds as JSON")
    args = ap.parse_args(argv[1:])
    try:
        result, runtime = analyse(args.config, args.build)
        budget = read_budget(args.check, args.config) if args.check else None
    except AnalysisError as e:
        sys.exit("stack_bound %s: %s" % (args.config, e))
    if args.json:
        print(json.dumps({fn: b for fn, (b, _) in result.items()}, indent=1))
        return
    method = ("runtime routines and tail calls from the disassembly of a whole link (assumed: no loop in a "
              "runtime routine decrements sp)" if args.config.startswith("cortex")
              else "glibc routines %d B each: assumed, not measured" % HOST_RUNTIME_FRAME)
    print("static stack bound, %s: GCC's frames (.su) and calls (.ci); %s; interrupts not included"
          % (args.config, method))
    print("  runtime: " + ", ".join("%s %d" % kv for kv in sorted(runtime.items())))
    width = max(len(fn) for fn in result)
    for fn, (b, path) in result.items():
        print("  %-*s %5d B  %s" % (width, fn, b, " -> ".join(path)))
    worst = max(result.items(), key=lambda kv: kv[1][0])
    if budget is not None:
        verdict = "within" if worst[1][0] <= budget else "OVER"
        print("worst %s %d B: %s the budget of %d B (%s)" % (worst[0], worst[1][0], verdict, budget, args.check))
        if worst[1][0] > budget:
            sys.exit(1)


if __name__ == "__main__":
    main(sys.argv)
