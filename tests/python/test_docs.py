# SPDX-License-Identifier: Apache-2.0
"""Every `python -m icoac ...` command in README.md, docs/*.md and the Makefile, and every
`icoac ...` command (the installed package's script), still parses, and its --set /
--param names and values build a configuration (nothing is run)."""
import re
import shlex
from pathlib import Path

import pytest

from icoac import cli
from icoac.studies import sweep
from icoac.core.config import build_config, parse_sets

REPO = Path(__file__).resolve().parents[2]
# Placeholders the documents use, with a value each stands for.
PLACEHOLDERS = {"NAME": "variant", "SETTING": "integrator=rk4", "$(BENCH_PROFILE)": "quick",
                "$(BENCH_OUT)": "results/bench", "$(BENCH_FIGURES)": "docs/figures", "$(BENCH_ARGS)": "--resume",
                "$(PLANT)": "furuta", "$(PLANT_OUT)": "results/bench-furuta", "$(PLANT_OUT)/ceiling": "results/c",
                "$(PLANT_FIGURES)": "docs/figures/furuta", "$(PLANT_DATA)": "docs/data/bench-default-furuta.json"}


def _after(text: str):
    """What follows 'python -m icoac' in a command, or 'icoac' at its start (None for
    other commands, icoac.tools, the package name alone and `icoac: error: ...`)."""
    m = (re.search(r"(?:python3?|\$\(VPY\)) -m icoac(\s.*|$)", text, re.S)
         or re.match(r"\s*(?:\S*/)?icoac(\s+\S.*)", text, re.S))
    return " ".join(m.group(1).split()) if m else None


def documented_commands():
    """(file, arguments) of every documented harness command: code-block lines (with '\\'
    continuations), inline `...` spans (which may wrap), Makefile recipe lines."""
    out = []
    for path in [REPO / "README.md", REPO / "Makefile", *sorted((REPO / "docs").glob("*.md"))]:
        text = path.read_text().replace("\\\n", " ")
        if path.name == "Makefile":
            lines, spans = text.splitlines(), []
        else:
            blocks = re.findall(r"```[^\n]*\n(.*?)```", text, re.S)
            lines = [line for block in blocks for line in block.splitlines()]
            spans = re.findall(r"`([^`]+)`", re.sub(r"```.*?```", "", text, flags=re.S))
        for item in lines + spans:
            args = _after(item)
            if args is not None:
                out.append((path.name, args))
    return out


COMMANDS = documented_commands()


def test_commands_found():
    assert len(COMMANDS) >= 8, COMMANDS
    assert any("sweep" in c and "--seeds" in c for _, c in COMMANDS)


@pytest.mark.parametrize("where, command", COMMANDS, ids=[f"{w}:{c[:50]}" for w, c in COMMANDS])
def test_documented_command_parses(where, command):
    words = [PLACEHOLDERS.get(w, w) for w in shlex.split(command)]
    if words in ([], ["--help"], ["--version"]):  # they print and exit (--version: test_version.py)
        return
    args = cli.build_parser().parse_args(words)
    if hasattr(args, "scheduler"):  # the backend options combine (nothing connects)
        cli._dask_spec(args)
    if getattr(args, "set", None):
        build_config(parse_sets(args.set))
    if args.command == "sweep":
        params = sweep.parse_params(args.param)
        for setting in sweep.settings(params, args.one_at_a_time):
            build_config({k: v for k, v in setting.items() if k not in sweep.PRIOR_PARAMS}, condition=args.condition)


def test_learner_sweep_plans_build():
    """Every setting of the learner sweeps (icoac.tools.learner_sweeps, method.md, L2-L4) builds a
    configuration of its condition, in the mode of that condition."""
    from icoac.core import binding as B
    from icoac.tools import learner_sweeps

    n = 0
    for name, condition, params, one_at_a_time in learner_sweeps.STAGE_1 + learner_sweeps.STAGE_2:
        for setting in sweep.settings(sweep.parse_params(params), one_at_a_time):
            cfg = build_config({k: v for k, v in setting.items() if k not in sweep.PRIOR_PARAMS}, condition=condition)
            assert cfg.controller.mode == (B.MODE_SEARCH if "search" in condition else B.MODE_RL), name
            n += 1
    assert n > 20
