# SPDX-License-Identifier: Apache-2.0
"""ctypes binding of libicoac_sim (sim_host/include/icoac_sim/icoac_sim.h, firmware/include/icoac/*.h).

C is the single source of every number this module exposes: at import it reads the library's
constant table (icoac_sim_constants: sizes, enum values, statuses, outcomes, progress indices,
grid geometry) and its field table (icoac_sim_fields: offset and size of every member of every
public struct) and its parameter table (icoac_sim_param_table: every controller and run parameter
with its type, unit, range, default, modes, tier, status and description, PARAMS). The mirrors of
icoac_config_t and icoac_sim_run_t are built from the parameter table; every ctypes mirror (and the
cell numpy dtype) is checked against the field table - same fields, same offsets and sizes, same
total size - so that a stale or mismatched library fails loudly with a LibraryError naming the field. The controller state is opaque
storage of icoac_sizeof_state() bytes, read through icoac_get_posterior / icoac_get_counters.
Every prototype is declared once here.
"""
from __future__ import annotations

import ctypes
import os
from pathlib import Path
from typing import Any, Mapping, Union

import numpy as np
from numpy.ctypeslib import ndpointer

from icoac.core.errors import HarnessError, LibraryError

PACKAGE_DIR = Path(__file__).resolve().parents[1]   # harness/icoac in a checkout
REPO_ROOT = PACKAGE_DIR.parents[1]
LIBRARY_ENV = "ICOAC_SIM_LIBRARY"
# The library of an installed package (a wheel: `pip install .`, pyproject.toml); absent in a checkout.
PACKAGE_LIBRARY = PACKAGE_DIR / "lib" / "libicoac_sim.so"
BUILD_INFO = PACKAGE_LIBRARY.parent / "build_info.json"   # the commit the package was built from
# The development build (`make build`, preset release) of the checkout the package runs from.
DEFAULT_LIBRARY = REPO_ROOT / "build" / "release" / "sim_host" / "libicoac_sim.so"

# The ABI versions the mirrors below are written for (everything else is read from the library).
ABI_VERSION = 10
SIM_ABI_VERSION = 10


class IcoacError(HarnessError):
    """A non-OK status from the C library; ``.status`` is the code, the message is the C text."""

    def __init__(self, status: int, message: str | None = None, context: str | None = None):
        self.status = int(status)
        self.c_message = status_str(self.status)
        text = message if message is not None else self.c_message
        if context:
            text = f"{context}: {text}"
        super().__init__(text)

    def __reduce__(self):  # picklable (a Dask worker sends it back to the client), class and text kept
        return _restore_error, (type(self), self.status, str(self))


def _restore_error(cls: type, status: int, text: str) -> IcoacError:
    err = cls.__new__(cls)
    HarnessError.__init__(err, text)
    err.status = int(status)
    err.c_message = status_str(err.status)
    return err


class ConfigError(IcoacError):
    """A configuration, prior, plant, run or argument rejected (a bad-parameter status of the C
    library, or the status C would give for a value rejected on the Python side), or a bad name."""

    def __init__(self, status: int | None = None, message: str | None = None, context: str | None = None):
        super().__init__(SIM_ERR_BAD_ARGUMENT if status is None else status, message, context)


class Cancelled(IcoacError):
    """The cancel flag was raised (ICOAC_SIM_CANCELLED); finished cells are kept."""


def _library_path() -> tuple[Path, str]:
    """(path, source) of the library to load, source one of "env", "package", "build": the
    ICOAC_SIM_LIBRARY path when the variable is set (even if nothing is there); else the
    package's own library when installed; else the development build of the checkout."""
    env = os.environ.get(LIBRARY_ENV)
    if env:
        return Path(env), "env"
    if PACKAGE_LIBRARY.is_file():
        return PACKAGE_LIBRARY, "package"
    return DEFAULT_LIBRARY, "build"


def _load(path: Path, source: str) -> ctypes.CDLL:
    if not path.is_file():
        where = (f"{LIBRARY_ENV}={path}" if source == "env" else
                 f"{PACKAGE_LIBRARY} (installed package) nor at {path} (development build)")
        raise LibraryError(
            f"icoac_sim shared library not found at {where}; build it with `make build` "
            f"(or install the package with `pip install .`, or set {LIBRARY_ENV} to its path)")
    try:
        return ctypes.CDLL(str(path))
    except OSError as exc:  # pragma: no cover - depends on the system
        raise LibraryError(f"cannot load {path}: {exc}") from exc


LIBRARY_PATH, LIBRARY_SOURCE = _library_path()
lib = _load(LIBRARY_PATH, LIBRARY_SOURCE)


def _stale(detail: str) -> LibraryError:
    fix = ("reinstall the package (`pip install .`)" if LIBRARY_SOURCE == "package" else
           "rebuild it with `make build`")
    return LibraryError(f"{LIBRARY_PATH} does not match the harness binding ({detail}); {fix}")


# -- ABI versions and sizes first ---------------------------------------------------------------
_SIZE_FUNCTIONS = ("icoac_abi_version", "icoac_sizeof_real", "icoac_sizeof_config", "icoac_sizeof_state",
                   "icoac_sizeof_input", "icoac_sizeof_output", "icoac_sizeof_prior",
                   "icoac_sim_abi_version", "icoac_sim_sizeof_run",
                   "icoac_sim_sizeof_cell")
for _name in _SIZE_FUNCTIONS:
    getattr(lib, _name).argtypes = []
    getattr(lib, _name).restype = ctypes.c_uint32

if lib.icoac_abi_version() != ABI_VERSION or lib.icoac_sim_abi_version() != SIM_ABI_VERSION:
    raise _stale(f"ABI versions icoac {lib.icoac_abi_version()}, icoac_sim {lib.icoac_sim_abi_version()}; "
                 f"the binding needs icoac {ABI_VERSION}, icoac_sim {SIM_ABI_VERSION}")


# -- the C tables ----------------------------------------------------------------------------------
class _Constant(ctypes.Structure):
    """icoac_sim_constant_t."""
    _fields_ = [("name", ctypes.c_char_p), ("value", ctypes.c_double)]


class _Field(ctypes.Structure):
    """icoac_sim_field_t."""
    _fields_ = [("type", ctypes.c_char_p), ("field", ctypes.c_char_p),
                ("offset", ctypes.c_uint32), ("size", ctypes.c_uint32)]


for _name, _row in (("icoac_sim_constants", _Constant), ("icoac_sim_fields", _Field)):
    getattr(lib, _name).argtypes = [ctypes.POINTER(ctypes.c_int32)]
    getattr(lib, _name).restype = ctypes.POINTER(_row)


def _table(fn) -> list:
    count = ctypes.c_int32(0)
    rows = fn(ctypes.byref(count))
    return [rows[i] for i in range(count.value)]


def _number(value: float) -> Union[int, float]:
    return int(value) if float(value).is_integer() else float(value)


# {C macro or enum name: value}, e.g. "ICOAC_MODE_RL": 1 (integral values as int).
CONSTANTS: dict[str, Union[int, float]] = {
    row.name.decode(): _number(row.value) for row in _table(lib.icoac_sim_constants)}

# {C type: {member designator: (offset, size)}}, e.g. "icoac_config_t": {"policy.gain": (24, 4), ...}.
FIELDS: dict[str, dict[str, tuple[int, int]]] = {}
for _row in _table(lib.icoac_sim_fields):
    FIELDS.setdefault(_row.type.decode(), {})[_row.field.decode()] = (int(_row.offset), int(_row.size))


class _ParamRow(ctypes.Structure):
    """icoac_sim_param_row_t."""
    _fields_ = [("type", ctypes.c_char_p), ("name", ctypes.c_char_p), ("group", ctypes.c_char_p),
                ("ctype", ctypes.c_char_p), ("dim", ctypes.c_char_p), ("check", ctypes.c_char_p),
                ("unit", ctypes.c_char_p), ("tier", ctypes.c_char_p), ("doc", ctypes.c_char_p),
                ("min", ctypes.c_double), ("max", ctypes.c_double), ("default", ctypes.c_double),
                ("modes", ctypes.c_uint32), ("status", ctypes.c_int32), ("offset", ctypes.c_uint32),
                ("size", ctypes.c_uint32)]


lib.icoac_sim_param_table.argtypes = [ctypes.POINTER(ctypes.c_int32)]
lib.icoac_sim_param_table.restype = ctypes.POINTER(_ParamRow)

# {canonical name: row} of every controller parameter (icoac_params.h) and run parameter
# (ICOAC_SIM_RUN_PARAMS), in struct order: type (its C struct), name, group, ctype, dim (scalar,
# inputs, rules), check, unit, tier, doc, min, max, default, modes (bit mask), status, offset, size.
PARAMS: dict[str, dict] = {}
for _row in _table(lib.icoac_sim_param_table):
    PARAMS[_row.name.decode()] = {
        **{k: getattr(_row, k).decode() for k in ("type", "name", "group", "ctype", "dim", "check", "unit",
                                                   "tier", "doc")},
        **{k: _number(getattr(_row, k)) for k in ("min", "max", "default")},
        **{k: int(getattr(_row, k)) for k in ("modes", "status", "offset", "size")}}


def params_of(c_type: str) -> dict[str, dict]:
    """The parameter rows of one C struct ("icoac_config_t", "icoac_sim_run_t"), in its order."""
    return {n: r for n, r in PARAMS.items() if r["type"] == c_type}


def _g(value: float) -> str:
    return f"{value:g}"


def range_text(row: Mapping[str, Any], choices: tuple[str, ...] | None = None) -> str:
    """A row's valid values in words, e.g. "[0, 10000]", "(0, 1]", "0 or [0.001, 1000]"."""
    lo, hi, check = row["min"], row["max"], row["check"]
    if check == "flag":
        return "true, false"
    if check == "choice":
        return ", ".join(choices) if choices else f"{lo} .. {hi}"
    if check == "sign":
        return f"{lo:+g}, {hi:+g}"
    if check == "index":
        return f"[{lo}, task.n_inputs)"
    if check == "at_least":
        return f">= {_g(lo)}"
    text = {"real_open_lo": "({}, {}]", "real_open_hi": "[{}, {})"}.get(check, "[{}, {}]").format(_g(lo), _g(hi))
    if check == "real_or_zero":
        return f"0 or {text}"
    if check == "units":
        return f"{text}, product <= {constant('ICOAC_MAX_CRITIC_UNITS')}"
    return text


def constant(name: str) -> Union[int, float]:
    """Value of a C constant from the library's table; LibraryError if the library lacks it."""
    try:
        return CONSTANTS[name]
    except KeyError:
        raise _stale(f"constant {name} missing from icoac_sim_constants") from None


def enum(prefix: str, members: tuple[str, ...] | None = None) -> dict[str, int]:
    """{symbolic name: value} of the C constants PREFIX + MEMBER (every constant with the prefix
    when members is None); the symbolic name is MEMBER in lower case, e.g. "ICOAC_MODE_RL" -> "rl"."""
    names = members if members is not None else tuple(
        n[len(prefix):] for n in CONSTANTS if n.startswith(prefix))
    out = {m.lower(): int(constant(prefix + m)) for m in names}
    if not out or len(set(out.values())) != len(out):
        raise _stale(f"enum {prefix}* is empty or has repeated values: {out}")
    return out


# The engine's plant is the cart-pole (the controller's cart-pole task): its 4 state variables
# are the inputs, the weights and the prior; the C structs have room for the build maxima.
N_INPUTS = int(constant("ICOAC_CARTPOLE_INPUTS"))
CRITIC_UNITS = int(constant("ICOAC_CARTPOLE_CRITIC_UNITS"))
MAX_INPUTS = int(constant("ICOAC_MAX_INPUTS"))
MAX_RULES = int(constant("ICOAC_MAX_RULES"))
INPUT_LATE = int(constant("ICOAC_INPUT_LATE"))
LATE_SOURCES = enum("ICOAC_LATE_", ("RULES", "SENSOR"))  # rules, sensor
RULE_SIDES = enum("ICOAC_RULE_", ("BELOW", "ABOVE"))     # below, above
STATE_SIZE = int(constant("ICOAC_STATE_SIZE"))
INPUT_TERMINAL = int(constant("ICOAC_INPUT_TERMINAL"))

# Switches: {symbolic name: value}.
MODES = enum("ICOAC_MODE_")                       # ico, rl, search
REFLEX_MODES = enum("ICOAC_REFLEX_")              # unit, gain
ICO_TIMINGS = enum("ICOAC_ICO_TIMING_")           # code, literal
ACTOR_UPDATES = enum("ICOAC_ACTOR_", ("POSTERIOR", "MEAN", "GRADIENT"))  # posterior, mean, gradient
INTEGRATORS = enum("ICOAC_SIM_", ("EULER", "RK4"))  # euler, rk4
MODE_ICO, MODE_RL, MODE_SEARCH = MODES["ico"], MODES["rl"], MODES["search"]
PARAM_MODES = enum("ICOAC_PARAM_", ("ICO", "RL", "SEARCH"))  # the modes column's bits: ico, rl, search
SEARCH_BATCH_MAX = int(constant("ICOAC_SEARCH_BATCH_MAX"))
EXPLORE_TICKS_MAX = int(constant("ICOAC_EXPLORE_TICKS_MAX"))

# Statuses (icoac_status_t, then icoac_sim_status_t).
OK = int(constant("ICOAC_OK"))
ERR_NULL = int(constant("ICOAC_ERR_NULL"))
ERR_NOT_INITIALISED = int(constant("ICOAC_ERR_NOT_INITIALISED"))
ERR_NONFINITE_INPUT = int(constant("ICOAC_ERR_NONFINITE_INPUT"))
ERR_NUMERIC = int(constant("ICOAC_ERR_NUMERIC"))
ERR_BAD_MODE = int(constant("ICOAC_ERR_BAD_MODE"))
ERR_BAD_SCALE = int(constant("ICOAC_ERR_BAD_SCALE"))
ERR_BAD_GAIN = int(constant("ICOAC_ERR_BAD_GAIN"))
ERR_BAD_ZONE = int(constant("ICOAC_ERR_BAD_ZONE"))
ERR_BAD_ICO_RATE = int(constant("ICOAC_ERR_BAD_ICO_RATE"))
ERR_BAD_CRITIC = int(constant("ICOAC_ERR_BAD_CRITIC"))
ERR_BAD_ACTOR = int(constant("ICOAC_ERR_BAD_ACTOR"))
ERR_BAD_PRIOR = int(constant("ICOAC_ERR_BAD_PRIOR"))
ERR_BAD_SEARCH = int(constant("ICOAC_ERR_BAD_SEARCH"))
ERR_BAD_TASK = int(constant("ICOAC_ERR_BAD_TASK"))
SIM_OK = int(constant("ICOAC_SIM_OK"))
SIM_ERR_BAD_PLANT = int(constant("ICOAC_SIM_ERR_BAD_PLANT"))
SIM_ERR_BAD_RUN = int(constant("ICOAC_SIM_ERR_BAD_RUN"))
SIM_ERR_BAD_ARGUMENT = int(constant("ICOAC_SIM_ERR_BAD_ARGUMENT"))
SIM_ERR_THREAD = int(constant("ICOAC_SIM_ERR_THREAD"))
SIM_CANCELLED = int(constant("ICOAC_SIM_CANCELLED"))
SIM_ERR_NONFINITE = int(constant("ICOAC_SIM_ERR_NONFINITE"))

# Status ranges, from the names: icoac_status_t (ICOAC_OK, ICOAC_ERR_*), the bad-parameter
# statuses of both libraries (a rejected configuration, prior, plant, run or argument).
CONTROLLER_STATUSES = frozenset(int(v) for n, v in CONSTANTS.items() if n == "ICOAC_OK" or n.startswith("ICOAC_ERR_"))
CONFIG_STATUSES = frozenset(int(v) for n, v in CONSTANTS.items()
                            if n.startswith("ICOAC_ERR_BAD_") or n.startswith("ICOAC_SIM_ERR_BAD_"))

# Cell outcomes (icoac_sim_outcome_t).
OUTCOME_NAMES = {v: k for k, v in enum("ICOAC_SIM_", ("PENDING", "SUCCESS", "FAILED", "ERROR")).items()}
PENDING, SUCCESS, FAILED, ERROR = (int(constant("ICOAC_SIM_" + n)) for n in ("PENDING", "SUCCESS", "FAILED", "ERROR"))

# Progress counters of icoac_sim_run_grid.
PROGRESS_CELLS = int(constant("ICOAC_SIM_PROGRESS_CELLS"))
PROGRESS_TRIALS = int(constant("ICOAC_SIM_PROGRESS_TRIALS"))
PROGRESS_STEPS = int(constant("ICOAC_SIM_PROGRESS_STEPS"))
PROGRESS_LEN = int(constant("ICOAC_SIM_PROGRESS_LEN"))

# The plant registry (docs/plants.md).
PI = float(constant("ICOAC_SIM_PI"))
DT_MIN, DT_MAX = float(constant("ICOAC_SIM_DT_MIN")), float(constant("ICOAC_SIM_DT_MAX"))  # a model's dt (s)
MAX_STATE = int(constant("ICOAC_SIM_MAX_STATE"))
MAX_PARAMS = int(constant("ICOAC_SIM_MAX_PARAMS"))
CART_POLE = int(constant("ICOAC_SIM_CART_POLE"))

# -- structure mirrors ------------------------------------------------------------------------------
_SIZEOF_REAL = lib.icoac_sizeof_real()
if _SIZEOF_REAL == 4:
    c_real = ctypes.c_float
    real_dtype = np.dtype(np.float32)
elif _SIZEOF_REAL == 8:
    c_real = ctypes.c_double
    real_dtype = np.dtype(np.float64)
else:  # pragma: no cover
    raise LibraryError(f"unsupported icoac_real_t size {_SIZEOF_REAL}")

_RN = c_real * MAX_INPUTS
_RNN = (c_real * MAX_INPUTS) * MAX_INPUTS


_CTYPES = {"icoac_real_t": c_real, "int32_t": ctypes.c_int32, "int64_t": ctypes.c_int64, "double": ctypes.c_double}
_DIMS = {"scalar": 1, "inputs": MAX_INPUTS, "rules": MAX_RULES}


def _param_ctype(row: dict):
    scalar = _CTYPES[row["ctype"]]
    return scalar if row["dim"] == "scalar" else scalar * _DIMS[row["dim"]]


def _param_struct(class_name: str, rows: list[dict], doc: str) -> type:
    """A ctypes mirror whose members are the parameter rows (their last name part), in order."""
    members = [(r["name"].rsplit(".", 1)[-1], _param_ctype(r)) for r in rows]
    return type(class_name, (ctypes.Structure,), {"_fields_": members, "__doc__": doc})


def _config_struct() -> type:
    """icoac_config_t from its rows: the top-level fields, then one structure per group."""
    rows = list(params_of("icoac_config_t").values())
    members: list = [(r["name"], _param_ctype(r)) for r in rows if r["group"] == "config"]
    groups = list(dict.fromkeys(r["group"] for r in rows if r["group"] != "config"))
    for g in groups:
        struct = _param_struct(f"{g.capitalize()}Config", [r for r in rows if r["group"] == g],
                               f"icoac_{g}_config_t (its rows in icoac_params.h).")
        globals()[struct.__name__] = struct
        members.append((g, struct))
    return type("Config", (ctypes.Structure,), {
        "_fields_": members, "__doc__": "icoac_config_t: the mode and one group per concern (icoac_params.h)."})


# TaskConfig, PolicyConfig, IcoConfig, CriticConfig, ActorConfig, SearchConfig and Config.
Config = _config_struct()


class Prior(ctypes.Structure):
    """icoac_prior_t: mean and covariance of the weights (the cart-pole's: w_x, w_xdot, w_theta,
    w_thetadot in the leading 4 entries)."""
    _fields_ = [("mean", _RN), ("cov", _RNN)]


class Counters(ctypes.Structure):
    """icoac_counters_t (icoac_get_counters)."""
    _fields_ = [("ticks", ctypes.c_uint32), ("nonfinite", ctypes.c_uint32), ("numeric_faults", ctypes.c_uint32)]


class State(ctypes.Structure):
    """icoac_state_t: opaque, 8-byte aligned storage of icoac_sizeof_state() bytes; no layout is
    mirrored (read it with get_posterior and get_counters)."""
    _fields_ = [("opaque", ctypes.c_uint64 * (STATE_SIZE // 8))]


class Input(ctypes.Structure):
    """icoac_input_t."""
    _fields_ = [("s", _RN), ("flags", ctypes.c_uint32), ("reflex", c_real)]


class Output(ctypes.Structure):
    """icoac_output_t."""
    _fields_ = [
        ("force", c_real),
        ("z", c_real),
        ("reflex", c_real),
        ("penalty", c_real),
        ("q", c_real),
        ("weight_norm", c_real),
        ("value", c_real),
        ("td_error", c_real),
        ("noise", c_real),
        ("cov_trace", c_real),
        ("status", ctypes.c_int32),
    ]


Run = _param_struct("Run", list(params_of("icoac_sim_run_t").values()),
                    "icoac_sim_run_t (its rows: ICOAC_SIM_RUN_PARAMS).")


class Axis(ctypes.Structure):
    """icoac_sim_axis_t: name and unit of a state component or of a plant's input."""
    _fields_ = [("name", ctypes.c_char_p), ("unit", ctypes.c_char_p)]


class Param(ctypes.Structure):
    """icoac_sim_param_t: one plant parameter, its default, valid range, tier and description."""
    _fields_ = [("name", ctypes.c_char_p), ("unit", ctypes.c_char_p), ("value", ctypes.c_double),
                ("min", ctypes.c_double), ("max", ctypes.c_double), ("tier", ctypes.c_char_p),
                ("doc", ctypes.c_char_p)]


class Sweep(ctypes.Structure):
    """icoac_sim_sweep_t: a swept start coordinate of a plant's grid."""
    _fields_ = [("component", ctypes.c_int32), ("count", ctypes.c_int32), ("first", ctypes.c_double),
                ("step", ctypes.c_double), ("degrees", ctypes.c_int32), ("reserved", ctypes.c_int32)]


class Learner(ctypes.Structure):
    """icoac_sim_learner_t: a plant's settings of some learning conditions (applied by C)."""
    _fields_ = [("conditions", ctypes.c_char_p), ("apply", ctypes.c_void_p)]


class PlantTask(ctypes.Structure):
    """icoac_sim_task_t: the controller task a plant is benchmarked with (applied by C)."""
    _fields_ = [("source", ctypes.c_char_p), ("apply", ctypes.c_void_p), ("n_knobs", ctypes.c_int32),
                ("reserved", ctypes.c_int32), ("knobs", ctypes.POINTER(Param)), ("n_learners", ctypes.c_int32),
                ("paper", ctypes.c_int32), ("learners", ctypes.POINTER(Learner)),
                ("prior_all_finished", ctypes.c_char_p)]


class Actuator(ctypes.Structure):
    """icoac_sim_actuator_t: a plant's saturation parameter and a real actuator's limit."""
    _fields_ = [("param", ctypes.c_int32), ("reserved", ctypes.c_int32), ("limit", ctypes.c_double),
                ("source", ctypes.c_char_p)]


class PlantDesc(ctypes.Structure):
    """icoac_sim_plant_desc_t: a registry plant (read only; its functions are opaque pointers)."""
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("title", ctypes.c_char_p),
        ("source", ctypes.c_char_p),
        ("input", Axis),
        ("actuator", Actuator),
        ("n_state", ctypes.c_int32),
        ("n_params", ctypes.c_int32),
        ("state", Axis * MAX_STATE),
        ("params", ctypes.POINTER(Param)),
        ("rows", Sweep),
        ("cols", Sweep),
        ("start", ctypes.c_double * MAX_STATE),
        ("drawn", ctypes.c_int32 * MAX_STATE),
        ("observed", ctypes.c_int32 * MAX_STATE),
        ("step", ctypes.c_void_p),
        ("derivatives", ctypes.c_void_p),
        ("failed", ctypes.c_void_p),
        ("energy", ctypes.c_void_p),
        ("task", ctypes.POINTER(PlantTask)),
    ]


class Rng(ctypes.Structure):
    """icoac_rng_t: a PCG32 generator's state (seeded by icoac_rng_seed)."""
    _fields_ = [("state", ctypes.c_uint64), ("increment", ctypes.c_uint64), ("spare_normal", c_real),
                ("has_spare", ctypes.c_int32)]


class Model(ctypes.Structure):
    """icoac_sim_model_t: a registry plant's parameter block with dt and the integrator."""
    _fields_ = [("plant", ctypes.c_int32), ("integrator", ctypes.c_int32), ("dt", ctypes.c_double),
                ("param", ctypes.c_double * MAX_PARAMS)]


CELL_DTYPE = np.dtype([
    ("x0", np.float64),
    ("theta0", np.float64),
    ("seed", np.uint64),
    ("outcome", np.int32),
    ("status", np.int32),
    ("trials", np.int64),
    ("total_steps", np.int64),
    ("last_trial_steps", np.int64),
    ("elapsed_time", np.float64),
    ("weights", np.float64, (MAX_INPUTS,)),
    ("cov", np.float64, (MAX_INPUTS, MAX_INPUTS)),
], align=True)

Mirror = Union[type, np.dtype]

# C type -> (mirror, C sizeof function or None). icoac_counters_t has no sizeof function: its size
# is the C rule applied to the C field table (end of the last member, rounded up to the alignment).
MIRRORS: dict[str, tuple[Mirror, str | None]] = {
    "icoac_config_t": (Config, "icoac_sizeof_config"),
    "icoac_prior_t": (Prior, "icoac_sizeof_prior"),
    "icoac_counters_t": (Counters, None),
    "icoac_input_t": (Input, "icoac_sizeof_input"),
    "icoac_output_t": (Output, "icoac_sizeof_output"),
    "icoac_sim_run_t": (Run, "icoac_sim_sizeof_run"),
    "icoac_sim_cell_t": (CELL_DTYPE, "icoac_sim_sizeof_cell"),
    "icoac_sim_axis_t": (Axis, None),
    "icoac_sim_param_t": (Param, None),
    "icoac_sim_sweep_t": (Sweep, None),
    "icoac_sim_actuator_t": (Actuator, None),
    "icoac_sim_learner_t": (Learner, None),
    "icoac_sim_task_t": (PlantTask, None),
    "icoac_sim_plant_desc_t": (PlantDesc, None),
    "icoac_sim_model_t": (Model, None),
    "icoac_rng_t": (Rng, None),
}


# -- layout checks -----------------------------------------------------------------------------------
def mirror_fields(mirror: Mirror) -> dict[str, tuple[int, int]]:
    """{member designator: (offset, size)} of a ctypes structure or numpy record dtype, nested
    structures flattened with dotted names ("policy.gain"); arrays are one member."""
    if isinstance(mirror, np.dtype):
        return {name: (int(mirror.fields[name][1]), int(mirror.fields[name][0].itemsize)) for name in mirror.names}
    out: dict[str, tuple[int, int]] = {}
    for name, ctype in mirror._fields_:
        offset = getattr(mirror, name).offset
        if isinstance(ctype, type) and issubclass(ctype, ctypes.Structure):
            for sub, (off, size) in mirror_fields(ctype).items():
                out[f"{name}.{sub}"] = (offset + off, size)
        else:
            out[name] = (offset, ctypes.sizeof(ctype))
    return out


def mirror_size(mirror: Mirror) -> int:
    return int(mirror.itemsize) if isinstance(mirror, np.dtype) else ctypes.sizeof(mirror)


def check_mirror(c_type: str, mirror: Mirror, c_fields: Mapping[str, tuple[int, int]] | None = None,
                 c_size: int | None = None) -> None:
    """Raise LibraryError naming the first member of ``c_type`` whose name, offset or size differs
    between the C field table (default: the library's) and ``mirror``, or a different total size."""
    if c_fields is None:
        if c_type not in FIELDS:
            raise _stale(f"{c_type} missing from icoac_sim_fields")
        c_fields = FIELDS[c_type]
    py = mirror_fields(mirror)
    for name in c_fields:
        if name not in py:
            raise _stale(f"{c_type}.{name} is in the C layout but not in the binding")
    for name in py:
        if name not in c_fields:
            raise _stale(f"{c_type}.{name} is in the binding but not in the C layout")
    for name, (offset, size) in c_fields.items():
        if py[name] != (offset, size):
            raise _stale(f"{c_type}.{name}: C offset {offset} size {size}, binding offset {py[name][0]} "
                         f"size {py[name][1]}")
    if c_size is not None and mirror_size(mirror) != c_size:
        raise _stale(f"sizeof({c_type}): C {c_size}, binding {mirror_size(mirror)}")


def _c_size(c_type: str, size_fn: str | None) -> int:
    if size_fn is not None:
        return int(getattr(lib, size_fn)())
    ends = [off + size for off, size in FIELDS[c_type].values()]
    align = max(min(size, 8) for _, size in FIELDS[c_type].values())  # scalar members only here
    return -(-max(ends) // align) * align


def layout_report() -> dict:
    """Python vs C sizes of every mirrored type and of the state, and the ABI versions."""
    report = {
        "abi_version": (ABI_VERSION, lib.icoac_abi_version()),
        "sim_abi_version": (SIM_ABI_VERSION, lib.icoac_sim_abi_version()),
        "real": (ctypes.sizeof(c_real), _SIZEOF_REAL),
        "state": (ctypes.sizeof(State), lib.icoac_sizeof_state()),
    }
    for c_type, (mirror, size_fn) in MIRRORS.items():
        report[c_type] = (mirror_size(mirror), _c_size(c_type, size_fn) if c_type in FIELDS else None)
    return report


def _check_layout() -> None:
    for c_type, (mirror, size_fn) in MIRRORS.items():
        check_mirror(c_type, mirror, c_size=_c_size(c_type, size_fn) if c_type in FIELDS else None)
    if ctypes.sizeof(State) != lib.icoac_sizeof_state() or STATE_SIZE % 8 or ctypes.alignment(State) != 8:
        raise _stale(f"icoac_state_t: C {lib.icoac_sizeof_state()} bytes, ICOAC_STATE_SIZE {STATE_SIZE}, "
                     f"binding {ctypes.sizeof(State)} bytes aligned to {ctypes.alignment(State)}")


_check_layout()

# -- prototypes ----------------------------------------------------------------------------------
_P = ctypes.POINTER
_cells_p = ndpointer(CELL_DTYPE, flags="C_CONTIGUOUS,WRITEABLE")
_progress_p = ndpointer(np.int64, ndim=1, shape=(PROGRESS_LEN,), flags="C_CONTIGUOUS,WRITEABLE")
_cancel_p = ndpointer(np.int32, ndim=1, flags="C_CONTIGUOUS")
_f64_w = ndpointer(np.float64, ndim=1, flags="C_CONTIGUOUS,WRITEABLE")


_state_w = ndpointer(np.float64, ndim=1, shape=(MAX_STATE,), flags="C_CONTIGUOUS,WRITEABLE")
_state_r = ndpointer(np.float64, ndim=1, shape=(MAX_STATE,), flags="C_CONTIGUOUS")


class _NullableNdpointer:
    """ndpointer that also accepts None (passed as NULL)."""

    def __init__(self, base):
        self._base = base

    def from_param(self, obj):
        if obj is None:
            return None
        return self._base.from_param(obj)


_PROTOTYPES = {
    "icoac_status_str": ([ctypes.c_int], ctypes.c_char_p),
    "icoac_config_default": ([_P(Config)], None),
    "icoac_config_check": ([_P(Config)], ctypes.c_int),
    "icoac_config_check_field": ([_P(Config), _P(ctypes.c_char_p)], ctypes.c_int),
    "icoac_init": ([_P(Config), _P(State), _P(Prior), ctypes.c_uint64], ctypes.c_int),
    "icoac_retune": ([_P(State), _P(Config)], ctypes.c_int),
    "icoac_reset": ([_P(State)], ctypes.c_int),
    "icoac_step": ([_P(State), _P(Input), _P(Output)], ctypes.c_int),
    "icoac_get_config": ([_P(State), _P(Config)], ctypes.c_int),
    "icoac_get_posterior": ([_P(State), _P(Prior)], ctypes.c_int),
    "icoac_get_counters": ([_P(State), _P(Counters)], ctypes.c_int),
    "icoac_prior_check": ([_P(Prior), ctypes.c_int32], ctypes.c_int),
    "icoac_mix_seed": ([ctypes.c_uint64, ctypes.c_uint64], ctypes.c_uint64),
    "icoac_sim_status_str": ([ctypes.c_int32], ctypes.c_char_p),
    "icoac_sim_run_default": ([_P(Run)], None),
    "icoac_sim_run_check": ([_P(Run)], ctypes.c_int32),
    "icoac_sim_plant_count": ([], ctypes.c_int32),
    "icoac_sim_plant_info": ([ctypes.c_int32], _P(PlantDesc)),
    "icoac_sim_plant_find": ([ctypes.c_char_p], ctypes.c_int32),
    "icoac_sim_plant_task": ([ctypes.c_int32, _P(ctypes.c_double), _P(Config)], ctypes.c_int32),
    "icoac_sim_plant_learner": ([ctypes.c_int32, ctypes.c_char_p, _P(Config)], ctypes.c_int32),
    "icoac_sim_model_default": ([_P(Model), ctypes.c_int32], ctypes.c_int32),
    "icoac_sim_model_check": ([_P(Model)], ctypes.c_int32),
    "icoac_sim_model_step": ([_P(Model), _state_w, ctypes.c_double], ctypes.c_int32),
    "icoac_sim_model_derivatives": ([_P(Model), _state_r, ctypes.c_double, _state_w], ctypes.c_int32),
    "icoac_sim_model_failed": ([_P(Model), _state_r, _P(ctypes.c_int32)], ctypes.c_int32),
    "icoac_sim_model_energy": ([_P(Model), _state_r, _P(ctypes.c_double)], ctypes.c_int32),
    "icoac_sim_model_step_lanes": ([_P(Model), ndpointer(np.float64, ndim=2, flags="C_CONTIGUOUS,WRITEABLE"),
                                    ndpointer(np.float64, ndim=1, flags="C_CONTIGUOUS"),
                                    ndpointer(np.int32, ndim=1, flags="C_CONTIGUOUS,WRITEABLE"), ctypes.c_int64],
                                   ctypes.c_int32),
    "icoac_sim_plant_grid": ([ctypes.c_int32, _cells_p, ctypes.c_int64, ctypes.c_uint64], ctypes.c_int32),
    "icoac_rng_seed": ([_P(Rng), ctypes.c_uint64, ctypes.c_uint64], None),
    "icoac_sim_model_start": ([_P(Model), ndpointer(CELL_DTYPE, shape=(1,), flags="C_CONTIGUOUS"), ctypes.c_double, _P(Rng), _state_w], ctypes.c_int32),
    "icoac_sim_run_cell": ([_P(Config), _P(Model), _P(Run), _P(Prior), _cells_p,
                            _NullableNdpointer(_cancel_p), _NullableNdpointer(_progress_p)], ctypes.c_int32),
    "icoac_sim_run_grid": ([_P(Config), _P(Model), _P(Run), _P(Prior), _cells_p, ctypes.c_int64,
                            ctypes.c_int32, _NullableNdpointer(_cancel_p), _NullableNdpointer(_progress_p)],
                           ctypes.c_int32),
    "icoac_sim_trajectory": ([_P(Config), _P(Model), _P(Prior), ctypes.c_double, ctypes.c_double,
                              ctypes.c_double, ctypes.c_uint64, ctypes.c_int64, _f64_w, _f64_w,
                              _P(ctypes.c_int64)], ctypes.c_int32),
}
for _name, (_args, _res) in _PROTOTYPES.items():
    _fn = getattr(lib, _name)
    _fn.argtypes = _args
    _fn.restype = _res


def status_str(status: int) -> str:
    """C message of a status: icoac_status_str for icoac_status_t values, icoac_sim_status_str
    for the others."""
    status = int(status)
    if not -2 ** 31 <= status < 2 ** 31:
        return f"status {status}"
    fn = lib.icoac_status_str if status in CONTROLLER_STATUSES else lib.icoac_sim_status_str
    text = fn(status)
    return text.decode("utf-8", "replace") if text else f"status {status}"


def status_name(status: int) -> str:
    """Short name of a status: its C message up to the first ':' or ' (' ("numeric failure")."""
    text = status_str(status)
    for stop in (":", " ("):
        text = text.split(stop, 1)[0]
    return text


def check_status(status: int, context: str | None = None) -> None:
    """Raise the exception class matching a non-OK status."""
    status = int(status)
    if status == OK:
        return
    if status in CONFIG_STATUSES:
        raise ConfigError(status, context=context)
    if status == SIM_CANCELLED:
        raise Cancelled(status, context=context)
    raise IcoacError(status, context=context)


def get_posterior(state: State) -> Prior:
    """Current weights and covariance of a controller state (icoac_get_posterior)."""
    post = Prior()
    check_status(lib.icoac_get_posterior(ctypes.byref(state), ctypes.byref(post)), "get posterior")
    return post


def get_counters(state: State) -> Counters:
    """Tick counters of a controller state (icoac_get_counters)."""
    counters = Counters()
    check_status(lib.icoac_get_counters(ctypes.byref(state), ctypes.byref(counters)), "get counters")
    return counters


def library_version() -> str:
    """The release version the loaded C library was built as (icoac_version)."""
    if not hasattr(lib, "icoac_version"):
        raise _stale("no icoac_version")
    lib.icoac_version.argtypes = []
    lib.icoac_version.restype = ctypes.c_char_p
    return lib.icoac_version().decode("ascii")


def abi_info() -> dict:
    """ABI description recorded with every result."""
    return {
        "library": str(LIBRARY_PATH),
        "library_source": LIBRARY_SOURCE,
        "abi_version": int(lib.icoac_abi_version()),
        "sim_abi_version": int(lib.icoac_sim_abi_version()),
        "sizeof_real": int(_SIZEOF_REAL),
        "critic_kernel": "dense" if CONSTANTS["ICOAC_CRITIC_DENSE"] else "sparse",
        "max_lanes": int(CONSTANTS["ICOAC_SIM_MAX_LANES"]),
    }


# -- the plant registry ------------------------------------------------------------------------------
def plant_index(name: str) -> int:
    """Registry index of the plant called name (ConfigError when none is)."""
    index = int(lib.icoac_sim_plant_find(name.encode()))
    if index < 0:
        names = [plant_info(i)["name"] for i in range(int(lib.icoac_sim_plant_count()))]
        raise ConfigError(SIM_ERR_BAD_PLANT, f"unknown plant {name!r}; the registry has {', '.join(names)}")
    return index


def plant_info(plant: Union[int, str]) -> dict:
    """A registry plant's descriptor as plain data: name, title, source, input (name, unit),
    state [(name, unit)], params [{name, unit, value, min, max, tier, doc}], rows and cols of its grid
    ({component, count, first, step, degrees}), start, drawn, observed, has_energy, actuator
    ({param, limit, source}; None when its input is not saturated), and its task
    (None when it has none): {source, paper, learners (condition names), prior_all_finished}."""
    index = plant_index(plant) if isinstance(plant, str) else int(plant)
    ptr = lib.icoac_sim_plant_info(index)
    if not ptr:
        raise ConfigError(SIM_ERR_BAD_PLANT, f"no plant {index} in the registry")
    d = ptr.contents
    n = d.n_state
    sweep = lambda w: {"component": w.component, "count": w.count, "first": w.first, "step": w.step,  # noqa: E731
                       "degrees": bool(w.degrees)}
    return {
        "index": index,
        "name": d.name.decode(), "title": d.title.decode(), "source": d.source.decode(),
        "input": (d.input.name.decode(), d.input.unit.decode()),
        "actuator": _actuator(d),
        "state": [(d.state[i].name.decode(), d.state[i].unit.decode()) for i in range(n)],
        "params": [_param_info(d.name.decode(), p) for p in (d.params[i] for i in range(d.n_params))],
        "rows": sweep(d.rows), "cols": sweep(d.cols),
        "start": list(d.start[:n]), "drawn": [bool(v) for v in d.drawn[:n]], "observed": list(d.observed[:n]),
        "has_energy": bool(d.energy),
        "task": _task_info(d.name.decode(), d.task.contents) if d.task else None,
    }


def _actuator(d: PlantDesc) -> dict | None:
    a = d.actuator
    if a.param == -1:
        return None
    if not 0 <= a.param < d.n_params or not a.source:
        raise LibraryError(f"plant {d.name.decode()}: its actuator needs a parameter index below {d.n_params} (or -1: "
                           "none) and a source (docs/plants.md)")
    return {"param": d.params[a.param].name.decode(), "limit": a.limit, "source": a.source.decode()}


def _param_info(plant: str, p: Param) -> dict:
    name = p.name.decode()
    tier, doc = (p.tier or b"").decode(), (p.doc or b"").decode()
    if tier not in ("essential", "advanced") or not doc:
        raise LibraryError(f"plant {plant}: parameter {name} needs a tier (\"essential\" or \"advanced\") and a "
                           "one-line doc in its C table (docs/plants.md)")
    return {"name": name, "unit": p.unit.decode(), "value": p.value, "min": p.min, "max": p.max,
            "tier": tier, "doc": doc}


def _task_info(plant: str, t: PlantTask) -> dict:
    return {"source": t.source.decode(), "paper": bool(t.paper),
            "knobs": [_param_info(plant, t.knobs[i]) for i in range(t.n_knobs)],
            "learners": [t.learners[i].conditions.decode().split() for i in range(t.n_learners)],
            "prior_all_finished": t.prior_all_finished.decode() if t.prior_all_finished else None}


def model_default(plant: Union[int, str], **params: float) -> Model:
    """A model of the plant with its default parameters, dt 0.01 s and Euler, then params (by
    name, plus dt and integrator) set and the result checked."""
    index = plant_index(plant) if isinstance(plant, str) else int(plant)
    model = Model()
    check_status(lib.icoac_sim_model_default(ctypes.byref(model), index), "plant model")
    names = [p["name"] for p in plant_info(index)["params"]]
    for key, value in params.items():
        if key in ("dt", "integrator"):
            setattr(model, key, INTEGRATORS[value] if key == "integrator" and isinstance(value, str) else value)
        elif key in names:
            model.param[names.index(key)] = float(value)
        else:
            raise ConfigError(SIM_ERR_BAD_PLANT, f"plant {plant_info(index)['name']} has no parameter {key!r}")
    check_status(lib.icoac_sim_model_check(ctypes.byref(model)), "plant model")
    return model


def model_step_lanes(model: Model, states: np.ndarray, u: np.ndarray, ended: np.ndarray) -> None:
    """icoac_sim_model_step_lanes in place: states (lanes, MAX_STATE) float64, u (lanes,) float64,
    ended (lanes,) int32; a lane already ended is left alone, a lane that fails (or whose state or
    input is not finite) gets ended = 1."""
    lanes = len(u)
    if states.shape != (lanes, MAX_STATE) or ended.shape != (lanes,):
        raise ValueError(f"step_lanes: states must be ({lanes}, {MAX_STATE}) and ended ({lanes},), "
                         f"got {states.shape} and {ended.shape}")
    check_status(lib.icoac_sim_model_step_lanes(ctypes.byref(model), states, u, ended, lanes), "plant step")
