# SPDX-License-Identifier: Apache-2.0
"""The schema of a run record (run.json), checked with jsonschema.

The configuration part is derived from the library, not written by hand: every group and field
of a plant's default configuration (RunConfig.to_dict of the C defaults) is required, with its
JSON type, and nothing else is allowed. A record that lacks a group or a field is refused, never
filled in from today's defaults; the values themselves are then checked by the C library
(config_from_dict).
"""
from __future__ import annotations

import functools
from typing import Any

import jsonschema

from icoac.core.config import ENUMS, build_config
from icoac.core.errors import ResultsError
from icoac.core.options import SEED_LIMIT
from icoac.core.plants import PLANTS
from icoac.core.registry import CONDITIONS

FORMAT_VERSION = 3
_NULLABLE_STRING = {"type": ["string", "null"]}
_NUMBERS = {"type": "array", "items": {"type": "number"}}


def _of_value(value: Any, name: str) -> dict[str, Any]:
    """The schema of a configuration value shaped like ``value`` (a default), by its field name."""
    if isinstance(value, list):
        return {"type": "array", "items": _of_value(value[0], name), "minItems": len(value), "maxItems": len(value)}
    if name in ENUMS:
        return {"enum": list(ENUMS[name])}
    if isinstance(value, bool):
        return {"type": "boolean"}
    if isinstance(value, int):
        return {"type": "integer"}
    if isinstance(value, float):
        return {"type": "number"}
    if isinstance(value, str):
        return {"const": value}  # a plant's name
    return _closed_object({key: _of_value(v, f"{name}.{key}" if name else key) for key, v in value.items()})


def _closed_object(properties: dict[str, Any], optional: dict[str, Any] | None = None) -> dict[str, Any]:
    return {"type": "object", "properties": {**properties, **(optional or {})}, "required": list(properties),
            "additionalProperties": False}


def _group(value: dict[str, Any], prefix: str) -> dict[str, Any]:
    """A group of the configuration: its fields' names are the canonical ones after ``prefix``."""
    return _closed_object({key: _of_value(v, prefix + key) for key, v in value.items()})


def _config_schema() -> dict[str, Any]:
    defaults = [build_config(plant=plant).to_dict() for plant in PLANTS]
    prior = {"oneOf": [{"type": "null"},
                       _closed_object({"mean": _NUMBERS, "cov": {"type": "array", "items": _NUMBERS}})]}
    return _closed_object({
        "controller": _group(defaults[0]["controller"], ""),
        "plant": {"oneOf": [_group(d["plant"], "") for d in defaults]},
        "run": _group(defaults[0]["run"], ""),
        "prior": prior,
    })


# What a prior taken from an ICO run records of its origin (prior.from_results).
PRIOR_ORIGIN = ("source_plant", "source_condition", "source_learn", "source_task")

_PRIOR_INFO = {
    "oneOf": [
        {"type": "null"},
        {"type": "object", "required": ["kind", "mean", "cov"],
         "properties": {"kind": {"type": "string"}, "mean": _NUMBERS,
                        "cov": {"type": "array", "items": _NUMBERS}},
         # a prior taken from an ICO results directory names the run's plant, condition, task and learning flag
         "if": {"required": ["source_commit"], "properties": {"source": {"type": "string"}}},
         "then": {"required": list(PRIOR_ORIGIN)}},
    ]
}

_BUILD = _closed_object({"commit": _NULLABLE_STRING, "dirty": {"type": ["boolean", "null"]},
                         "abi": {"type": ["object", "null"]}, "timestamp": {"type": "string"}})


@functools.lru_cache(maxsize=None)
def run_record_schema() -> dict[str, Any]:
    """The JSON schema of a run.json of this version (results.make_record writes it)."""
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        **_closed_object({
            "format_version": {"const": FORMAT_VERSION},
            "condition": {"enum": list(CONDITIONS)},
            "seed": {"type": "integer", "minimum": 0, "maximum": SEED_LIMIT - 1},
            "cells": {"oneOf": [{"type": "null"},
                                {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 1}]},
            "cells_sha256": {"type": "string", "pattern": "^[0-9a-f]{64}$"},
            "complete": {"type": "boolean"},
            "config": _config_schema(),
            "git": _closed_object({"commit": _NULLABLE_STRING, "dirty": {"type": ["boolean", "null"]}}),
            "abi": {"type": "object"},
            "builds": {"type": "array", "items": _BUILD, "minItems": 1},
            "timestamp": {"type": "string"},
            "wall_time": {"type": "number", "minimum": 0},
            "threads": {"type": "integer", "minimum": 0},
            "summary": {"type": "object"},
        }, optional={"prior_info": _PRIOR_INFO, "backend": {"type": "object"}}),
    }


def check_run_record(record: Any, where: str) -> None:
    """ResultsError naming the first place where ``record`` breaks the schema."""
    if isinstance(record, dict) and record.get("format_version") != FORMAT_VERSION:
        raise ResultsError(f"{where}: format_version {_short(repr(record.get('format_version')), 40)} is not "
                           f"{FORMAT_VERSION}; this version reads only the records it writes (rerun that run)")
    validator = jsonschema.Draft202012Validator(run_record_schema())
    error = jsonschema.exceptions.best_match(validator.iter_errors(record))
    if error is not None:
        path = ".".join(str(p) for p in error.absolute_path) or "the record"
        raise ResultsError(f"{where}: {path}: {_short(error.message)} (a run.json of format "
                           f"{FORMAT_VERSION}, as this version writes, is required)")


def _short(text: str, limit: int = 160) -> str:
    return text if len(text) <= limit else text[:limit - 3] + "..."
