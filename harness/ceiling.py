"""`ceiling`: what the policy class F = G * w^T x~ + U can reach on the paper grid, with no
learning (method.md, L5, "the linear-policy ceiling"). Every simulation runs in C through the engine.

Fixed-w evaluation. A controller in mode ICO with ``learn = 0`` and a prior whose mean is w (and
covariance I, which ICO mode does not read) acts with exactly w in every cell and every trial;
nothing is updated, so a grid run of condition ``ico`` with ``learn = 0`` evaluates w. Two
protocols:

- ``first``: one trial per cell (``max_trials = 1``), the cell's first initial-velocity draw;
- ``retries``: the engine's trial loop, fresh initial velocities every trial, up to a trial cap
  (default 1000). A fixed controller can succeed on a later draw where its first trial failed.

The horizon is ``success_steps`` (default the paper's 1e5 steps = 1000 s).

The search for the best single w (``search``), all of it with the first protocol:

1. Starting points: the typical ICO weights - the mean final weight of the successful cells in
   the central frame of an ICO results directory (``--prior-from``, the ICO->RL prior mean), else
   options.TYPICAL_ICO_WEIGHTS - and the discrete-time LQR gains of the plant linearised at the
   upright state (A, B by central differences of the C plant step ``icoac_sim_plant_step``; Q =
   diag(1 / input_range^2), R = 1 / F^2 for F = 1, 3, 10, 30 N), converted to weights by
   w_i = -K_i * input_range_i / G (so F = G w^T x~ equals -K s while no input is clipped).
2. Random search (seeded: numpy's PCG64 from (seed, 0x1C0AC)), half the remaining budget:
   alternately a global draw (magnitudes log-uniform on [1e-3, 10], all positive signs - the
   LQR pattern - with probability 1/2, else random signs) and a local draw around a random
   starting point (magnitudes times exp(0.7 N(0, 1)), each sign flipped with probability 0.1).
3. Local refinement, the rest of the budget: a pattern search from the best candidate so far,
   in rounds of 8 coordinate moves (each |w_i| times e^+step or e^-step) and 4 Gaussian moves
   (w times exp(step N(0, 1)) per component); the centre moves to the round's best if that
   improves on it, else the step halves, from 0.5 down to 1/32. A converged pattern search
   restarts from the next best starting point or random candidate, until the budget is spent
   (or every one of them has been refined: the search then stops early).

Every candidate is rounded to the controller's real type (so the w recorded is the w run), its
magnitudes clipped to [1e-4, 1e3] (starting points are kept as they are), and screened once: a
grid run at ``screen_steps`` (default 1000) steps, first protocol, scored by (cells that
succeed, total steps survived). The best ``confirm`` screened w are then run at the full horizon
(first protocol, a results directory each); the best of them (most successes, then most interior
successes, then the screening score) is the reported w, and is run under the retries protocol
too. The search is deterministic for a seed, the cells and the configuration (the engine's cells
do not depend on threads); its incumbent is at least as good as every starting point on the
screening set, by construction.

The first-step bound (``first_step_bound``): the first explicit Euler step moves x and theta by
dt times the initial velocities only (x1 = x0 + dt x_dot0, theta1 = theta0 + dt theta_dot0); the
force changes only the velocities, which stay finite. So a cell on a failure threshold
(|x0| = 2.4 m or |theta0| = 12 deg; the grid's last x0 is 2.400000000000001 in double) whose
first draw points outward fails at step 1 whatever any controller does. The engine's first
draws are recomputed through the C API (``icoac_sim_trajectory`` with one step gives the start
state of the cell's first trial), stepped once by ``icoac_sim_plant_step`` under several forces
from -1e4 N to 1e4 N and tested with ``icoac_sim_failed``; the cells failing under every force
are lost, and failure must not depend on the force (checked). The same set is checked against
the engine itself: one trial of 1 step per cell. The bound - cells minus lost cells - is an upper
bound on the successes of ANY controller under the first-trial protocol with this seed's draws;
with retries a boundary cell may still succeed on a later, inward draw. It is defined for the
Euler integrator only (with RK4 the force enters x1 and theta1) and reported as not computed
otherwise.

Layout of OUT: ``search.json`` (settings and every screening result, rewritten atomically at
most every 2 s and on exit: a rerun of the same command takes the screens from it and replays
the deterministic search), ``evals/<hash of w>_<protocol>_h<steps>/`` (a results directory per
full-horizon evaluation, checkpointed and resumed like ``grid``), ``ceiling.json`` and
``ceiling.md`` (the summary, written at the end).
"""
from __future__ import annotations

import ctypes
import hashlib
import math
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from . import _binding as B
from . import geometry, grid, literals, metrics, results, store
from . import prior as P
from .conditions import run_condition
from .config import RunConfig, build_config, make_prior, parse_sets
from .errors import LibraryError, ResultsError, UsageError
from .metrics import percent
from .options import (CEILING_CANDIDATES, CEILING_CONFIRM, CEILING_DIR, CEILING_FILE, CEILING_MAX_CANDIDATES,
                      CEILING_MAX_TRIALS, CEILING_PROTOCOL_CHOICES, CEILING_PROTOCOLS, CEILING_SCREEN_STEPS,
                      INT64_MAX, TYPICAL_ICO_WEIGHTS)

FORMAT_VERSION = 1
SEARCH_FILE = "search.json"
SUMMARY_MD = "ceiling.md"
EVALS_DIR = "evals"
W_NAMES = ("w_x", "w_xdot", "w_theta", "w_thetadot")
# Parameters the command sets itself (--set may not change them).
RESERVED = {"mode": "ICO mode is the fixed-w evaluation", "learn": "every update is off (learn = 0)",
            "max_trials": "use --protocol and --max-trials", "success_steps": "use --success-steps"}
PROTOCOL_LABELS = {"first": "first trial", "retries": "retries"}

# The search (see the module docstring).
SEARCH_STREAM = 0x1C0AC
LQR_FORCES = (1.0, 3.0, 10.0, 30.0)           # N: R = 1 / F^2
GLOBAL_MAGNITUDES = (1e-3, 10.0)
LOCAL_SPREAD = 0.7
LOCAL_FLIP = 0.1
STEP_START, STEP_MIN = 0.5, 1.0 / 32.0
GAUSS_MOVES = 4
CLIP_MAGNITUDES = (1e-4, 1e3)
# Forces (N) of the first-step check: failure at step 1 must be the same under each.
BOUND_FORCES = (-1e4, -10.0, -1.0, 0.0, 1.0, 10.0, 1e4)
FLUSH_EVERY = 2.0                             # s between rewrites of search.json


# -- weights and configurations ---------------------------------------------------------------------
def as_weights(values: Any, what: str = "w") -> tuple[float, ...]:
    """4 finite numbers rounded to the controller's real type (what the controller acts with), as
    a tuple of Python floats; UsageError for anything the C prior check would refuse."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise UsageError(f"{what}: expected {B.N_INPUTS} numbers, got {values!r:.60}") from None
    if arr.shape != (B.N_INPUTS,):
        raise UsageError(f"{what}: expected {B.N_INPUTS} numbers (w_x, w_xdot, w_theta, w_thetadot), "
                         f"got {values!r:.60}")
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > 1e6):
        raise UsageError(f"{what}: every weight must be finite with |w_i| <= 1e6, got {values!r:.60}")
    with np.errstate(under="ignore"):
        rounded = arr.astype(B.real_dtype)
    tiny = np.finfo(B.real_dtype).tiny
    if np.any((rounded != 0) & (np.abs(rounded) < tiny)) or np.any((arr != 0) & (rounded == 0)):
        raise UsageError(f"{what}: a weight is subnormal in the controller's reals (|w_i| must be 0 "
                         f"or >= {tiny:.3g})")
    return tuple(float(v) for v in rounded)


def parse_weights(text: str, what: str = "--w") -> tuple[float, ...]:
    """'w1,w2,w3,w4' -> as_weights."""
    parts = [p.strip() for p in str(text).strip().strip("()[]").split(",")]
    try:
        values = [literals.real(p) for p in parts]
    except literals.NumberError as exc:
        raise UsageError(f"{what} expects {B.N_INPUTS} comma-separated numbers w_x,w_xdot,w_theta,w_thetadot, "
                         f"got {text!r:.60} (a value {exc})") from None
    return as_weights(values, what)


def weights_key(w: Sequence[float]) -> str:
    """Short stable name of a w (hash of its real-typed bytes)."""
    return hashlib.sha1(np.asarray(w, dtype=B.real_dtype).tobytes()).hexdigest()[:12]


def format_w(w: Sequence[float], digits: int = 4) -> str:
    return "(" + ", ".join(f"{v:.{digits}g}" for v in w) + ")"


def check_overrides(sets: Sequence[str] | Mapping[str, Any] | None) -> dict[str, Any]:
    """--set items (or a mapping) as canonical overrides, refusing the parameters the command sets."""
    over = dict(sets) if isinstance(sets, Mapping) else parse_sets(sets or [])
    for name in over:
        if name in RESERVED:
            raise UsageError(f"--set {name}: set by the ceiling command ({RESERVED[name]})")
    return over


def fixed_config(w: Sequence[float], protocol: str = "first", *, max_trials: int = CEILING_MAX_TRIALS,
                 success_steps: int | None = None, overrides: Mapping[str, Any] | None = None) -> RunConfig:
    """Condition ico, learn = 0, prior mean w and covariance I: the engine evaluates w. Protocol
    first: max_trials = 1; retries: max_trials as given. success_steps None: the C default (1e5)."""
    check_protocol(protocol)
    over = dict(check_overrides(overrides))
    over["learn"] = 0
    over["max_trials"] = 1 if protocol == "first" else max_trials
    if success_steps is not None:
        over["success_steps"] = success_steps
    return build_config(over, condition="ico", prior=make_prior(as_weights(w), np.eye(B.N_INPUTS)))


def check_protocol(protocol: Any) -> str:
    if protocol not in CEILING_PROTOCOLS:
        raise UsageError(f"unknown protocol {protocol!r:.40}; valid: {', '.join(CEILING_PROTOCOLS)}")
    return protocol


def protocols_of(choice: str) -> tuple[str, ...]:
    if choice not in CEILING_PROTOCOL_CHOICES:
        raise UsageError(f"--protocol {choice!r:.40}: valid: {', '.join(CEILING_PROTOCOL_CHOICES)}")
    return CEILING_PROTOCOLS if choice == "both" else (choice,)


@dataclass
class FixedWeights:
    """The 'prior' of a fixed-w evaluation as run_condition takes it (prior(), to_dict()); run.json
    records it as prior_info with kind 'fixed-w'."""
    w: tuple[float, ...]
    protocol: str

    def prior(self) -> B.Prior:
        return make_prior(self.w, np.eye(B.N_INPUTS))

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "fixed-w", "mean": list(self.w), "cov": np.eye(B.N_INPUTS).tolist(),
                "protocol": self.protocol, "source": "python -m harness ceiling"}


def check_weights_kept(cells: np.ndarray, w: Sequence[float]) -> None:
    """learn = 0: every finished cell ends with exactly w; anything else is a library fault."""
    done = cells["outcome"] != B.PENDING
    if not np.all(cells["weights"][done] == np.asarray(w, dtype=np.float64)):
        raise LibraryError(f"a fixed-w evaluation changed the weights {format_w(w)}: learn = 0 is not honoured; "
                           "rebuild the library")


def evaluate(w: Sequence[float], protocol: str = "first", *, seed: int = 0, cells=None,
             max_trials: int = CEILING_MAX_TRIALS, success_steps: int | None = None,
             overrides: Mapping[str, Any] | None = None, threads: int = 0) -> np.ndarray:
    """Fixed-w evaluation in memory: the cells (all, or the indices / 'a-b' string ``cells``) of
    one grid run of fixed_config. KeyboardInterrupt if cancelled."""
    cfg = fixed_config(w, protocol, max_trials=max_trials, success_steps=success_steps, overrides=overrides)
    arr = grid.make_cells(seed, grid.parse_cell_indices(cells))
    res = grid.run_grid(cfg, arr, threads=threads, progress=False)
    if res.cancelled:
        raise KeyboardInterrupt
    check_weights_kept(arr, as_weights(w))
    return arr


def eval_dir(out: Path, w: Sequence[float], protocol: str, success_steps: int, max_trials: int) -> Path:
    cap = "" if protocol == "first" else str(max_trials)
    return Path(out) / EVALS_DIR / f"{weights_key(w)}_{protocol}{cap}_h{success_steps}"


def evaluate_into(out: Path, w: Sequence[float], protocol: str, *, seed: int, indices, max_trials: int,
                  success_steps: int, overrides: Mapping[str, Any], threads: int,
                  progress: bool) -> tuple[np.ndarray, dict]:
    """Fixed-w evaluation into a results directory (run_condition: checkpoints, resume of a
    matching directory); KeyboardInterrupt if interrupted (its finished cells are saved)."""
    over = dict(overrides)
    over.update(learn=0, max_trials=1 if protocol == "first" else max_trials, success_steps=success_steps)
    cells, record, cancelled = run_condition(
        condition="ico", out=out, seed=seed, threads=threads, overrides=over, cell_spec=indices,
        resume=results.exists(out), progress=progress, info=FixedWeights(tuple(w), protocol),
        start_over="use another --out")
    if cancelled:
        raise KeyboardInterrupt
    check_weights_kept(cells, w)
    return cells, record


SUMMARY_KEYS = ("n_cells", "n_interior", "n_success", "n_success_interior", "success_rate",
                "success_rate_interior", "median_trials_to_success", "max_trials_to_success", "total_trials",
                "outcomes", "success_within")


def protocol_summary(cells: np.ndarray, record: Mapping[str, Any] | None = None,
                     root: Path | None = None, directory: Path | None = None) -> dict[str, Any]:
    s = metrics.summary(cells)
    out = {k: s[k] for k in SUMMARY_KEYS}
    if record is not None:
        out["max_trials"] = record["config"]["run"]["max_trials"]
        out["success_steps"] = record["config"]["run"]["success_steps"]
        out["wall_time"] = record.get("wall_time")
    if directory is not None:
        out["dir"] = str(directory.relative_to(root)) if root is not None else str(directory)
    return out


# -- screening -----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Screen:
    """Screening result of one w (first protocol, screen_steps): its score is (n_success, total_steps)."""
    n_success: int
    n_success_interior: int
    total_steps: int

    @property
    def key(self) -> tuple[int, int]:
        return (self.n_success, self.total_steps)


def screen_cells(w: Sequence[float], cells: np.ndarray, cfg_for: Callable[[Sequence[float]], RunConfig],
                 threads: int) -> Screen:
    """One screening run of w on a copy of ``cells`` (PENDING template cells)."""
    arr = cells.copy()
    res = grid.run_grid(cfg_for(w), arr, threads=threads, progress=False)
    if res.cancelled:
        raise KeyboardInterrupt
    check_weights_kept(arr, w)
    ok = metrics.success_mask(arr)
    return Screen(int(ok.sum()), int((ok & geometry.interior_mask(arr)).sum()), int(arr["total_steps"].sum()))


def _key(entry: Mapping[str, Any]) -> tuple[int, int]:
    return (entry["n_success"], entry["total_steps"])


class _Budget(Exception):
    """The candidate budget is spent."""


@dataclass
class SearchResult:
    starts: list[dict]
    trace: list[dict]       # every screened candidate in order: index, phase, label, w, score
    best: dict              # the incumbent: the best screened candidate (first of equals)
    stop: str               # "budget", or "exhausted" (every start and random candidate refined)
    refinement_steps: list[float]
    refinement_origins: list[int]   # index of the candidate each refinement started from

    def ranked(self) -> list[dict]:
        """Screened candidates, best first (ties: earlier first)."""
        return sorted(self.trace, key=lambda e: (-e["n_success"], -e["total_steps"], e["index"]))


def _clip(w: np.ndarray) -> np.ndarray:
    lo, hi = CLIP_MAGNITUDES
    return np.sign(w) * np.clip(np.abs(w), lo, hi)


def search(screen: Callable[[tuple[float, ...]], Screen], starts: Sequence[tuple[str, Sequence[float]]],
           candidates: int, seed: int, report: Callable[[dict, dict], None] | None = None) -> SearchResult:
    """The search of the module docstring: ``candidates`` distinct w are screened by ``screen``
    (starting points first), the random phase takes half of what remains, refinement the rest."""
    if isinstance(candidates, bool) or not isinstance(candidates, int) or candidates < 1:
        raise UsageError(f"--candidates must be an integer >= 1, got {candidates!r:.40}")
    rng = np.random.default_rng([int(grid.check_seed(seed)), SEARCH_STREAM])
    trace: list[dict] = []
    seen: dict[tuple[float, ...], dict] = {}
    state: dict[str, Any] = {"best": None}

    def trial(w, phase: str, label: str) -> dict:
        w = as_weights(w if phase == "start" else _clip(np.asarray(w, dtype=np.float64)), "candidate")
        if w in seen:
            return seen[w]
        if len(trace) >= candidates:
            raise _Budget
        s = screen(w)
        entry = {"index": len(trace), "phase": phase, "label": label, "w": list(w), **asdict(s)}
        trace.append(entry)
        seen[w] = entry
        if state["best"] is None or _key(entry) > _key(state["best"]):
            state["best"] = entry
        if report is not None:
            report(entry, state["best"])
        return entry

    start_list = [(label, as_weights(w, f"starting point {label}")) for label, w in starts]
    steps: list[float] = []
    origins: list[int] = []
    stop = "exhausted"
    try:
        for label, w in start_list:
            trial(w, "start", label)
        n_random = max(0, (candidates - len(trace)) // 2)
        bases = [np.asarray(w) for _, w in start_list] or [np.asarray(TYPICAL_ICO_WEIGHTS)]
        lo, hi = (math.log(v) for v in GLOBAL_MAGNITUDES)
        for k in range(n_random):
            if k % 2 == 0:
                mag = np.exp(rng.uniform(lo, hi, B.N_INPUTS))
                signs = np.ones(B.N_INPUTS) if rng.random() < 0.5 else rng.choice([-1.0, 1.0], B.N_INPUTS)
                trial(signs * mag, "random", "global")
            else:
                b = int(rng.integers(len(bases)))
                flips = np.where(rng.random(B.N_INPUTS) < LOCAL_FLIP, -1.0, 1.0)
                trial(bases[b] * flips * np.exp(LOCAL_SPREAD * rng.standard_normal(B.N_INPUTS)), "random",
                      f"near {start_list[b][0] if start_list else 'typical'}")
        origins_left = sorted(trace, key=lambda e: (-e["n_success"], -e["total_steps"], e["index"]))
        for origin in origins_left:
            origins.append(origin["index"])
            incumbent = origin
            step = STEP_START
            while step >= STEP_MIN:
                steps.append(step)
                w0 = np.asarray(incumbent["w"], dtype=np.float64)
                moves = []
                for i in range(B.N_INPUTS):
                    for sign in (1.0, -1.0):
                        w = w0.copy()
                        w[i] *= math.exp(sign * step)
                        moves.append((w, f"{W_NAMES[i]} x e^{sign * step:+g}"))
                for _ in range(GAUSS_MOVES):
                    moves.append((w0 * np.exp(step * rng.standard_normal(B.N_INPUTS)), f"gauss {step:g}"))
                round_best = incumbent
                for w, label in moves:
                    entry = trial(w, "refine", label)
                    if _key(entry) > _key(round_best):
                        round_best = entry
                if round_best is incumbent:
                    step /= 2.0
                else:
                    incumbent = round_best
    except _Budget:
        stop = "budget"
    return SearchResult(starts=[{"label": label, "w": list(w)} for label, w in start_list], trace=trace,
                        best=state["best"], stop=stop, refinement_steps=steps, refinement_origins=origins)


# -- starting points -----------------------------------------------------------------------------------
def linearise(cfg: RunConfig, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of one plant step at the upright state with zero force, by central differences of
    the C plant step (icoac_sim_plant_step): s' ~ A s + B F."""
    plant = cfg.plant

    def step(s, force):
        s = np.array(s, dtype=np.float64)
        B.check_status(B.lib.icoac_sim_plant_step(ctypes.byref(plant), s, float(force)), "plant step")
        return s

    eye = np.eye(B.N_INPUTS)
    a = np.column_stack([(step(h * eye[j], 0.0) - step(-h * eye[j], 0.0)) / (2 * h) for j in range(B.N_INPUTS)])
    b = ((step(np.zeros(B.N_INPUTS), h) - step(np.zeros(B.N_INPUTS), -h)) / (2 * h)).reshape(B.N_INPUTS, 1)
    return a, b


def lqr_gain(a: np.ndarray, b: np.ndarray, q: np.ndarray, r: float, iterations: int = 200_000) -> np.ndarray | None:
    """K of the discrete LQR (u = -K s) by Riccati iteration; None if it does not converge."""
    p = q.copy()
    rr = np.array([[r]])
    for _ in range(iterations):
        k = np.linalg.solve(rr + b.T @ p @ b, b.T @ p @ a)
        p_next = q + a.T @ p @ (a - b @ k)
        if not np.all(np.isfinite(p_next)):
            return None
        if np.max(np.abs(p_next - p)) <= 1e-11 * max(1.0, float(np.max(np.abs(p_next)))):
            return k.ravel()
        p = p_next
    return None


def lqr_starts(cfg: RunConfig) -> list[tuple[str, tuple[float, ...]]]:
    """LQR gains of the linearised plant as weights, one per R = 1 / F^2 (LQR_FORCES)."""
    gain = float(cfg.controller.policy.gain)
    if gain <= 0:
        return []
    ranges = np.array(list(cfg.controller.policy.input_range)[:B.N_INPUTS], dtype=np.float64)
    a, b = linearise(cfg)
    q = np.diag(1.0 / ranges ** 2)
    out = []
    for force in LQR_FORCES:
        k = lqr_gain(a, b, q, 1.0 / force ** 2)
        if k is None:
            continue
        w = -k * ranges / gain
        if np.all(np.isfinite(w)) and np.all(np.abs(w) <= 1e6):
            out.append((f"lqr R=1/{force:g}^2", as_weights(w)))
    return out


# -- the first-step bound ---------------------------------------------------------------------------------
def initial_states(cfg: RunConfig, cells: np.ndarray) -> np.ndarray:
    """(n, 4) start states of each cell's first trial, as the engine draws them: icoac_sim_trajectory
    of one step from (x0, theta0) with the cell's seed records the start first."""
    out = np.zeros((cells.size, B.N_INPUTS))
    states = np.zeros(2 * B.N_INPUTS)
    forces = np.zeros(1)
    n = ctypes.c_int64(0)
    prior = ctypes.byref(cfg.prior) if cfg.prior is not None else None
    for i, cell in enumerate(cells):
        status = B.lib.icoac_sim_trajectory(ctypes.byref(cfg.controller), ctypes.byref(cfg.plant), prior,
                                            float(cell["x0"]), float(cell["theta0"]),
                                            float(cfg.run.init_velocity_noise), int(cell["seed"]), 1,
                                            states, forces, ctypes.byref(n))
        B.check_status(status, "trajectory")
        out[i] = states[:B.N_INPUTS]
    return out


def first_step_bound(cfg: RunConfig, cells: np.ndarray, threads: int = 0) -> dict[str, Any]:
    """Cells lost at the first step whatever the force (module docstring), for the cells of
    ``cells`` (PENDING template) and the run's initial-velocity noise; cfg gives plant and noise."""
    n = int(cells.size)
    inner = geometry.interior_mask(cells)
    base = {"protocol": "first", "n_cells": n, "n_interior": int(inner.sum())}
    if int(cfg.plant.integrator) != B.INTEGRATORS["euler"]:
        return {**base, "computed": False,
                "reason": "defined for the Euler integrator only (with RK4 the force enters x and theta "
                          "within the first step)"}
    plant = ctypes.byref(cfg.plant)
    s0 = initial_states(cfg, cells)
    failed = np.zeros((len(BOUND_FORCES), n), dtype=bool)
    after = np.zeros((n, B.N_INPUTS))
    for k, force in enumerate(BOUND_FORCES):
        for i in range(n):
            s = s0[i].copy()
            B.check_status(B.lib.icoac_sim_plant_step(plant, s, float(force)), "plant step")
            failed[k, i] = bool(B.lib.icoac_sim_failed(plant, s))
            if force == 0.0:
                after[i] = s
    lost = failed.all(axis=0)
    if not np.array_equal(lost, failed.any(axis=0)):
        raise LibraryError("failure at the first Euler step depends on the force; the first-step bound's "
                           "premise does not hold for this plant")
    # The engine itself: one trial of 1 step per cell; the lost cells are exactly its failures.
    probe = RunConfig(controller=B.Config.from_buffer_copy(cfg.controller), plant=B.Plant.from_buffer_copy(cfg.plant),
                      run=B.Run.from_buffer_copy(cfg.run), prior=cfg.prior)
    probe.run.max_trials, probe.run.success_steps = 1, 1
    eng = cells.copy()
    run = grid.run_grid(probe, eng, threads=threads, progress=False)
    if run.cancelled:
        raise KeyboardInterrupt
    eng_lost = (eng["outcome"] == B.FAILED) & (eng["last_trial_steps"] == 1)
    if not np.array_equal(eng_lost, lost):
        raise LibraryError(f"first-step bound: the engine loses {int(eng_lost.sum())} cells at step 1, the plant "
                           f"steps {int(lost.sum())}; the recomputed initial velocities do not match the engine's")
    rows, cols = geometry.grid_index(cells)
    xl, tl = float(cfg.plant.x_limit), float(cfg.plant.theta_limit)
    lost_cells = []
    for i in np.flatnonzero(lost):
        x1, th1 = after[i, 0], after[i, 2]
        exits = [name for name, hit in (("x > x_limit", x1 > xl), ("x < -x_limit", x1 < -xl),
                                        ("theta > theta_limit", th1 > tl), ("theta < -theta_limit", th1 < -tl))
                 if hit]
        lost_cells.append({"cell": int(geometry.cell_index(rows[i], cols[i])), "x0": float(s0[i, 0]),
                           "theta0_deg": float(np.degrees(s0[i, 2])), "x_dot0": float(s0[i, 1]),
                           "theta_dot0": float(s0[i, 3]), "exits": exits})
    n_lost, n_lost_in = int(lost.sum()), int((lost & inner).sum())
    return {**base, "computed": True, "integrator": "euler", "forces_tested": list(BOUND_FORCES),
            "engine_agrees": True, "init_velocity_noise": float(cfg.run.init_velocity_noise),
            "n_lost": n_lost, "n_lost_interior": n_lost_in,
            "n_boundary": int((~inner).sum()),
            "max_success": n - n_lost, "max_success_interior": int(inner.sum()) - n_lost_in,
            "success_rate_bound": (n - n_lost) / n if n else None,
            "success_rate_interior_bound": (int(inner.sum()) - n_lost_in) / int(inner.sum()) if inner.any() else None,
            "lost_cells": lost_cells}


# -- the screening store (search.json) ---------------------------------------------------------------
class _Store:
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


# -- the command -----------------------------------------------------------------------------------------
@dataclass
class CeilingOptions:
    """What `ceiling` runs (see harness.cli): a given w (no search) or the search, the protocols of
    the final evaluation, caps, cells, budgets."""
    out: Path
    prior_from: Path | None = None
    w: Sequence[float] | str | None = None
    protocol: str = "both"
    max_trials: int = CEILING_MAX_TRIALS
    success_steps: int | None = None
    cells: str | Sequence[int] | None = None
    candidates: int | None = None
    screen_steps: int | None = None
    confirm: int | None = None
    seed: int = 0
    threads: int = 0
    sets: Sequence[str] = ()
    quiet: bool = False


def _positive(name: str, value: Any, hi: int = INT64_MAX) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= int(value) <= hi:
        raise UsageError(f"{name} must be an integer in [1, {hi}], got {value!r:.40}")
    return int(value)


def _log(quiet: bool, message: str) -> None:
    if not quiet:
        print(f"[ceiling] {message}", file=sys.stderr, flush=True)


def run_ceiling(opt: CeilingOptions, argv: Sequence[str] = ()) -> int:
    """Validate everything, then search (or take --w), evaluate, bound, summarise; 130 if interrupted
    (finished screens and cells are kept; the same command resumes)."""
    t_start = time.monotonic()
    out = store.check_out_dir(opt.out)
    protocols = protocols_of(opt.protocol)
    seed = grid.check_seed(opt.seed, "--seed")
    threads = grid.check_threads(opt.threads)
    max_trials = _positive("--max-trials", opt.max_trials)
    overrides = check_overrides(opt.sets)
    try:
        indices = grid.parse_cell_indices(opt.cells)
    except B.ConfigError as exc:
        raise UsageError(f"--cells: {exc}") from None
    probe = fixed_config(TYPICAL_ICO_WEIGHTS, "retries", max_trials=max_trials, success_steps=opt.success_steps,
                         overrides=overrides)  # C checks of everything
    success_steps = int(probe.run.success_steps)
    given = None
    if opt.w is not None:
        given = parse_weights(opt.w) if isinstance(opt.w, str) else as_weights(opt.w, "--w")
        extra = [name for name, v in (("--prior-from", opt.prior_from), ("--candidates", opt.candidates),
                                      ("--screen-steps", opt.screen_steps), ("--confirm", opt.confirm)) if v is not None]
        if extra:
            raise UsageError(f"--w evaluates the given w without a search; {', '.join(extra)} apply to the search")
        fixed_config(given, "first", success_steps=success_steps, overrides=overrides)
    candidates = _positive("--candidates", CEILING_CANDIDATES if opt.candidates is None else opt.candidates,
                           CEILING_MAX_CANDIDATES)
    screen_steps = _positive("--screen-steps", CEILING_SCREEN_STEPS if opt.screen_steps is None else opt.screen_steps)
    confirm = _positive("--confirm", CEILING_CONFIRM if opt.confirm is None else opt.confirm, CEILING_MAX_CANDIDATES)
    if given is None and screen_steps > success_steps:
        raise UsageError(f"--screen-steps {screen_steps} is longer than the full horizon --success-steps "
                         f"{success_steps}")
    prior_info = None
    typical = ("typical ICO", as_weights(TYPICAL_ICO_WEIGHTS))
    if opt.prior_from is not None:
        prior_info = P.from_results(opt.prior_from)
        typical = ("ICO mean (--prior-from)", as_weights(prior_info.mean, "--prior-from mean"))
    template = grid.make_cells(seed, indices)
    screen_settings = None
    if given is None:
        base = fixed_config(TYPICAL_ICO_WEIGHTS, "first", success_steps=screen_steps, overrides=overrides).to_dict()
        base["prior"] = None
        screen_settings = {"seed": seed, "cells": indices, "screen_steps": screen_steps, "config": base}
    with store.DirectoryLock(out) as held:  # the whole run: search.json, evals/, ceiling.json
        screens = None
        if screen_settings is not None:
            screens = _Store(out / SEARCH_FILE, screen_settings, held.dir_fd)
            screens.load()
        git = results.git_info()

        settings = {"seed": seed, "cells": indices, "n_cells": int(template.size), "protocol": opt.protocol,
                    "max_trials": max_trials, "success_steps": success_steps, "set": overrides,
                    "w": list(given) if given is not None else None, "threads": threads,
                    "prior_from": None if prior_info is None else {
                        "path": prior_info.source, "mean": list(prior_info.mean), "n_cells": prior_info.n_cells,
                        "commit": prior_info.source_commit}}
        if given is None:
            settings.update(candidates=candidates, screen_steps=screen_steps, confirm=confirm)
        record: dict[str, Any] = {"format_version": FORMAT_VERSION, "command": "ceiling", "argv": list(argv),
                                  "settings": settings, "git": git, "abi": B.abi_info(),
                                  "policy": {"gain": float(probe.controller.policy.gain),
                                             "reflex_mode": probe.to_dict()["controller"]["policy"]["reflex_mode"],
                                             "reflex_force": float(probe.controller.policy.reflex_force)}}

        def full_eval(w, protocol):
            d = eval_dir(out, w, protocol, success_steps, max_trials)
            cells, rec = evaluate_into(d, w, protocol, seed=seed, indices=indices, max_trials=max_trials,
                                       success_steps=success_steps, overrides=overrides, threads=threads,
                                       progress=not opt.quiet)
            return protocol_summary(cells, rec, out, d)

        try:
            _log(opt.quiet, f"first-step bound on {template.size} cells ...")
            bound = first_step_bound(probe, template, threads)
            record["first_step_bound"] = bound
            if bound.get("computed"):
                _log(opt.quiet, f"  {bound['n_lost']} cells lost at step 1 whatever the force "
                                f"({bound['n_lost_interior']} interior): at most {bound['max_success']} of "
                                f"{bound['n_cells']}")
            if given is None:
                cfg_cache: dict = {}

                def cfg_for(w):
                    if w not in cfg_cache:
                        cfg_cache.clear()
                        cfg_cache[w] = fixed_config(w, "first", success_steps=screen_steps, overrides=overrides)
                    return cfg_cache[w]

                def screen(w):
                    s = screens.get(w)
                    if s is None:
                        s = screen_cells(w, template, cfg_for, threads)
                        screens.add(w, s)
                    return s

                def report(entry, best):
                    if entry is best or (entry["index"] + 1) % 50 == 0:
                        _log(opt.quiet, f"  #{entry['index'] + 1}/{candidates} {entry['phase']} ({entry['label']}): "
                                        f"{entry['n_success']} cells; best {best['n_success']} {format_w(best['w'])}")

                starts = [typical] + lqr_starts(probe)
                _log(opt.quiet, f"search: {candidates} candidates screened at {screen_steps} steps (first trial), "
                                f"{len(starts)} starting points")
                t0 = time.monotonic()
                res = search(screen, starts, candidates, seed, report=report)
                screens.flush()
                screen_wall = time.monotonic() - t0
                _log(opt.quiet, f"  {len(res.trace)} screened ({screens.reused} from {SEARCH_FILE}) in "
                                f"{screen_wall:.1f} s, stop: {res.stop}")
                confirmed = []
                t0 = time.monotonic()
                for entry in res.ranked()[:confirm]:
                    w = tuple(entry["w"])
                    summ = full_eval(w, "first")
                    confirmed.append({"index": entry["index"], "w": list(w), "screen": {
                        k: entry[k] for k in ("n_success", "n_success_interior", "total_steps")}, "first": summ})
                    _log(opt.quiet, f"  confirm #{entry['index'] + 1} {format_w(w)}: {summ['n_success']} of "
                                    f"{summ['n_cells']} at {success_steps} steps")
                best = max(confirmed, key=lambda c: (c["first"]["n_success"], c["first"]["n_success_interior"],
                                                     c["screen"]["n_success"], c["screen"]["total_steps"], -c["index"]))
                record["search"] = {
                    "candidates": candidates, "screen_steps": screen_steps, "confirm": confirm, "seed": seed,
                    "stop": res.stop, "refinement_steps": res.refinement_steps,
                    "refinement_origins": res.refinement_origins, "screened": len(res.trace),
                    "phases": {p: sum(1 for e in res.trace if e["phase"] == p) for p in ("start", "random", "refine")},
                    "reused_screens": screens.reused, "screen_wall_time": screen_wall,
                    "confirm_wall_time": time.monotonic() - t0,
                    "starts": res.starts, "screen_best": res.best, "confirmed": confirmed, "trace": res.trace}
                best_w = tuple(best["w"])
                protos = {"first": best["first"]}
                source = "search"
            else:
                best_w, protos, source = given, {}, "--w"
            for protocol in protocols:
                if protocol not in protos:
                    _log(opt.quiet, f"{protocol} protocol of {format_w(best_w)} at {success_steps} steps ...")
                    protos[protocol] = full_eval(best_w, protocol)
            record["best"] = {"w": list(best_w), "source": source,
                              "protocols": {p: protos[p] for p in CEILING_PROTOCOLS if p in protos}}
        except KeyboardInterrupt:
            if screens is not None:
                screens.flush()
            print("interrupted: finished screens and cells are saved; rerun the same command to resume",
                  file=sys.stderr)
            return 130
        record["timestamp"] = results.timestamp()
        record["wall_time"] = time.monotonic() - t_start
        text = summary_markdown(record)
        store.write_json(out / CEILING_FILE, record, indent=1, dir_fd=held.dir_fd)
        store.write_text(out / SUMMARY_MD, text, dir_fd=held.dir_fd)
        print(text, end="")
        print(f"wall time {record['wall_time']:.1f} s -> {out / CEILING_FILE}")
        return 0


# -- reports --------------------------------------------------------------------------------------------
def _count(s: Mapping[str, Any], key: str, den: str, rate: str) -> str:
    return f"{s[key]} of {s[den]} ({percent(s[rate])})"


def summary_markdown(record: Mapping[str, Any]) -> str:
    st = record["settings"]
    best = record["best"]
    pol = record.get("policy", {})
    lines = ["# Linear-policy ceiling (method.md, L5)", "",
             f"Policy F = G·wᵀx̃ + U with G = {pol.get('gain', 'n/a'):g} N, reflex {pol.get('reflex_mode')} "
             f"({pol.get('reflex_force', 'n/a'):g} N), no learning (learn = 0); seed {st['seed']}, "
             f"{st['n_cells']} cells{'' if st['cells'] is None else ' (subset)'}, horizon {st['success_steps']:g} "
             f"steps{'' if not st['set'] else ', --set ' + ', '.join(f'{k}={v}' for k, v in st['set'].items())}.",
             "", f"Best w = (w_x, w_ẋ, w_θ, w_θ̇) = {format_w(best['w'], 6)} ({best['source']}).", "",
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
        lines += ["", f"Search: {s['screened']} candidates screened at {s['screen_steps']} steps, first trial "
                      f"({ph['start']} starting points, {ph['random']} random, {ph['refine']} refinement; stop: "
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
