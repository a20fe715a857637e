"""Configurations: C defaults plus overrides by field name, validated by the C check functions."""
from __future__ import annotations

import ctypes
import json
import math
import re
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


_INT_LIMITS = {ctypes.c_int32: (-2 ** 31, 2 ** 31 - 1), ctypes.c_int64: (-2 ** 63, 2 ** 63 - 1)}
_INT_TEXT = re.compile(r"[+-]?[0-9]{1,30}")

# Status of a value rejected on the Python side: the one the C check would give for that field.
_FIELD_STATUS: dict[str, int] = {
    "input_range": B.ERR_BAD_SCALE, "gain": B.ERR_BAD_GAIN, "reflex_force": B.ERR_BAD_GAIN,
    "zone_theta": B.ERR_BAD_ZONE, "zone_x": B.ERR_BAD_ZONE, "ico_rate": B.ERR_BAD_ICO_RATE,
    "critic_rate": B.ERR_BAD_CRITIC, "discount": B.ERR_BAD_CRITIC, "td_clip": B.ERR_BAD_CRITIC,
    "critic_range": B.ERR_BAD_CRITIC, "critic_threshold": B.ERR_BAD_CRITIC,
    "noise_std": B.ERR_BAD_ACTOR, "actor_scale": B.ERR_BAD_ACTOR, "forgetting": B.ERR_BAD_ACTOR,
}


def _group(name: str) -> str:
    if name in CONTROLLER_FIELDS:
        return "controller"
    return "plant" if name in PLANT_FIELDS else "run"


def _status_of(name: str) -> int:
    if name in _FIELD_STATUS:
        return _FIELD_STATUS[name]
    group = _group(name)
    if group == "controller":
        return B.ERR_BAD_MODE
    return B.SIM_ERR_BAD_PLANT if group == "plant" else B.SIM_ERR_BAD_RUN


def _short(value: Any, limit: int = 60) -> str:
    """repr of a value, shortened for one-line messages."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _bad(name: str, message: str) -> ConfigError:
    return ConfigError(_status_of(name), f"{_group(name)} parameter {name}: {message}")


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def _parse_int(name: str, ctype, value: Any) -> int:
    """An integer for an int32/int64 field, range-checked so that ctypes never truncates it."""
    if isinstance(value, str):
        text = value.strip()
        if _INT_TEXT.fullmatch(text):
            value = int(text)
        else:
            try:
                value = float(text)
            except ValueError:
                raise _bad(name, f"bad value {_short(value)}; expected an integer") from None
    if not _is_number(value):
        raise _bad(name, f"bad value {_short(value)}; expected an integer")
    if isinstance(value, (float, np.floating)):
        if not math.isfinite(value) or not float(value).is_integer():
            raise _bad(name, f"bad value {_short(value)}; expected an integer")
    number = int(value)
    lo, hi = _INT_LIMITS[ctype]
    if not lo <= number <= hi:
        bits = 32 if ctype is ctypes.c_int32 else 64
        raise _bad(name, f"value {_short(value)} out of integer range (must fit int{bits}: [{lo}, {hi}])")
    return number


def _parse_real(name: str, ctype, value: Any) -> float:
    """A finite, normal (or zero) value representable in the field's C type."""
    if isinstance(value, str):
        try:
            value = float(value.strip())
        except ValueError:
            raise _bad(name, f"bad value {_short(value)}; expected a number") from None
    if not _is_number(value):
        raise _bad(name, f"bad value {_short(value)}; expected a number")
    try:
        number = float(value)
    except OverflowError:
        raise _bad(name, f"value {_short(value)} is not a finite number") from None
    if not math.isfinite(number):
        raise _bad(name, f"value {_short(value)} is not a finite number")
    kind = np.float32 if ctype is ctypes.c_float else np.float64
    with np.errstate(over="ignore", under="ignore"):
        stored = float(kind(number))
    info = np.finfo(kind)
    if not math.isfinite(stored):
        raise _bad(name, f"value {_short(value)} overflows the C {info.dtype} field")
    if number != 0.0 and abs(stored) < info.tiny:
        raise _bad(name, f"value {_short(value)} is subnormal or underflows the C {info.dtype} field "
                         f"(|value| must be 0 or >= {info.tiny:.4g})")
    return number


def _parse_scalar(name: str, ctype, value: Any):
    if name in ENUMS:
        names = ENUMS[name]
        if isinstance(value, str):
            key = value.strip().lower()
            if key not in names:
                raise ConfigError(_status_of(name), f"bad value {_short(value)} for {name}; valid: {', '.join(names)}")
            return names[key]
        if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
            return _parse_int(name, ctypes.c_int32, value)  # value range checked by C
        raise ConfigError(_status_of(name), f"bad value {_short(value)} for {name}; valid: {', '.join(names)}")
    if name in BOOLS:
        if isinstance(value, (bool, np.bool_)):
            return int(value)
        if isinstance(value, str) and value.strip().lower() in _BOOL_NAMES:
            return _BOOL_NAMES[value.strip().lower()]
        if isinstance(value, (int, np.integer)) and int(value) in (0, 1):
            return int(value)
        raise ConfigError(B.ERR_BAD_MODE, f"bad value {_short(value)} for {name}; expected true/false")
    if ctype in _INT_LIMITS:
        return _parse_int(name, ctype, value)
    return _parse_real(name, ctype, value)  # range checked by C


def _set_field(struct: ctypes.Structure, name: str, value: Any) -> None:
    ctype = dict(struct._fields_)[name]
    if issubclass(ctype, ctypes.Array):
        if isinstance(value, str):
            try:
                value = json.loads(value)
            except (ValueError, RecursionError):
                value = [v for v in value.replace("[", "").replace("]", "").split(",") if v.strip()]
        if isinstance(value, np.ndarray):
            value = value.tolist()
        if not isinstance(value, (list, tuple)) or len(value) != ctype._length_:
            raise _bad(name, f"bad value {_short(value)}; expected {ctype._length_} numbers")
        arr = ctype(*[_parse_scalar(name, ctype._type_, v) for v in value])
        setattr(struct, name, arr)
    else:
        setattr(struct, name, _parse_scalar(name, ctype, value))


def parse_value(text: str) -> Any:
    """Value of a ``--set name=value`` option: JSON if it parses, else the raw string."""
    try:
        return json.loads(text)
    except (ValueError, RecursionError):
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
        """Validate with the C check functions; raise ConfigError carrying the C message and naming
        the parameter(s) the C check rejects."""
        for label, struct, check_fn, default_fn in (
                ("controller config", self.controller, B.lib.icoac_config_check, B.lib.icoac_config_default),
                ("plant config", self.plant, B.lib.icoac_sim_plant_check, B.lib.icoac_sim_plant_default),
                ("run config", self.run, B.lib.icoac_sim_run_check, B.lib.icoac_sim_run_default)):
            status = int(check_fn(ctypes.byref(struct)))
            if status != B.OK:
                culprits = _culprits(struct, check_fn, default_fn)
                text = B.status_str(status) + (f"; rejected: {culprits}" if culprits else "")
                if status not in B._CONFIG_STATUSES:
                    B.check_status(status, label)
                raise ConfigError(status, text, context=label)
        if self.prior is not None:
            check_prior(self.prior)
        return self


def _culprits(struct: ctypes.Structure, check_fn, default_fn) -> str:
    """The fields of a struct the C check rejects: those that differ from the C default and fail
    the check on their own (or, when only a combination fails, every field that differs)."""
    def fresh():
        out = type(struct)()
        default_fn(ctypes.byref(out))
        return out

    def value(s, name):
        v = getattr(s, name)
        return list(v) if hasattr(v, "__len__") else v

    ref = fresh()
    differ = [name for name, _ in struct._fields_
              if name != "reserved" and not _same(value(struct, name), value(ref, name))]
    alone = []
    for name in differ:
        probe = fresh()
        setattr(probe, name, getattr(struct, name))
        if int(check_fn(ctypes.byref(probe))) != B.OK:
            alone.append(name)
    shown = _struct_to_dict(struct)
    return ", ".join(f"{name}={shown[name]!r}" for name in (alone or differ))


def _same(a, b) -> bool:
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return a == b


def prior_to_dict(prior: B.Prior) -> dict[str, Any]:
    return {"mean": [_real_out(v) for v in prior.mean],
            "cov": [[_real_out(v) for v in row] for row in prior.cov]}


def _prior_array(value: Any, shape: tuple[int, ...], what: str) -> np.ndarray:
    """Finite-or-not float array of an exact shape from numbers only (no strings, no booleans)."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "iuf" or value.shape != shape:
            raise ConfigError(B.ERR_BAD_PRIOR, f"prior {what}: expected {shape} numbers, got {_short(value)}")
        return value.astype(np.float64)

    def flat(v, depth):
        if depth == len(shape):
            if not _is_number(v):
                raise ConfigError(B.ERR_BAD_PRIOR, f"prior {what}: {_short(v)} is not a number")
            try:
                return [float(v)]
            except OverflowError:
                raise ConfigError(B.ERR_BAD_PRIOR, f"prior {what}: {_short(v)} is not a finite number") from None
        if not isinstance(v, (list, tuple)) or len(v) != shape[depth]:
            raise ConfigError(B.ERR_BAD_PRIOR, f"prior {what}: expected shape {shape}, got {_short(value)}")
        return [x for item in v for x in flat(item, depth + 1)]

    return np.array(flat(value, 0), dtype=np.float64).reshape(shape)


def make_prior(mean, cov) -> B.Prior:
    """icoac_prior_t from a mean (4,) and covariance (4, 4); order (w_x, w_xdot, w_theta, w_thetadot)."""
    mean = _prior_array(mean, (B.N_INPUTS,), "mean")
    cov = _prior_array(cov, (B.N_INPUTS, B.N_INPUTS), "cov")
    prior = B.Prior()
    with np.errstate(over="ignore"):
        for i in range(B.N_INPUTS):
            prior.mean[i] = float(mean[i])
            for j in range(B.N_INPUTS):
                prior.cov[i][j] = float(cov[i, j])
    return prior


def prior_from_dict(data: Mapping[str, Any] | None) -> B.Prior | None:
    if data is None:
        return None
    if not isinstance(data, Mapping) or set(data) != {"mean", "cov"}:
        raise ConfigError(B.ERR_BAD_PRIOR, f"prior must be null or {{\"mean\": [4], \"cov\": [4][4]}}, got {_short(data)}")
    return make_prior(data["mean"], data["cov"])


def check_prior(prior: B.Prior) -> None:
    """Prior validation is the C library's (icoac_prior_check, also run by icoac_init)."""
    B.check_status(B.lib.icoac_prior_check(ctypes.byref(prior)), "prior")


def _resolve(name: Any) -> str:
    if not isinstance(name, str) or name not in ALL_FIELDS or name == "reserved":
        valid = ", ".join(n for n in ALL_FIELDS if n != "reserved")
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"unknown parameter {_short(name)}; valid names: {valid}")
    return name


def build_config(overrides: Mapping[str, Any] | None = None, condition: str | None = None,
                 prior: B.Prior | None = None, check: bool = True) -> RunConfig:
    """C defaults, then the condition's overrides, then ``overrides`` by field name; validated by C."""
    if overrides is not None and not isinstance(overrides, Mapping):
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"overrides must be a mapping name -> value, got {_short(overrides)}")
    if prior is not None and not isinstance(prior, B.Prior):
        raise ConfigError(B.ERR_BAD_PRIOR, f"prior must be an icoac_prior_t, got {type(prior).__name__}")
    cfg = RunConfig(prior=prior)
    B.lib.icoac_config_default(ctypes.byref(cfg.controller))
    B.lib.icoac_sim_plant_default(ctypes.byref(cfg.plant))
    B.lib.icoac_sim_run_default(ctypes.byref(cfg.run))
    merged: dict[str, Any] = {}
    if condition is not None:
        if not isinstance(condition, str) or condition not in CONDITIONS:
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                              f"unknown condition {_short(condition)}; valid: {', '.join(CONDITIONS)}")
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


_GROUP_FIELDS = {"controller": CONTROLLER_FIELDS, "plant": PLANT_FIELDS, "run": RUN_FIELDS}


def config_from_dict(data: Mapping[str, Any], check: bool = True) -> RunConfig:
    """Inverse of RunConfig.to_dict. Groups may be partial (missing fields keep the C default);
    a field in the wrong group, an unknown group or a malformed value raises ConfigError."""
    if not isinstance(data, Mapping):
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"configuration must be a mapping, got {_short(data)}")
    unknown = [k for k in data if k not in ("controller", "plant", "run", "prior")]
    if unknown:
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                          f"unknown configuration group {_short(unknown[0])}; valid: controller, plant, run, prior")
    overrides: dict[str, Any] = {}
    for group, names in _GROUP_FIELDS.items():
        values = data.get(group)
        if values is None:
            continue
        if not isinstance(values, Mapping):
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"configuration group {group!r} must be a mapping, got {_short(values)}")
        for name, value in values.items():
            if name == "reserved" and group == "plant":
                if not (isinstance(value, int) and not isinstance(value, bool) and value == 0):
                    raise ConfigError(B.SIM_ERR_BAD_PLANT, f"plant parameter reserved must be 0, got {_short(value)}")
                continue
            if name not in names:
                _resolve(name)  # unknown names list the valid ones
                raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"{_short(name)} is a {_group(name)} parameter, not a {group} one")
            overrides[name] = value
    return build_config(overrides, prior=prior_from_dict(data.get("prior")), check=check)
