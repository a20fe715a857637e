# SPDX-License-Identifier: Apache-2.0
"""What `ceiling` writes into OUT and what is read back. Layout of OUT: ``search.json`` (settings and every screening result, rewritten atomically at
most every 2 s and on exit: a rerun of the same command takes the screens from it and replays
the deterministic search), ``evals/<hash of w>_<protocol>_h<steps>/`` (a results directory per
full-horizon evaluation, checkpointed and resumed like ``grid``), ``ceiling.json`` and
``ceiling.md`` (the summary, written at the end).
The bench reads ceiling.json back for summary.md and Fig. 3a.
"""
from __future__ import annotations

import time
from dataclasses import asdict
from pathlib import Path
from typing import Any, Mapping

from icoac.core import binding as B
from icoac.core import results, store
from icoac.core.errors import ResultsError, UsageError
from icoac.core.metrics import percent
from icoac.core.options import CART_POLE, CEILING_DIR, CEILING_FILE, CEILING_PROTOCOLS
from icoac.studies.ceiling.search import PATTERN, Screen
from icoac.studies.ceiling.weights import as_weights, format_w

FORMAT_VERSION = 1
SEARCH_FILE = "search.json"
SUMMARY_MD = "ceiling.md"
FLUSH_EVERY = 2.0                             # s between rewrites of search.json
PROTOCOL_LABELS = {"first": "first trial", "retries": "retries"}
PHASE_LABELS = {"start": "starting points", "random": "random", "refine": "refinement", "cma": "CMA-ES"}


class ScreenStore:
    """Every screening result, keyed by w, with the settings that determine them; a rerun with the
    same settings reuses them, other settings are refused."""

    def __init__(self, path: Path, settings: dict[str, Any], dir_fd: int):
        self.path = Path(path)
        self.dir_fd = dir_fd
        self.settings = settings
        self.screens: dict[tuple[float, ...], Screen] = {}
        self.reused = 0
        self.dirty = False
        self.last = time.monotonic()

    def load(self) -> None:
        if not self.path.is_file():
            return
        where = repr(str(self.path))
        data = results.read_json(self.path, follow=False)
        if not isinstance(data, dict) or data.get("format_version") != FORMAT_VERSION \
                or not isinstance(data.get("screens"), list):
            raise ResultsError(f"{where} is not a ceiling search record; use another --out")
        store.check_same_settings(data.get("settings"), self.settings, self.path.parent, "a ceiling search")
        try:
            for row in data["screens"]:
                w = as_weights(row["w"], "search.json")
                self.screens[w] = Screen(int(row["n_success"]), int(row["n_success_interior"]),
                                         int(row["total_steps"]))
        except (KeyError, TypeError, ValueError, UsageError) as exc:
            raise ResultsError(f"{where}: malformed screen ({str(exc):.80}); use another --out") from None

    def get(self, w: tuple[float, ...]) -> Screen | None:
        s = self.screens.get(w)
        if s is not None:
            self.reused += 1
        return s

    def add(self, w: tuple[float, ...], s: Screen) -> None:
        self.screens[w] = s
        self.dirty = True
        if time.monotonic() - self.last >= FLUSH_EVERY:
            self.flush()

    def flush(self) -> None:
        if not self.dirty:
            return
        data = {"format_version": FORMAT_VERSION, "settings": self.settings,
                "screens": [{"w": list(w), **asdict(s)} for w, s in self.screens.items()]}
        store.write_json(self.path, data, indent=1, dir_fd=self.dir_fd)
        self.dirty = False
        self.last = time.monotonic()


def _optimiser_text(optimiser: Mapping[str, Any] | None) -> str:
    """What the summary says of the optimiser: nothing for the pattern search (its phases say it)."""
    if not optimiser or optimiser["name"] == PATTERN or "sigma0" not in optimiser:
        return ""
    return (f"; CMA-ES from {optimiser['start']}, sigma0 {optimiser['sigma0']:.4g}, population "
            f"{optimiser['popsize']}, {len(optimiser['runs'])} run(s)")


def _count(s: Mapping[str, Any], key: str, den: str, rate: str) -> str:
    return f"{s[key]} of {s[den]} ({percent(s[rate])})"


def summary_markdown(record: Mapping[str, Any]) -> str:
    st = record["settings"]
    best = record["best"]
    pol = record.get("policy", {})
    plant = st.get("plant", CART_POLE)
    unit = B.plant_info(plant)["input"][1]
    names = "w_x, w_ẋ, w_θ, w_θ̇" if plant == CART_POLE else ", ".join(
        f"w_{name}" for name, _ in B.plant_info(plant)["state"])
    lines = ["# Best single w found (method.md, L5)", "",
             f"Policy F = G·wᵀx̃ + U with G = {pol.get('gain', 'n/a'):g} {unit}, reflex {pol.get('reflex_mode')} "
             f"({pol.get('reflex_force', 'n/a'):g} {unit}), no learning (learn = 0); "
             f"{'' if plant == CART_POLE else f'plant {plant}; '}seed {st['seed']}, "
             f"{st['n_cells']} cells{'' if st['cells'] is None else ' (subset)'}, horizon {st['success_steps']:g} "
             f"steps{'' if not st['set'] else ', --set ' + ', '.join(f'{k}={v}' for k, v in st['set'].items())}.",
             "", f"Best w = ({names}) = {format_w(best['w'], 6)} ({best['source']}).", "",
             "| protocol | trials per cell | success, all cells | success, interior cells | median trials to success |",
             "|---|---|---|---|---|"]
    for p, s in best["protocols"].items():
        cap = "1" if p == "first" else f"≤ {s.get('max_trials', st['max_trials']):g}"
        med = "n/a" if s["median_trials_to_success"] is None else f"{s['median_trials_to_success']:g}"
        lines.append(f"| {PROTOCOL_LABELS[p]} | {cap} | {_count(s, 'n_success', 'n_cells', 'success_rate')} | "
                     f"{_count(s, 'n_success_interior', 'n_interior', 'success_rate_interior')} | {med} |")
    b = record.get("first_step_bound") or {}
    lines.append("")
    if b.get("computed"):
        lines.append(f"First-step bound (first trial, this seed's initial velocities): {b['n_lost']} cells "
                     f"({b['n_lost_interior']} interior) fail at the first Euler step whatever the force, so no "
                     f"controller succeeds in more than {b['max_success']} of {b['n_cells']} cells "
                     f"({percent(b['success_rate_bound'])}; interior {b['max_success_interior']} of "
                     f"{b['n_interior']}, {percent(b['success_rate_interior_bound'])}) on its first trial. With "
                     "retries a boundary cell can still succeed on a later, inward draw.")
    else:
        lines.append(f"First-step bound: not computed ({b.get('reason', 'n/a')}).")
    s = record.get("search")
    if s:
        ph = s["phases"]
        phases = ", ".join(f"{n} {PHASE_LABELS[p]}" for p, n in ph.items())
        lines += ["", f"Search: {s['screened']} candidates screened at {s['screen_steps']} steps, first trial "
                      f"({phases}{_optimiser_text(s.get('optimiser'))}; stop: "
                      f"{s['stop']}; seed {s['seed']}); the best {len(s['confirmed'])} confirmed at "
                      f"{st['success_steps']:g} steps:", "",
                  "| # | w | screen: success (interior) | full horizon, first trial: success (interior) |",
                  "|---|---|---|---|"]
        for c in s["confirmed"]:
            lines.append(f"| {c['index'] + 1} | {format_w(c['w'])} | {c['screen']['n_success']} "
                         f"({c['screen']['n_success_interior']}) | {c['first']['n_success']} "
                         f"({c['first']['n_success_interior']}) |")
        lines += ["", "Starting points (screen):", ""]
        by_w = {tuple(e["w"]): e for e in s["trace"]}
        for start in s["starts"]:
            e = by_w.get(tuple(start["w"]))
            score = f"{e['n_success']} ({e['n_success_interior']} interior)" if e else "not screened"
            lines.append(f"- {start['label']}: {format_w(start['w'])}: {score}")
    lines += ["", f"Wall time {record.get('wall_time', 0.0):.1f} s; git {(record.get('git') or {}).get('commit')}"
                  f"{' (dirty)' if (record.get('git') or {}).get('dirty') else ''}."]
    return "\n".join(lines) + "\n"


def load_ceiling(path: str | Path, what: str = "--ceiling") -> dict[str, Any]:
    """A ceiling.json (or the directory holding it), checked for what the bench reads; ResultsError
    otherwise."""
    path = Path(path)
    file = path / CEILING_FILE if path.is_dir() else path
    where = repr(str(file))
    data = results.read_json(file, f"{what}: ")
    try:
        if data["format_version"] != FORMAT_VERSION or data["command"] != "ceiling":
            raise ValueError("not a ceiling record")
        protos = data["best"]["protocols"]
        if not protos or any(p not in CEILING_PROTOCOLS for p in protos):
            raise ValueError("no protocol")
        for s in protos.values():
            for key in ("success_rate", "success_rate_interior"):
                v = s[key]
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 <= v <= 1:
                    raise ValueError(f"{key} {v!r:.20}")
        as_weights(data["best"]["w"])
    except (KeyError, TypeError, ValueError, UsageError) as exc:
        raise ResultsError(f"{what}: {where} is not a ceiling record ({str(exc):.80})") from None
    return data


def reference_lines(record: Mapping[str, Any] | None) -> dict[str, float] | None:
    """{'first trial': rate, 'retries': rate} (all cells) of a ceiling record, for Fig. 3a."""
    if record is None:
        return None
    return {PROTOCOL_LABELS[p]: float(s["success_rate"]) for p, s in record["best"]["protocols"].items()}


def bench_ceiling(out: Path, explicit: Path | None = None) -> dict[str, Any] | None:
    """The ceiling record the bench shows: ``explicit`` (must load), else OUT/ceiling/ceiling.json
    when it exists (None otherwise)."""
    if explicit is not None:
        return load_ceiling(explicit)
    default = Path(out) / CEILING_DIR / CEILING_FILE
    return load_ceiling(default, what="bench") if default.is_file() else None
