# SPDX-License-Identifier: Apache-2.0
"""Configurations: C defaults plus overrides by field name, validated by the C check functions.

Names. The name of a controller field is its member designator in icoac_config_t, "group.field"
(``mode``, ``policy.gain``, ``ico.timing``, ``critic.range``, ``actor.noise_std``); plant and run
fields keep their member names (``dt``, ``integrator``, ``max_trials``). Every record is written
with them, the controller nested by group.
"""
from __future__ import annotations

import ctypes
import difflib
import json
import math
import re
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, literals, options
from icoac.core.options import CART_POLE
from icoac.core.plants import PLANTS
from icoac.core.plants import spec as plant_spec
from icoac.core.registry import CONDITIONS, REGISTRY
from icoac.core.signs import derive_input_signs
from icoac.core.binding import ConfigError
from icoac.core.errors import UsageError

GROUPS = ("controller", "plant", "run")
CONTROLLER_GROUPS = tuple(name for name, ctype in B.Config._fields_ if issubclass(ctype, ctypes.Structure))

# Canonical names, in C order: the rows of the C parameter table (icoac_params.h, the run's rows).
CONTROLLER_FIELDS = tuple(B.params_of("icoac_config_t"))
# The default plant's parameters (its registry model's: its C descriptor's, then dt and integrator);
# another plant's go by its own names (plant_params).
PLANT_FIELDS = tuple(p["name"] for p in B.plant_info(CART_POLE)["params"]) + ("dt", "integrator")
RUN_FIELDS = tuple(B.params_of("icoac_sim_run_t"))
ALL_FIELDS = CONTROLLER_FIELDS + PLANT_FIELDS + RUN_FIELDS
_GROUP_OF = {**{n: "controller" for n in CONTROLLER_FIELDS}, **{n: "plant" for n in PLANT_FIELDS},
             **{n: "run" for n in RUN_FIELDS}}

# ICO's input signs: derived from the plant (icoac.core.signs) unless a layer gives them; one number
# sets every input's.
SIGN_FIELD = "task.input_sign"

# Symbolic values of the switches (values from the C constant table) and the 0/1 flags.
ENUMS: dict[str, dict[str, int]] = {
    "mode": B.MODES,
    "policy.reflex_mode": B.REFLEX_MODES,
    "ico.timing": B.ICO_TIMINGS,
    "actor.update": B.ACTOR_UPDATES,
    "task.late_source": B.LATE_SOURCES,
    "task.rule_side": B.RULE_SIDES,
    "integrator": B.INTEGRATORS,
}
BOOLS = tuple(name for name, row in B.PARAMS.items() if row["check"] == "flag")
_BOOL_NAMES = {"true": 1, "false": 0, "on": 1, "off": 0, "yes": 1, "no": 0, "1": 1, "0": 0}

# Every field each condition sets over the C defaults (icoac.core.registry defines them).
CONDITION_OVERRIDES: dict[str, dict[str, Any]] = {c.name: c.config_overrides() for c in REGISTRY.values()}
assert {c.mode for c in REGISTRY.values()} <= set(B.MODES), B.MODES


# Named configurations: --set items applied before the command's own --set. "literal" restores the
# paper's literal reading where the defaults were chosen by the learner sweeps (docs/results.md).
NAMED_CONFIGURATIONS: dict[str, tuple[str, ...]] = {
    "default": (),
    "literal": ("actor.update=posterior", "actor.noise_std=1", "actor.scale=0.5", "actor.likelihood_std=0",
                "actor.batch=0", "actor.explore_ticks=0", "critic.quirks=0"),
}
assert tuple(NAMED_CONFIGURATIONS) == options.CONFIGURATION_NAMES


def named_sets(name: str, sets: Iterable[str] | None = None) -> list[str]:
    """The --set items of a named configuration, then ``sets``."""
    if name not in NAMED_CONFIGURATIONS:
        raise UsageError(f"unknown configuration {_short(name)}; valid: {', '.join(NAMED_CONFIGURATIONS)}")
    return list(NAMED_CONFIGURATIONS[name]) + list(sets or [])


def _short(value: Any, limit: int = 60) -> str:
    """repr of a value, shortened for one-line messages."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def canonical(name: Any, plant: str = CART_POLE) -> str:
    """``name`` if it names a parameter; ConfigError (listing the valid names, the plant's own
    parameters and task knobs among them) for anything else."""
    if isinstance(name, str) and name in _GROUP_OF:
        return name
    valid = list(ALL_FIELDS)
    if plant != CART_POLE:
        valid = [n for n in valid if _GROUP_OF[n] != "plant"] + sorted(plant_params(plant)) + sorted(task_knobs(plant))
    hint = ""
    if isinstance(name, str):
        by_part = {**{n.rpartition(".")[2]: n for n in valid}, **{n: n for n in valid}}
        close = difflib.get_close_matches(name, list(by_part), n=1)  # by full name or by field
        hint = f" (did you mean {by_part[close[0]]}?)" if close else ""
    raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                      f"unknown parameter {_short(name)}{hint}; valid names: {', '.join(valid)} "
                      f"(python -m icoac params{'' if plant == CART_POLE else ' --plant ' + plant})")


def group_of(name: str) -> str:
    """'controller', 'plant' or 'run' of a canonical name."""
    return _GROUP_OF[name]


# -- fields of the ctypes structures, by canonical name ------------------------------------------------
def _owner(struct: ctypes.Structure, name: str) -> tuple[ctypes.Structure, str]:
    """(structure holding the member, member name) of a dotted name."""
    *path, leaf = name.split(".")
    for part in path:
        struct = getattr(struct, part)
    return struct, leaf


def _ctype(struct: ctypes.Structure, name: str):
    owner, leaf = _owner(struct, name)
    return dict(owner._fields_)[leaf]


def _get(struct: ctypes.Structure, name: str):
    owner, leaf = _owner(struct, name)
    value = getattr(owner, leaf)
    if isinstance(value, ctypes.Array):
        return [list(v) if isinstance(v, ctypes.Array) else v for v in value]
    return value


def _real_out(value: float) -> float:
    """icoac_real_t value as a JSON-friendly float (float32 printed to its shortest round trip)."""
    if B.real_dtype == np.float32:
        return float(np.format_float_positional(np.float32(value), unique=True, trim="-")) \
            if math.isfinite(value) else float(value)
    return float(value)


def _value_out(name: str, ctype, value) -> Any:
    """A field's value as written to JSON: symbolic switches, booleans, shortest reals."""
    if isinstance(value, list):
        return [_value_out(name, ctype._type_, v) for v in value]
    if ctype is B.c_real:
        value = _real_out(value)
    elif ctype is ctypes.c_double:
        value = float(value)
    else:
        value = int(value)
    if name in ENUMS:
        reverse = {v: k for k, v in ENUMS[name].items()}
        return reverse.get(value, value)
    if name in BOOLS:
        return bool(value)
    return value


def _struct_to_dict(struct: ctypes.Structure, prefix: str = "") -> dict[str, Any]:
    """Nested dict of a structure (nested structures as sub-dicts), canonical names' last parts as keys."""
    out: dict[str, Any] = {}
    for name, ctype in struct._fields_:
        value = getattr(struct, name)
        if isinstance(value, ctypes.Structure):
            out[name] = _struct_to_dict(value, f"{prefix}{name}.")
        else:
            out[name] = _value_out(prefix + name, ctype, _get(struct, name))
    return out


# -- parsing of values ---------------------------------------------------------------------------------
_INT_LIMITS = {ctypes.c_int32: (-2 ** 31, 2 ** 31 - 1), ctypes.c_int64: (-2 ** 63, 2 ** 63 - 1)}


# The status C gives a bad value of each field: the parameter table's (a plant's parameters:
# icoac_sim_model_check's ICOAC_SIM_ERR_BAD_PLANT).
_FIELD_STATUS = {**{name: row["status"] for name, row in B.PARAMS.items()},
                 **{name: B.SIM_ERR_BAD_PLANT for name in PLANT_FIELDS}}


def _bad(name: str, message: str) -> ConfigError:
    return ConfigError(_FIELD_STATUS[name], f"{group_of(name)} parameter {name}: {message}")


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def _parse_int(name: str, ctype, value: Any) -> int:
    """An integer for an int32/int64 field, range-checked so that ctypes never truncates it."""
    if isinstance(value, str):
        try:
            value = literals.integer(value)
        except literals.NumberError as exc:
            raise _bad(name, f"bad value {_short(value)}, which {exc}; expected an integer") from None
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
            value = literals.real(value)
        except literals.NumberError as exc:
            raise _bad(name, f"value {_short(value)} {exc}") from None
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
                raise _bad(name, f"bad value {_short(value)}; valid: {', '.join(names)}")
            return names[key]
        if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
            return _parse_int(name, ctypes.c_int32, value)  # value range checked by C
        raise _bad(name, f"bad value {_short(value)}; valid: {', '.join(names)}")
    if name in BOOLS:
        if isinstance(value, (bool, np.bool_)):
            return int(value)
        if isinstance(value, str) and value.strip().lower() in _BOOL_NAMES:
            return _BOOL_NAMES[value.strip().lower()]
        if isinstance(value, (int, np.integer)) and int(value) in (0, 1):
            return int(value)
        raise _bad(name, f"bad value {_short(value)}; expected true/false")
    if ctype in _INT_LIMITS:
        return _parse_int(name, ctype, value)
    return _parse_real(name, ctype, value)  # range checked by C


def _set_field(struct: ctypes.Structure, name: str, value: Any) -> None:
    """Set a field by canonical name (relative to struct), parsing and range-checking the value."""
    owner, leaf = _owner(struct, name)
    ctype = dict(owner._fields_)[leaf]
    if issubclass(ctype, ctypes.Array):
        if isinstance(value, str):
            parsed = parse_value(value)
            value = parsed if not isinstance(parsed, str) else \
                [v for v in value.replace("[", "").replace("]", "").split(",") if v.strip()]
        if isinstance(value, np.ndarray):
            value = value.tolist()
        if name == SIGN_FIELD and _is_number(value):
            value = [value] * ctype._length_  # one sign for every input: --set task.input_sign=1
        # every entry, or the leading ones a task uses (the others keep their values): the
        # cart-pole's N_INPUTS of an input array, any number of a rule array (task.n_rules)
        sizes = (set(range(1, ctype._length_ + 1)) if name.startswith("task.rule_") else
                 {B.N_INPUTS, ctype._length_})
        if not isinstance(value, (list, tuple)) or len(value) not in sizes:
            expected = " or ".join(str(n) for n in sorted(sizes)) if len(sizes) < 3 else f"1 to {ctype._length_}"
            raise _bad(name, f"bad value {_short(value)}; expected {expected} numbers")
        array = getattr(owner, leaf)
        for i, v in enumerate(value):
            array[i] = _parse_scalar(name, ctype._type_, v)
    else:
        setattr(owner, leaf, _parse_scalar(name, ctype, value))


def parse_value(text: str) -> Any:
    """Value of a ``--set name=value`` option: JSON if it parses, its numbers read by
    icoac.core.literals, else the raw string (which the field's parser then reads, or refuses:
    ``1e-400`` is no JSON number here, and no number of a field either)."""
    try:
        return json.loads(text, parse_float=literals.real)
    except (ValueError, RecursionError):
        return text


def given_twice(name: str, first: str, second: str) -> UsageError:
    """The error of a parameter set by two options (or twice by one): nothing given is ignored."""
    return UsageError(f"{first} and {second} both set {name}; give it once")


def plant_params(plant: str) -> set[str]:
    """The names --set takes for a registry plant's model: its parameters, dt and integrator."""
    return {p["name"] for p in B.plant_info(B.plant_index(plant))["params"]} | {"dt", "integrator"}


def task_knobs(plant: str) -> set[str]:
    """The names --set takes for the knobs of a registry plant's task (its C file)."""
    B.plant_index(plant)  # an unknown name: the registry's message
    return set(PLANTS[plant].knobs)


def parse_sets(items: Iterable[str] | None, option: str = "--set", plant: str = CART_POLE) -> dict[str, Any]:
    """``NAME=VALUE`` strings -> {canonical name: value} (a plant's parameters by their own names).
    UsageError for an item without '=' and for a field given twice (under any of its names);
    ConfigError for an unknown name."""
    out: dict[str, Any] = {}
    given: dict[str, str] = {}
    own = plant_params(plant) | task_knobs(plant)
    for item in items or []:
        if "=" not in item:
            raise UsageError(f"{option} expects name=value, got {_short(item)}")
        name, value = item.split("=", 1)
        name = name.strip() if name.strip() in own else canonical(name.strip(), plant)
        if name in given:
            raise given_twice(name, f"{option} {given[name]}", f"{option} {item[:60]}")
        given[name] = item[:60]
        out[name] = parse_value(value.strip())
    return out


def command_overrides(configuration: str, sets: Iterable[str] | None,
                      flags: Mapping[str, tuple[str, Any]] | None = None, plant: str = CART_POLE) -> dict[str, Any]:
    """The overrides of a command: the items of the named ``configuration``, replaced field by field
    by the ``sets`` items (--set), and the options that set one field each (``flags``: option ->
    (canonical name, value, None when not given)). A field set by --set and by its own option is
    a UsageError naming both, as is a field given twice by --set."""
    user = parse_sets(sets, plant=plant)
    for option, (name, value) in (flags or {}).items():
        if value is None:
            continue
        if name in user:
            raise given_twice(name, f"{option} {value}", f"--set {name}")
        user[name] = value
    return {**parse_sets(named_sets(configuration)), **user}


# -- configurations ------------------------------------------------------------------------------------
def _default_model() -> B.Model:
    model = B.Model()
    B.check_status(B.lib.icoac_sim_model_default(ctypes.byref(model), B.CART_POLE), "plant model")
    return model


@dataclass
class RunConfig:
    """Controller, plant and run parameters of one benchmark, plus an optional prior. The plant is
    a registry plant's model (docs/plants.md), the cart-pole's by default."""
    controller: B.Config = field(default_factory=B.Config)
    model: B.Model = field(default_factory=_default_model)
    run: B.Run = field(default_factory=B.Run)
    prior: B.Prior | None = None

    @property
    def plant_name(self) -> str:
        return B.plant_info(self.model.plant)["name"]

    @property
    def n_inputs(self) -> int:
        """The task's inputs n: the leading n entries of the weights and the prior are used."""
        return int(self.controller.task.n_inputs)

    def engine_model(self) -> B.Model:
        """The model the engine runs."""
        return self.model

    def to_dict(self) -> dict[str, Any]:
        """The record of run.json: canonical names, the controller nested by group; the plant by
        its name, dt, integrator and parameters."""
        return {"controller": _struct_to_dict(self.controller), "plant": model_to_dict(self.model),
                "run": _struct_to_dict(self.run),
                "prior": prior_to_dict(self.prior, self.n_inputs) if self.prior is not None else None}

    def flat(self) -> dict[str, Any]:
        """{name: value as in to_dict} of every parameter: the controller's and the run's by canonical
        name, the plant's by its own (its parameters, dt, integrator), as build_config takes them."""
        record = model_to_dict(self.model)
        plant = {name: value for name, value in record.items() if name not in ("name", "dt", "integrator")}
        plant.update(dt=record["dt"], integrator=record["integrator"])  # the order of PLANT_FIELDS
        out = {name: _value_out(name, _ctype(self._struct(name), name), _get(self._struct(name), name))
               for name in CONTROLLER_FIELDS}
        out.update(plant)
        out.update({name: _value_out(name, _ctype(self.run, name), _get(self.run, name)) for name in RUN_FIELDS})
        return out

    def _struct(self, name: str) -> ctypes.Structure:
        return getattr(self, group_of(name))

    def check(self) -> "RunConfig":
        """Validate with the C check functions; raise ConfigError carrying the C message and naming
        the field the C check rejects (icoac_config_check_field for the controller)."""
        bad = ctypes.c_char_p()
        status = int(B.lib.icoac_config_check_field(ctypes.byref(self.controller), ctypes.byref(bad)))
        if status != B.OK:
            designator = bad.value.decode() if bad.value else None
            text = B.status_str(status) + (f"; rejected: {_designated(self.controller, designator)}"
                                           if designator else "")
            if status not in B.CONFIG_STATUSES:
                B.check_status(status, "controller config")
            raise ConfigError(status, text, context="controller config")
        check_model(self.model)
        n_state = geometry.of(self.plant_name).n_inputs
        if self.n_inputs != n_state:  # the engine's refusal, said before a run
            raise ConfigError(B.SIM_ERR_BAD_PLANT, f"task.n_inputs={self.n_inputs}: plant {self.plant_name} has "
                              f"{n_state} state components, one input each",
                              context="plant config")
        for label, struct, check_fn, default_fn in (
                ("run config", self.run, B.lib.icoac_sim_run_check, B.lib.icoac_sim_run_default),):
            status = int(check_fn(ctypes.byref(struct)))
            if status != B.OK:
                culprits = _culprits(struct, check_fn, default_fn)
                text = B.status_str(status) + (f"; rejected: {culprits}" if culprits else "")
                if status not in B.CONFIG_STATUSES:
                    B.check_status(status, label)
                raise ConfigError(status, text, context=label)
        if self.prior is not None:
            check_prior(self.prior, self.n_inputs)
        return self


# -- registry plants -----------------------------------------------------------------------------------
def model_to_dict(model: B.Model) -> dict[str, Any]:
    """A model's record: plant name, dt, integrator, then its parameters by name."""
    info = B.plant_info(model.plant)
    return {"name": info["name"], "dt": model.dt, "integrator": _value_out("integrator", ctypes.c_int32, model.integrator),
            **{p["name"]: model.param[i] for i, p in enumerate(info["params"])}}


def check_model(model: B.Model) -> None:
    """The C check of a model, and that this controller build observes the plant (its state
    components are the controller's inputs); ConfigError naming the plant otherwise."""
    info = B.plant_info(model.plant)
    status = int(B.lib.icoac_sim_model_check(ctypes.byref(model)))
    if status != B.OK:
        # the culprits: each value the C check refuses when set alone on the plant's defaults
        bad = []
        for i, key in [(i, p["name"]) for i, p in enumerate(info["params"])] + [(None, "dt"), (None, "integrator")]:
            probe = B.Model()
            B.lib.icoac_sim_model_default(ctypes.byref(probe), model.plant)
            value = model.param[i] if i is not None else getattr(model, key)
            if i is None:
                setattr(probe, key, value)
            else:
                probe.param[i] = value
            if int(B.lib.icoac_sim_model_check(ctypes.byref(probe))) != B.OK:
                rng = f" (valid: 0 or a normal number in [{info['params'][i]['min']:g}, " \
                      f"{info['params'][i]['max']:g}])" if i is not None else ""
                bad.append(f"{key}={value!r}{rng}")
        raise ConfigError(status, f"{B.status_str(status)}; rejected: plant {info['name']}: "
                                  f"{', '.join(bad) or 'parameters'}", context="plant config")
    n = len(info["state"])
    if n > B.MAX_INPUTS or info["observed"][:n] != list(range(n)):
        raise ConfigError(B.SIM_ERR_BAD_PLANT,
                          f"plant {info['name']} has {n} state components; this controller build takes "
                          f"at most {B.MAX_INPUTS} inputs, one per component in order", context="plant config")



def build_model(name: str, values: Mapping[str, Any]) -> B.Model:
    """The registry plant called name with its defaults, then values by parameter name (and dt,
    integrator), parsed as --set values are; unknown names raise ConfigError listing the valid."""
    index = B.plant_index(name)
    info = B.plant_info(index)
    names = [p["name"] for p in info["params"]]
    model = B.Model()
    B.check_status(B.lib.icoac_sim_model_default(ctypes.byref(model), index), "plant model")
    for key, value in values.items():
        if key in ("dt", "integrator"):  # parsed as the cart-pole's fields of these names
            setattr(model, key, _parse_scalar(key, dict(B.Model._fields_)[key], value))
        elif key in names:
            model.param[names.index(key)] = _parse_param(name, key, value)
        else:
            raise ConfigError(B.SIM_ERR_BAD_PLANT, f"plant {name} has no parameter {_short(key)}; valid: "
                                                  f"{', '.join(names + ['dt', 'integrator'])}")
    return model


def _parse_param(plant: str, key: str, value: Any) -> float:
    """A finite number for a plant parameter (its range is the C check's)."""
    try:
        number = literals.real(value) if isinstance(value, str) else float(value) if _is_number(value) else None
    except (literals.NumberError, OverflowError):
        number = None
    if number is None or not math.isfinite(number):
        raise ConfigError(B.SIM_ERR_BAD_PLANT, f"plant {plant} parameter {key}: bad value {_short(value)}; "
                                               "expected a finite number")
    return number


_DESIGNATOR = re.compile(r"([a-z_.]+)((?:\[[0-9]+\])*)")


def _designated(controller: B.Config, designator: str) -> str:
    """'critic.range[0]=0.0': the member C names, with its value."""
    m = _DESIGNATOR.fullmatch(designator)
    if not m or m.group(1) not in CONTROLLER_FIELDS:
        return designator
    value = _value_out(m.group(1), _ctype(controller, m.group(1)), _get(controller, m.group(1)))
    for index in re.findall(r"\[([0-9]+)\]", m.group(2)):
        if isinstance(value, list) and int(index) < len(value):
            value = value[int(index)]
    valid = B.range_text(B.PARAMS[m.group(1)], tuple(ENUMS[m.group(1)]) if m.group(1) in ENUMS else None)
    return f"{designator}={value!r} (valid: {valid})"


def _culprits(struct: ctypes.Structure, check_fn, default_fn) -> str:
    """The fields of a plant or run the C check rejects: those that differ from the C default and
    fail the check on their own (or, when only a combination fails, every field that differs)."""
    def fresh():
        out = type(struct)()
        default_fn(ctypes.byref(out))
        return out

    ref = fresh()
    differ = [name for name, _ in struct._fields_
              if not _same(_get(struct, name), _get(ref, name))]
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


# -- priors --------------------------------------------------------------------------------------------
def prior_to_dict(prior: B.Prior, n: int) -> dict[str, Any]:
    """A prior's leading n entries (a task of n inputs; the others are unused, 0)."""
    return {"mean": [_real_out(v) for v in prior.mean[:n]],
            "cov": [[_real_out(v) for v in row[:n]] for row in prior.cov[:n]]}


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
    """icoac_prior_t from a mean (n,) and covariance (n, n), n the task's inputs (1 to MAX_INPUTS;
    the cart-pole's order w_x, w_xdot, w_theta, w_thetadot); the entries after n are 0."""
    n = len(mean) if isinstance(mean, (list, tuple, np.ndarray)) else 0
    if not 1 <= n <= B.MAX_INPUTS:
        raise ConfigError(B.ERR_BAD_PRIOR, f"prior mean: expected 1 to {B.MAX_INPUTS} numbers, got {_short(mean)}")
    mean = _prior_array(mean, (n,), "mean")
    cov = _prior_array(cov, (n, n), "cov")
    prior = B.Prior()
    with np.errstate(over="ignore"):
        for i in range(n):
            prior.mean[i] = float(mean[i])
            for j in range(n):
                prior.cov[i][j] = float(cov[i, j])
    return prior


def prior_from_dict(data: Mapping[str, Any] | None) -> B.Prior | None:
    if data is None:
        return None
    if not isinstance(data, Mapping) or set(data) != {"mean", "cov"}:
        raise ConfigError(B.ERR_BAD_PRIOR, f"prior must be null or {{\"mean\": [n], \"cov\": [n][n]}}, got {_short(data)}")
    return make_prior(data["mean"], data["cov"])


def check_prior(prior: B.Prior, n: int) -> None:
    """Prior validation is the C library's (icoac_prior_check of the leading n, also run by icoac_init)."""
    B.check_status(B.lib.icoac_prior_check(ctypes.byref(prior), n), "prior")


# -- building and reading configurations ---------------------------------------------------------------
def build_config(overrides: Mapping[str, Any] | None = None, condition: str | None = None,
                 prior: B.Prior | None = None, check: bool = True, plant: str = CART_POLE,
                 derive_signs: bool = True) -> RunConfig:
    """C defaults and the plant's task (its C file, written from its knobs: their defaults, or the
    overrides named after them), then the condition's overrides and the plant's settings of that
    learner, then ``overrides`` by field name (a later name for the same field wins); validated by
    C. A registry plant takes the overrides named after its parameters (and dt, integrator). With
    derive_signs, task.input_sign comes from the plant's LQR gain (icoac.core.signs) unless the plant's
    task, the condition or ``overrides`` gives it (--set task.input_sign=1: the paper's signs)."""
    if overrides is not None and not isinstance(overrides, Mapping):
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"overrides must be a mapping name -> value, got {_short(overrides)}")
    if prior is not None and not isinstance(prior, B.Prior):
        raise ConfigError(B.ERR_BAD_PRIOR, f"prior must be an icoac_prior_t, got {type(prior).__name__}")
    cfg = RunConfig(prior=prior)
    spec = plant_spec(plant)
    items = list((overrides or {}).items())
    knobs = {name: value for name, value in items if name in spec.knobs}
    spec.task_config(cfg.controller, knobs)  # the C defaults, then the plant's task from its knobs
    task_signs = list(cfg.controller.task.input_sign) != [1] * B.MAX_INPUTS  # the task gives its signs
    B.lib.icoac_sim_run_default(ctypes.byref(cfg.run))
    condition_items: list[tuple[Any, Any]] = []
    if condition is not None:
        if not isinstance(condition, str) or condition not in CONDITION_OVERRIDES:
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                              f"unknown condition {_short(condition)}; valid: {', '.join(CONDITIONS)}")
        condition_items = list(CONDITION_OVERRIDES[condition].items())
    params = plant_params(plant)
    cfg.model = build_model(plant, {name: value for name, value in items if name in params})
    items = [(name, value) for name, value in items if name not in params and name not in knobs]

    given = set()

    def set_items(pairs: list[tuple[Any, Any]]) -> None:
        for name, value in pairs:
            name = canonical(name, plant)
            if group_of(name) == "plant":
                raise ConfigError(B.SIM_ERR_BAD_PLANT, f"plant {plant} has no parameter {name}")
            _set_field(cfg._struct(name), name, value)
            given.add(name)

    set_items(condition_items)
    if condition is not None:  # the plant's settings of the learner, over the condition's
        spec.learner_config(REGISTRY[condition].base, cfg.controller)
    set_items(items)
    if derive_signs and SIGN_FIELD not in given and not task_signs:
        _derive_signs(cfg)
    if check:
        cfg.check()
    return cfg


def _derive_signs(cfg: RunConfig) -> None:
    """task.input_sign of cfg from its plant's LQR gain (icoac.core.signs), when the rest of cfg is
    valid (an invalid one is refused by its check, naming the field)."""
    try:
        cfg.check()
    except B.IcoacError:
        return
    signs = derive_input_signs(cfg)
    for i, sign in enumerate(signs or ()):
        cfg.controller.task.input_sign[i] = sign


def _controller_items(values: Mapping[str, Any], prefix: str = ""):
    """(name, value) of a controller dict: nested groups ({"policy": {"gain": 10}}), dotted names
    ("policy.gain"); names not checked yet."""
    for key, value in values.items():
        if not isinstance(key, str):
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"configuration key {_short(key)} is not a name")
        name = prefix + key
        if name in CONTROLLER_GROUPS:
            if not isinstance(value, Mapping):
                raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                                  f"controller group {name!r} must be a mapping, got {_short(value)}")
            yield from _controller_items(value, name + ".")
        else:
            yield name, value


def config_from_dict(data: Mapping[str, Any], check: bool = True) -> RunConfig:
    """Inverse of RunConfig.to_dict. Groups may be partial (missing fields keep their default, as
    in build_config: a run record is checked complete against icoac.core.schema first, so its input
    signs are its own); a field in the wrong group, an unknown group or a malformed value raises
    ConfigError."""
    if not isinstance(data, Mapping):
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"configuration must be a mapping, got {_short(data)}")
    unknown = [k for k in data if k not in GROUPS + ("prior",)]
    if unknown:
        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                          f"unknown configuration group {_short(unknown[0])}; valid: {', '.join(GROUPS)}, prior")
    overrides: list[tuple[str, Any]] = []
    plant = CART_POLE
    for group in GROUPS:
        values = data.get(group)
        if values is None:
            continue
        if not isinstance(values, Mapping):
            raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"configuration group {group!r} must be a mapping, got {_short(values)}")
        if group == "plant":  # by name; a partial configuration without one is the cart-pole's
            plant = values.get("name", CART_POLE)
            if not isinstance(plant, str):
                raise ConfigError(B.SIM_ERR_BAD_PLANT, f"plant name must be a string, got {_short(plant)}")
            own = plant_params(plant) | task_knobs(plant)
            for name, value in values.items():
                if name != "name":
                    if name not in own and group_of(canonical(name)) != "plant":
                        raise ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"{_short(canonical(name))} is a "
                                          f"{group_of(canonical(name))} parameter, not a plant one")
                    overrides.append((name, value))
            continue
        items = _controller_items(values) if group == "controller" else values.items()
        for name, value in items:
            name = canonical(name)
            if group_of(name) != group:
                raise ConfigError(B.SIM_ERR_BAD_ARGUMENT,
                                  f"{_short(name)} is a {group_of(name)} parameter, not a {group} one")
            overrides.append((name, value))
    cfg = build_config(dict(overrides), prior=prior_from_dict(data.get("prior")), check=False, plant=plant)
    return cfg.check() if check else cfg
