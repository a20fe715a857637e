"""Configurations: C defaults plus overrides by field name, validated by the C check functions."""
from __future__ import annotations

import ctypes
import json
import math
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from . import _binding as B
from ._binding import ConfigError

# Symbolic names of the enum / boolean switches.
ENUMS: dict[str, dict[str, int]] = {
    "mode": {"ico": 0, "rl": 1},
    "reflex_mode": {"unit": 0, "gain": 1},
    "ico_timing": {"code": 0, "literal": 1},
    "integrator": {"euler": 0, "rk4": 1},
}
BOOLS = ("clip_inputs", "rl_reflex", "act_with_sample")
_BOOL_NAMES = {"true": 1, "false": 0, "on": 1, "off": 0, "yes": 1, "no": 0, "1": 1, "0": 0}

CONTROLLER_FIELDS = tuple(name for name, _ in B.Config._fields_)
PLANT_FIELDS = tuple(name for name, _ in B.Plant._fields_)
RUN_FIELDS = tuple(name for name, _ in B.Run._fields_)
ALL_FIELDS = CONTROLLER_FIELDS + PLANT_FIELDS + RUN_FIELDS

# Named learning conditions: overrides applied on top of the defaults.
CONDITIONS: dict[str, dict[str, Any]] = {
    "ico": {"mode": "ico"},
    "rl": {"mode": "rl"},       # prior mean 0 (spec A16)
    "ico-rl": {"mode": "rl"},   # prior from an ICO grid (spec 7)
}


def _real_out(value: float) -> float:
    """icoac_real_t value as a JSON-friendly float (float32 printed to its shortest round trip)."""
    if B.real_dtype == np.float32:
        return float(np.format_float_positional(np.float32(value), unique=True, trim="-")) \
            if math.isfinite(value) else float(value)
    return float(value)


def _struct_to_dict(struct: ctypes.Structure) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for name, ctype in struct._fields_:
        value = getattr(struct, name)
        if hasattr(value, "__len__"):
            out[name] = [_real_out(v) if ctype._type_ is B.c_real else v for v in value]
        elif ctype is B.c_real:
            out[name] = _real_out(value)
        elif ctype is ctypes.c_double:
            out[name] = float(value)
        else:
            out[name] = int(value)
    for name, names in ENUMS.items():
        if name in out:
            reverse = {v: k for k, v in names.items()}
            out[name] = reverse.get(out[name], out[name])
    for name in BOOLS:
        if name in out:
            out[name] = bool(out[name])
    return out


def _parse_scalar(name: str, ctype, value: Any):
    if name in ENUMS:
        names = ENUMS[name]
        if isinstance(value, str):
            key = value.strip().lower()
            if key not in names:
                raise ConfigError(B.ERR_BAD_MODE, f"bad value {value!r} for {name}; valid: {', '.join(names)}")
            return names[key]
        if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
            return int(value)  # range checked by C
        raise ConfigError(B.ERR_BAD_MODE, f"bad value {value!r} for {name}; valid: {', '.join(names)}")
    if name in BOOLS:
        if isinstance(value, (bool, np.bool_)):
            return int(value)
        if isinstance(value, str) and value.strip().lower() in _BOOL_NAMES:
            return _BOOL_NAMES[value.strip().lower()]
        if isinstance(value, (int, np.integer)):
            return int(value)
        raise ConfigError(B.ERR_BAD_MODE, f"bad value {value!r} for {name}; expected true/false")
    if ctype in (ctypes.c_int32, ctypes.c_int64):
        if isinstance(value, str):
            try:
                value = float(value)
            except ValueError:
                raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"bad value {value!r} for {name}; expected an integer")
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"bad value {value!r} for {name}; expected an integer")
        if not (math.isfinite(value) and float(value) == int(value)):
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"bad value {value!r} for {name}; expected an integer")
        limit = 2 ** 31 if ctype is ctypes.c_int32 else 2 ** 63
        if not -limit <= int(value) < limit:
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"value {value!r} for {name} out of integer range")
        return int(value)
    # real
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"bad value {value!r} for {name}; expected a number")
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"bad value {value!r} for {name}; expected a number")
    return float(value)  # finiteness and range checked by C


def _set_field(struct: ctypes.Structure, name: str, value: Any) -> None:
    ctype = dict(struct._fields_)[name]
    if issubclass(ctype, ctypes.Array):
        if isinstance(value, str):
            try:
                value = json.loads(value)
            except ValueError:
                value = [v for v in value.replace("[", "").replace("]", "").split(",") if v.strip()]
        if not isinstance(value, (list, tuple, np.ndarray)) or len(value) != ctype._length_:
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                              f"bad value {value!r} for {name}; expected {ctype._length_} numbers")
        arr = ctype(*[_parse_scalar(name, ctype._type_, v) for v in value])
        setattr(struct, name, arr)
    else:
        setattr(struct, name, _parse_scalar(name, ctype, value))


def parse_value(text: str) -> Any:
    """Value of a ``--set name=value`` option: JSON if it parses, else the raw string."""
    try:
        return json.loads(text)
    except ValueError:
        return text


@dataclass
class RunConfig:
    """Controller, plant and run parameters of one benchmark, plus an optional prior."""
    controller: B.Config = field(default_factory=B.Config)
    plant: B.Plant = field(default_factory=B.Plant)
    run: B.Run = field(default_factory=B.Run)
    prior: B.Prior | None = None

    def to_dict(self) -> dict[str, Any]:
        out = {"controller": _struct_to_dict(self.controller),
               "plant": _struct_to_dict(self.plant),
               "run": _struct_to_dict(self.run)}
        out["prior"] = prior_to_dict(self.prior) if self.prior is not None else None
        return out

    def check(self) -> "RunConfig":
        """Validate with the C check functions; raise ConfigError carrying the C message."""
        B.check_status(B.lib.icoac_config_check(ctypes.byref(self.controller)), "controller config")
        B.check_status(B.lib.icoac_sim_plant_check(ctypes.byref(self.plant)), "plant config")
        B.check_status(B.lib.icoac_sim_run_check(ctypes.byref(self.run)), "run config")
        if self.prior is not None:
            check_prior(self.prior)
        return self


def prior_to_dict(prior: B.Prior) -> dict[str, Any]:
    return {"mean": [_real_out(v) for v in prior.mean],
            "cov": [[_real_out(v) for v in row] for row in prior.cov]}


def make_prior(mean, cov) -> B.Prior:
    """icoac_prior_t from a mean (4,) and covariance (4, 4); order (w_x, w_xdot, w_theta, w_thetadot)."""
    mean = np.asarray(mean, dtype=float).reshape(B.N_INPUTS)
    cov = np.asarray(cov, dtype=float).reshape(B.N_INPUTS, B.N_INPUTS)
    prior = B.Prior()
    for i in range(B.N_INPUTS):
        prior.mean[i] = float(mean[i])
        for j in range(B.N_INPUTS):
            prior.cov[i][j] = float(cov[i, j])
    return prior


def prior_from_dict(data: Mapping[str, Any] | None) -> B.Prior | None:
    if data is None:
        return None
    return make_prior(data["mean"], data["cov"])


def check_prior(prior: B.Prior) -> None:
    """Prior validation is the C library's (icoac_prior_check, also run by icoac_init)."""
    B.check_status(B.lib.icoac_prior_check(ctypes.byref(prior)), "prior")


def _resolve(name: str) -> str:
    if name not in ALL_FIELDS or name == "reserved":
        valid = ", ".join(n for n in ALL_FIELDS if n != "reserved")
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"unknown parameter {name!r}; valid names: {valid}")
    return name


def build_config(overrides: Mapping[str, Any] | None = None, condition: str | None = None,
                 prior: B.Prior | None = None, check: bool = True) -> RunConfig:
    """C defaults, then the condition's overrides, then ``overrides`` by field name; validated by C."""
    cfg = RunConfig(prior=prior)
    B.lib.icoac_config_default(ctypes.byref(cfg.controller))
    B.lib.icoac_sim_plant_default(ctypes.byref(cfg.plant))
    B.lib.icoac_sim_run_default(ctypes.byref(cfg.run))
    merged: dict[str, Any] = {}
    if condition is not None:
        if condition not in CONDITIONS:
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                              f"unknown condition {condition!r}; valid: {', '.join(CONDITIONS)}")
        merged.update(CONDITIONS[condition])
    merged.update(overrides or {})
    for name, value in merged.items():
        name = _resolve(name)
        if name in CONTROLLER_FIELDS:
            target = cfg.controller
        elif name in PLANT_FIELDS:
            target = cfg.plant
        else:
            target = cfg.run
        _set_field(target, name, value)
    if check:
        cfg.check()
    return cfg


def config_from_dict(data: Mapping[str, Any], check: bool = True) -> RunConfig:
    """Inverse of RunConfig.to_dict."""
    overrides: dict[str, Any] = {}
    for group in ("controller", "plant", "run"):
        for name, value in (data.get(group) or {}).items():
            if name != "reserved":
                overrides[name] = value
    return build_config(overrides, prior=prior_from_dict(data.get("prior")), check=check)
