# SPDX-License-Identifier: Apache-2.0
"""firmware/port/stack_bound.py on small call graphs and disassemblies: the bound is the deepest
path, tail calls add in place of the caller's frame, and recursion, indirect calls, non-static
frames and unbounded stack writes fail the analysis."""
import importlib.util
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("stack_bound", REPO / "firmware" / "port" / "stack_bound.py")
sb = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sb)


def write_unit(tmp_path, name, functions, calls):
    """One object's .su and .ci: functions {name: (bytes, qualifier)}, calls [(caller, callee)]."""
    src = f"/src/{name}.c"
    su = "".join(f"{src}:{i + 1}:5:{fn}\t{b}\t{q}\n" for i, (fn, (b, q)) in enumerate(functions.items()))
    ci = [f'graph: {{ title: "{src}"']
    for i, (fn, (b, q)) in enumerate(functions.items()):
        ci.append(f'node: {{ title: "{fn}" label: "{fn}\\n{src}:{i + 1}:5\\n{b} bytes ({q})" }}')
    for caller, callee in calls:
        if callee not in functions:
            ci.append(f'node: {{ title: "{callee}" label: "{callee}" shape : ellipse }}')
        ci.append(f'edge: {{ sourcename: "{caller}" targetname: "{callee}" label: "{src}:9:1" }}')
    ci.append("}")
    (tmp_path / f"{name}.c.su").write_text(su)
    (tmp_path / f"{name}.c.ci").write_text("\n".join(ci) + "\n")


def bound_of(tmp_path, fn, runtime=None, accept_bounded=False, tails=frozenset()):
    frames, edges = sb.read_callgraph(str(tmp_path))
    return sb.bounds(frames, edges, runtime or {}, accept_bounded, set(tails))[fn]


def test_the_bound_is_the_deepest_path_and_a_tail_call_replaces_the_callers_frame(tmp_path):
    write_unit(tmp_path, "a", {"api": (16, "static"), "deep": (100, "static"), "wide": (40, "static")},
               [("api", "deep"), ("api", "wide"), ("wide", "leaf"), ("deep", "memcpy")])
    write_unit(tmp_path, "b", {"leaf": (200, "static")}, [])
    runtime = {"memcpy": (20, ["memcpy (20, runtime)"])}
    bound, path = bound_of(tmp_path, "api", runtime)
    assert bound == 16 + 40 + 200 and path == ["api (16)", "wide (40)", "leaf (200)"]
    assert bound_of(tmp_path, "deep", runtime)[0] == 120
    # api -> wide as a sibling call: wide's depth counts from api's caller
    assert bound_of(tmp_path, "api", runtime, tails={("api", "wide")})[0] == 240


def test_recursion_fails(tmp_path):
    write_unit(tmp_path, "a", {"f": (8, "static"), "g": (8, "static")}, [("f", "g"), ("g", "f")])
    with pytest.raises(sb.AnalysisError, match="recursion: f -> g -> f"):
        bound_of(tmp_path, "f")


def test_an_indirect_call_fails(tmp_path):
    write_unit(tmp_path, "a", {"f": (8, "static")}, [("f", "__indirect_call")])
    with pytest.raises(sb.AnalysisError, match="indirect call in f"):
        bound_of(tmp_path, "f")


@pytest.mark.parametrize("qualifier", ["dynamic", "dynamic,bounded"])
def test_a_frame_that_is_not_static_fails(tmp_path, qualifier):
    write_unit(tmp_path, "a", {"f": (8, qualifier)}, [])
    with pytest.raises(sb.AnalysisError, match="frame"):
        bound_of(tmp_path, "f")
    if qualifier == "dynamic,bounded":  # GCC's reliable maximum: the host accepts it
        assert bound_of(tmp_path, "f", accept_bounded=True)[0] == 8


def test_a_call_out_of_the_library_without_a_bound_fails_on_the_host():
    assert sb.host_runtime(["expf"])["expf"][0] == sb.HOST_RUNTIME_FRAME
    with pytest.raises(sb.AnalysisError, match="no stated bound: printf"):
        sb.host_runtime(["expf", "printf"])


def funcs(**bodies):
    """Disassembly {address: (name, [(address, mnemonic, operands)])}, 0x100 bytes per routine."""
    out = {}
    for k, (name, insns) in enumerate(bodies.items()):
        base = 0x1000 + 0x100 * k
        out[base] = (name, [(base + 2 * i, m, o) for i, (m, o) in enumerate(insns)])
    return out


def test_runtime_frames_are_the_sum_of_every_stack_decrement():
    f = funcs(r0=[("push", "{r4, r5, r6, lr}"), ("vpush", "{s16-s21}"), ("sub", "sp, #40"),
                  ("str.w", "lr, [sp, #-4]!"), ("bl", "1100 <r1>"), ("pop", "{r4, r5, r6, pc}")],
              r1=[("stmdb", "sp!, {r4, r5, lr}"), ("sub.w", "sp, sp, #8"), ("b.w", "1200 <r2>")],
              r2=[("push", "{r4, lr}"), ("ldr", "r3, [sp, #4]"), ("nop", "")],  # falls through
              r3=[("bx", "lr")])
    graph = sb.runtime_graph(f, {}, None)
    assert graph[0x1000][1] == 16 + 24 + 40 + 4 and graph[0x1000][2] == [0x1100]
    assert graph[0x1100][1] == 20 and graph[0x1100][4] == {0x1200}
    assert graph[0x1200][2] == [0x1300]  # the fall-through into the next routine
    bounds = sb.runtime_bounds(graph, [0x1000])
    assert bounds[0x1000][0] == 84 + 20 + 8 + 0


@pytest.mark.parametrize("insn", [("blx", "r3"), ("bx", "r2"), ("mov", "sp, r7"), ("add", "sp, r3"),
                                  ("tbb", "[pc, r3]"), ("ldr", "sp, [r0]"), ("mov", "pc, r3")])
def test_an_indirect_branch_or_unbounded_stack_write_fails(insn):
    graph = sb.runtime_graph(funcs(r0=[("push", "{lr}"), insn, ("pop", "{pc}")]), {}, lambda a, n: [0] * n)
    with pytest.raises(sb.AnalysisError):
        sb.runtime_bounds(graph, [0x1000])


def test_a_jump_table_inside_its_routine_is_a_switch():
    body = [("push", "{r4, lr}"), ("cmp", "r3, #2"), ("ldr", "r2, [pc, #8]\t@ (1080 <r0+0x80>)"),
            ("lsls", "r3, r3, #2"), ("ldr", "r3, [r2, r3]"), ("mov", "pc, r3"), ("pop", "{r4, pc}")]
    words = {0x1080: 0x5000}
    inside = sb.runtime_graph(funcs(r0=body), words, lambda a, n: [0x1009, 0x100b, 0x100d][:n] if a == 0x5000 else [])
    assert inside[0x1000][3] == [] and inside[0x1000][1] == 8
    outside = sb.runtime_graph(funcs(r0=body), words, lambda a, n: [0x1009, 0x2001, 0x100d][:n])
    assert "indirect branch" in outside[0x1000][3][0]


def test_the_budget_is_read_from_the_porting_guide(tmp_path):
    doc = tmp_path / "doc.md"
    doc.write_text("text\n" + sb.BUDGET_BEGIN + "\n| stack budget | cortex-m4f | cortex-m0plus | host |\n"
                   "|---|---|---|---|\n| budget: any call | 512 B | 1,024 B | 2,048 B |\n" + sb.BUDGET_END + "\n")
    assert [sb.read_budget(str(doc), c) for c in ("cortex-m4f", "cortex-m0plus", "host", "host-double")] == \
        [512, 1024, 2048, 2048]
    doc.write_text("no table\n")
    with pytest.raises(sb.AnalysisError):
        sb.read_budget(str(doc), "cortex-m4f")
    guide = str(REPO / "docs" / "porting.md")
    assert all(sb.read_budget(guide, c) > 0 for c in sb.CONFIGS)


def test_the_public_functions_are_the_headers_declarations():
    names = sb.public_functions()
    assert {"icoac_step", "icoac_init", "icoac_reset", "icoac_retune", "icoac_config_check",
            "icoac_rng_normal", "icoac_status_str"} <= set(names)
    assert len(names) == len(set(names)) and all(n.startswith("icoac_") for n in names)


def test_an_optional_function_is_skipped_only_where_its_option_is_off(tmp_path):
    assert set(sb.OPTIONAL_FUNCTIONS) <= set(sb.public_functions())
    cache = tmp_path / "CMakeCache.txt"
    assert not sb.option_off(str(tmp_path), "ICOAC_BATCH")  # no cache: required
    cache.write_text("ICOAC_BUILD_HOST:BOOL=OFF\nICOAC_BATCH:BOOL=OFF\n")
    assert sb.option_off(str(tmp_path), "ICOAC_BATCH")
    cache.write_text("ICOAC_BATCH:BOOL=ON\n")
    assert not sb.option_off(str(tmp_path), "ICOAC_BATCH")
    cache.write_text("ICOAC_BATCH_X:BOOL=OFF\n")
    assert not sb.option_off(str(tmp_path), "ICOAC_BATCH")


def test_a_multiversioned_call_counts_its_deepest_clone_and_not_its_resolver():
    frames = {"f.c:g": (16, "static", "g"), "f.c:v.default": (8, "static", "v"),
              "f.c:v.avx2": (900, "static", "v.avx2"), "f.c:v.resolver": (16, "static", "v.resolver")}
    edges = {"f.c:g": ["f.c:v"], "f.c:v.resolver": ["__cpu_indicator_init"]}
    graph = sb.multiversioned(frames, edges)
    assert sorted(graph["f.c:g"]) == ["f.c:v.avx2", "f.c:v.default"]
    assert graph["f.c:v.resolver"] == []
    assert sb.bounds(frames, graph, {}, accept_bounded=True)["f.c:g"][0] == 916
