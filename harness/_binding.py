"""ctypes binding of libicoac_sim (sim_host/include/icoac_sim/icoac_sim.h, firmware/include/icoac/*.h).

Every prototype is declared once here; struct layouts are checked against the C ``sizeof``
functions and the ABI versions at import, so a stale or mismatched library fails loudly.
"""
from __future__ import annotations

import ctypes
import os
from pathlib import Path

import numpy as np
from numpy.ctypeslib import ndpointer

REPO_ROOT = Path(__file__).resolve().parent.parent
LIBRARY_ENV = "ICOAC_SIM_LIBRARY"
DEFAULT_LIBRARY = REPO_ROOT / "build" / "release" / "sim_host" / "libicoac_sim.so"

ABI_VERSION = 3
SIM_ABI_VERSION = 1
N_INPUTS = 4
GRID_THETAS = 25
GRID_XS = 49
GRID_CELLS = GRID_THETAS * GRID_XS
PROGRESS_CELLS, PROGRESS_TRIALS, PROGRESS_STEPS, PROGRESS_LEN = 0, 1, 2, 3

# Status codes (icoac_status_t, icoac_sim_status_t).
OK = 0
ERR_NULL = 1
ERR_NOT_INITIALISED = 2
ERR_NONFINITE_INPUT = 3
ERR_NUMERIC = 4
ERR_BAD_MODE = 10
ERR_BAD_SCALE = 11
ERR_BAD_GAIN = 12
ERR_BAD_ZONE = 13
ERR_BAD_ICO_RATE = 14
ERR_BAD_CRITIC = 15
ERR_BAD_ACTOR = 16
ERR_BAD_PRIOR = 17
SIM_ERR_BAD_PLANT = 100
SIM_ERR_BAD_RUN = 101
SIM_ERR_BAD_ARGUMENT = 102
SIM_ERR_THREAD = 103
SIM_CANCELLED = 104

# Cell outcomes (icoac_sim_outcome_t).
PENDING, SUCCESS, FAILED, ERROR = 0, 1, 2, 3
OUTCOME_NAMES = {PENDING: "pending", SUCCESS: "success", FAILED: "failed", ERROR: "error"}

_CONFIG_STATUSES = set(range(10, 18)) | {SIM_ERR_BAD_PLANT, SIM_ERR_BAD_RUN, SIM_ERR_BAD_ARGUMENT}


class IcoacError(RuntimeError):
    """A non-OK status from the C library; ``.status`` is the code, the message is the C text."""

    def __init__(self, status: int, message: str | None = None, context: str | None = None):
        self.status = int(status)
        self.c_message = status_str(self.status)
        text = message if message is not None else self.c_message
        if context:
            text = f"{context}: {text}"
        super().__init__(text)


class ConfigError(IcoacError):
    """A configuration, prior, plant, run or argument rejected (status 10-17, 100-102) or a bad name."""

    def __init__(self, status: int | None = None, message: str | None = None, context: str | None = None):
        super().__init__(SIM_ERR_BAD_ARGUMENT if status is None else status, message, context)


class Cancelled(IcoacError):
    """The cancel flag was raised (status 104); finished cells are kept."""


class LibraryError(RuntimeError):
    """The shared library is missing or does not match this binding."""


def _library_path() -> Path:
    env = os.environ.get(LIBRARY_ENV)
    return Path(env) if env else DEFAULT_LIBRARY


def _load() -> ctypes.CDLL:
    path = _library_path()
    if not path.is_file():
        raise LibraryError(
            f"icoac_sim shared library not found at {path}; build it with `make build` "
            f"(or set {LIBRARY_ENV} to its path)")
    try:
        return ctypes.CDLL(str(path))
    except OSError as exc:  # pragma: no cover - depends on the system
        raise LibraryError(f"cannot load {path}: {exc}") from exc


lib = _load()
LIBRARY_PATH = _library_path()

# -- sizes first: the real type decides the structure layouts ----------------------------------
for _name in ("icoac_abi_version", "icoac_sizeof_real", "icoac_sizeof_config", "icoac_sizeof_state",
              "icoac_sizeof_input", "icoac_sizeof_output", "icoac_sizeof_prior",
              "icoac_sim_abi_version", "icoac_sim_sizeof_plant", "icoac_sim_sizeof_run",
              "icoac_sim_sizeof_cell"):
    getattr(lib, _name).argtypes = []
    getattr(lib, _name).restype = ctypes.c_uint32

_SIZEOF_REAL = lib.icoac_sizeof_real()
if _SIZEOF_REAL == 4:
    c_real = ctypes.c_float
    real_dtype = np.dtype(np.float32)
elif _SIZEOF_REAL == 8:
    c_real = ctypes.c_double
    real_dtype = np.dtype(np.float64)
else:  # pragma: no cover
    raise LibraryError(f"unsupported icoac_real_t size {_SIZEOF_REAL}")

_R4 = c_real * N_INPUTS
_R44 = (c_real * N_INPUTS) * N_INPUTS


class Config(ctypes.Structure):
    """icoac_config_t."""
    _fields_ = [
        ("mode", ctypes.c_int32),
        ("reflex_mode", ctypes.c_int32),
        ("ico_timing", ctypes.c_int32),
        ("clip_inputs", ctypes.c_int32),
        ("input_range", _R4),
        ("gain", c_real),
        ("reflex_force", c_real),
        ("zone_theta", c_real),
        ("zone_x", c_real),
        ("ico_rate", c_real),
        ("critic_rate", c_real),
        ("discount", c_real),
        ("td_clip", c_real),
        ("critic_range", _R4),
        ("critic_threshold", c_real),
        ("noise_std", c_real),
        ("actor_scale", c_real),
        ("forgetting", c_real),
        ("rl_reflex", ctypes.c_int32),
        ("act_with_sample", ctypes.c_int32),
    ]


class Prior(ctypes.Structure):
    """icoac_prior_t: mean and covariance of (w_x, w_xdot, w_theta, w_thetadot)."""
    _fields_ = [("mean", _R4), ("cov", _R44)]


class Rng(ctypes.Structure):
    """icoac_rng_t."""
    _fields_ = [("state", ctypes.c_uint64), ("increment", ctypes.c_uint64),
                ("spare_normal", c_real), ("has_spare", ctypes.c_int32)]


CRITIC_UNITS = 3 * 3 * 6 * 3
CRITIC_PAIRS = 3 * 3
CRITIC_CELLS = 6 * 3
INPUT_TERMINAL = 1


class CriticActive(ctypes.Structure):
    """icoac_critic_active_t: critic units kept at one state."""
    _fields_ = [
        ("pair_product", c_real * CRITIC_PAIRS),
        ("cell_product", c_real * (CRITIC_CELLS + 1)),
        ("pair", ctypes.c_uint8 * CRITIC_PAIRS),
        ("pair_cells", ctypes.c_uint8 * CRITIC_PAIRS),
        ("cell", ctypes.c_uint8 * CRITIC_CELLS),
        ("pairs", ctypes.c_uint8),
        ("cells", ctypes.c_uint8),
    ]


class State(ctypes.Structure):
    """icoac_state_t (opaque to callers; mirrored for size checks and direct controller tests)."""
    _fields_ = [
        ("magic", ctypes.c_uint32),
        ("has_prev", ctypes.c_int32),
        ("inv_range", _R4),
        ("w", _R4),
        ("weight_norm", c_real),
        ("cov", _R44),
        ("w_act", _R4),
        ("v", c_real * CRITIC_UNITS),
        ("active", CriticActive * 2),
        ("active_slot", ctypes.c_int32),
        ("x_prev", _R4),
        ("penalty_prev", c_real),
        ("value_prev", c_real),
        ("noise_prev", c_real),
        ("rng", Rng),
        ("ticks", ctypes.c_uint32),
        ("nonfinite_count", ctypes.c_uint32),
        ("numeric_fault_count", ctypes.c_uint32),
    ]


class Input(ctypes.Structure):
    """icoac_input_t."""
    _fields_ = [("s", _R4), ("flags", ctypes.c_uint32)]


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


class Plant(ctypes.Structure):
    """icoac_sim_plant_t."""
    _fields_ = [
        ("gravity", ctypes.c_double),
        ("cart_mass", ctypes.c_double),
        ("pole_mass", ctypes.c_double),
        ("half_length", ctypes.c_double),
        ("dt", ctypes.c_double),
        ("x_limit", ctypes.c_double),
        ("theta_limit", ctypes.c_double),
        ("integrator", ctypes.c_int32),
        ("reserved", ctypes.c_int32),
    ]


class Run(ctypes.Structure):
    """icoac_sim_run_t."""
    _fields_ = [
        ("max_trials", ctypes.c_int64),
        ("success_steps", ctypes.c_int64),
        ("init_velocity_noise", ctypes.c_double),
    ]


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
    ("weights", np.float64, (N_INPUTS,)),
    ("cov", np.float64, (N_INPUTS, N_INPUTS)),
], align=True)

# -- prototypes ----------------------------------------------------------------------------------
_P = ctypes.POINTER
_cells_p = ndpointer(CELL_DTYPE, flags="C_CONTIGUOUS,WRITEABLE")
_progress_p = ndpointer(np.int64, ndim=1, shape=(PROGRESS_LEN,), flags="C_CONTIGUOUS,WRITEABLE")
_cancel_p = ndpointer(np.int32, ndim=1, flags="C_CONTIGUOUS")
_f64_w = ndpointer(np.float64, ndim=1, flags="C_CONTIGUOUS,WRITEABLE")


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
    "icoac_init": ([_P(Config), _P(State), _P(Prior), ctypes.c_uint64], ctypes.c_int),
    "icoac_reset": ([_P(Config), _P(State)], ctypes.c_int),
    "icoac_step": ([_P(Config), _P(State), _P(Input), _P(Output)], ctypes.c_int),
    "icoac_get_posterior": ([_P(State), _P(Prior)], ctypes.c_int),
    "icoac_prior_check": ([_P(Prior)], ctypes.c_int),
    "icoac_mix_seed": ([ctypes.c_uint64, ctypes.c_uint64], ctypes.c_uint64),
    "icoac_sim_status_str": ([ctypes.c_int32], ctypes.c_char_p),
    "icoac_sim_plant_default": ([_P(Plant)], None),
    "icoac_sim_plant_check": ([_P(Plant)], ctypes.c_int32),
    "icoac_sim_run_default": ([_P(Run)], None),
    "icoac_sim_run_check": ([_P(Run)], ctypes.c_int32),
    "icoac_sim_plant_step": ([_P(Plant), ndpointer(np.float64, ndim=1, shape=(N_INPUTS,),
                                                   flags="C_CONTIGUOUS,WRITEABLE"), ctypes.c_double],
                             ctypes.c_int32),
    "icoac_sim_failed": ([_P(Plant), ndpointer(np.float64, ndim=1, shape=(N_INPUTS,), flags="C_CONTIGUOUS")],
                         ctypes.c_int32),
    "icoac_sim_paper_grid": ([_cells_p, ctypes.c_int64, ctypes.c_uint64], ctypes.c_int32),
    "icoac_sim_run_cell": ([_P(Config), _P(Plant), _P(Run), _P(Prior), _cells_p,
                            _NullableNdpointer(_cancel_p), _NullableNdpointer(_progress_p)], ctypes.c_int32),
    "icoac_sim_run_grid": ([_P(Config), _P(Plant), _P(Run), _P(Prior), _cells_p, ctypes.c_int64, ctypes.c_int32,
                            _NullableNdpointer(_cancel_p), _NullableNdpointer(_progress_p)], ctypes.c_int32),
    "icoac_sim_trajectory": ([_P(Config), _P(Plant), _P(Prior), ctypes.c_double, ctypes.c_double,
                              ctypes.c_double, ctypes.c_uint64, ctypes.c_int64, _f64_w, _f64_w,
                              _P(ctypes.c_int64)], ctypes.c_int32),
}
for _name, (_args, _res) in _PROTOTYPES.items():
    _fn = getattr(lib, _name)
    _fn.argtypes = _args
    _fn.restype = _res


def status_str(status: int) -> str:
    """C message of a status (icoac_sim_status_str passes values < 100 to icoac_status_str)."""
    text = lib.icoac_sim_status_str(int(status))
    return text.decode("utf-8", "replace") if text else f"status {status}"


def check_status(status: int, context: str | None = None) -> None:
    """Raise the exception class matching a non-OK status."""
    status = int(status)
    if status == OK:
        return
    if status in _CONFIG_STATUSES:
        raise ConfigError(status, context=context)
    if status == SIM_CANCELLED:
        raise Cancelled(status, context=context)
    raise IcoacError(status, context=context)


# -- layout checks ---------------------------------------------------------------------------------
def layout_report() -> dict:
    """Python vs C sizes of every mirrored type, and the ABI versions."""
    return {
        "abi_version": (ABI_VERSION, lib.icoac_abi_version()),
        "sim_abi_version": (SIM_ABI_VERSION, lib.icoac_sim_abi_version()),
        "config": (ctypes.sizeof(Config), lib.icoac_sizeof_config()),
        "prior": (ctypes.sizeof(Prior), lib.icoac_sizeof_prior()),
        "state": (ctypes.sizeof(State), lib.icoac_sizeof_state()),
        "input": (ctypes.sizeof(Input), lib.icoac_sizeof_input()),
        "output": (ctypes.sizeof(Output), lib.icoac_sizeof_output()),
        "plant": (ctypes.sizeof(Plant), lib.icoac_sim_sizeof_plant()),
        "run": (ctypes.sizeof(Run), lib.icoac_sim_sizeof_run()),
        "cell": (CELL_DTYPE.itemsize, lib.icoac_sim_sizeof_cell()),
    }


def _check_layout() -> None:
    bad = {k: v for k, v in layout_report().items() if v[0] != v[1]}
    if bad:
        detail = ", ".join(f"{k}: python {p} != C {c}" for k, (p, c) in bad.items())
        raise LibraryError(f"{LIBRARY_PATH} does not match the harness binding ({detail}); "
                           "rebuild it with `make build`")


_check_layout()


def abi_info() -> dict:
    """ABI description recorded with every result."""
    return {
        "library": str(LIBRARY_PATH),
        "abi_version": int(lib.icoac_abi_version()),
        "sim_abi_version": int(lib.icoac_sim_abi_version()),
        "sizeof_real": int(_SIZEOF_REAL),
    }
