# SPDX-License-Identifier: Apache-2.0
"""The parameters as the C tables describe them (icoac_params.h and the run's rows, read by the
binding as B.PARAMS; each plant's own in its descriptor): their valid ranges in words, the listing
of `python -m icoac params`, and the tables of docs/design.md and docs/plants.md
(icoac.tools.params_table writes and checks them)."""
from __future__ import annotations

import ctypes
from typing import Any, Mapping

from icoac.core import binding as B

COLUMNS = ("name", "unit", "default", "range", "modes", "tier", "description")


def _num(value: float) -> str:
    return f"{value:g}"


def modes_text(row: Mapping[str, Any]) -> str:
    names = [name for name, bit in B.PARAM_MODES.items() if row["modes"] & bit]
    return "all" if len(names) == len(B.PARAM_MODES) else ", ".join(names)


def _defaults() -> dict[str, Any]:
    """Every parameter's C default as a record writes it (symbolic switches, booleans; the
    arrays' entries the default task uses)."""
    from icoac.core import config as C  # the value formatting of records
    controller, run = B.Config(), B.Run()
    B.lib.icoac_config_default(ctypes.byref(controller))
    B.lib.icoac_sim_run_default(ctypes.byref(run))
    sizes = {"inputs": controller.task.n_inputs, "rules": controller.task.n_rules}
    out = {}
    for name, row in B.PARAMS.items():
        struct = controller if row["type"] == "icoac_config_t" else run
        value = C._value_out(name, C._ctype(struct, name), C._get(struct, name))
        out[name] = value[:sizes[row["dim"]]] if row["dim"] in sizes else value
    return out


def _value_text(value: Any) -> str:
    if isinstance(value, list):
        return ", ".join(_value_text(v) for v in value)
    if isinstance(value, bool):
        return str(value).lower()
    return _num(value) if isinstance(value, float) else str(value)


def rows(tier: str | None = None) -> list[dict[str, str]]:
    """One dict of COLUMNS per parameter (tier "essential" or "advanced": those only), in C order."""
    from icoac.core import config as C  # the symbolic names of the switches
    defaults = _defaults()
    out = []
    for name, row in B.PARAMS.items():
        if tier is not None and row["tier"] != tier:
            continue
        choices = tuple(C.ENUMS[name]) if name in C.ENUMS else None
        out.append({"name": name, "unit": row["unit"], "default": _value_text(defaults[name]),
                    "range": B.range_text(row, choices), "modes": modes_text(row), "tier": row["tier"],
                    "description": row["doc"]})
    return out


def _integrator(value: int) -> str:
    return next(name for name, v in B.INTEGRATORS.items() if v == value)


def plant_rows(plant: str, tier: str | None = None) -> list[dict[str, str]]:
    """One dict of COLUMNS per parameter of a registry plant (its descriptor's table; tier: those
    only), then its model's dt and integrator, then its task's knobs."""
    model = B.model_default(plant)
    info = B.plant_info(plant)

    def row(p: dict) -> dict[str, str]:
        return {"name": p["name"], "unit": p["unit"], "default": _num(p["value"]),
                "range": f"[{_num(p['min'])}, {_num(p['max'])}]", "tier": p["tier"], "description": p["doc"]}
    table = [row(p) for p in info["params"]]
    table += [{"name": "dt", "unit": "s", "default": _num(model.dt), "range": f"[{_num(B.DT_MIN)}, {_num(B.DT_MAX)}]",
               "tier": "advanced", "description": "integration step, one controller tick"},
              {"name": "integrator", "unit": "", "default": _integrator(model.integrator),
               "range": ", ".join(B.INTEGRATORS), "tier": "advanced",
               "description": "explicit Euler (Sutton's update order) or classical RK4"}]
    table += [row(k) for k in (info["task"] or {}).get("knobs", [])]
    return [dict(r, modes="all") for r in table if tier is None or r["tier"] == tier]


def text_table(tier: str | None = None, plant: str | None = None) -> str:
    """The listing of `python -m icoac params`: aligned columns, one line per parameter (the
    controller's and the run's; with plant, that registry plant's after them)."""
    table = [dict(zip(COLUMNS, COLUMNS))] + rows(tier) + (plant_rows(plant, tier) if plant else [])
    widths = {c: max(len(r[c]) for r in table) for c in COLUMNS[:-1]}
    return "\n".join("  ".join(r[c].ljust(widths[c]) for c in COLUMNS[:-1]) + "  " + r["description"]
                     for r in table).rstrip() + "\n"


def _markdown(table: list[dict[str, str]], columns: tuple[str, ...]) -> list[str]:
    def cell(text: str) -> str:
        return text.replace("|", "\\|")
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for r in table:
        lines.append("| " + " | ".join([f"`{r['name']}`"] + [cell(r[c]) for c in columns[1:]]) + " |")
    return lines


def markdown_table() -> list[str]:
    """docs/design.md's parameter table."""
    return _markdown(rows(), COLUMNS)


def plant_markdown(plant: str) -> list[str]:
    """A registry plant's parameter table in docs/plants.md."""
    return _markdown(plant_rows(plant), tuple(c for c in COLUMNS if c != "modes"))
