# SPDX-License-Identifier: Apache-2.0
"""The Gymnasium side (icoac.gym): the registered cart-pole env against the engine it must
reproduce, the controller as a policy, Gymnasium's own CartPole-v1 under a continuous force."""
import ctypes
import re
import subprocess
import sys
import warnings
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from gymnasium.error import ResetNeeded
from gymnasium.utils.env_checker import check_env

import icoac.gym as hg
from icoac.core import binding as B
from icoac.core import geometry
from icoac.gym import plants as gym_plants
from icoac.studies.ceiling.fixed import fixed_config
from icoac.core.config import build_config
from icoac.core.grid import plant_grid, run_cell, trajectory
from icoac.core.options import TYPICAL_ICO_WEIGHTS

REPO = Path(__file__).resolve().parents[2]
ENV_ID = "icoac/CartPole-v0"
CENTRE, CORNER = 612, 0          # paper-grid cells: theta0 = 0, x0 = 0; theta0 = -12 deg, x0 = -2.4 m
# check_env's advice that this env does not follow, on purpose: the action is a force in N, and
# the observation is unbounded (a failing step is observed as it is, however far out).
KNOWN_WARNINGS = ("symmetric and normalized space", "minimum value is -infinity", "maximum value is infinity")


def make(steps=None, **kwargs):
    return gymnasium.make(ENV_ID, **({} if steps is None else {"max_episode_steps": steps}), **kwargs)


def c_model_step(model, s, force):
    """icoac_sim_model_step on a cart-pole state of 4 (in place)."""
    full = np.zeros(B.MAX_STATE)
    full[:4] = s
    B.check_status(B.lib.icoac_sim_model_step(ctypes.byref(model), full, force))
    s[:] = full[:4]


def c_model_failed(model, s):
    full = np.zeros(B.MAX_STATE)
    full[:4] = s
    failed = ctypes.c_int32(-1)
    B.check_status(B.lib.icoac_sim_model_failed(ctypes.byref(model), full, ctypes.byref(failed)))
    return bool(failed.value)


def test_registered_and_passes_check_env():
    env = make()
    assert env.spec.id == ENV_ID and env.spec.max_episode_steps == build_config().run.success_steps
    assert env.action_space.shape == (1,) and env.action_space.high[0] == B.constant("ICOAC_FORCE_MAX")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    unexpected = [str(w.message) for w in caught if not any(k in str(w.message) for k in KNOWN_WARNINGS)]
    assert unexpected == []
    # the "module:id" form imports the package first
    assert gymnasium.make("icoac.gym:" + ENV_ID).spec.id == ENV_ID


def test_vector_env():
    envs = gymnasium.make_vec(ENV_ID, num_envs=2, vectorization_mode="sync", max_episode_steps=20)
    obs, info = envs.reset(seed=1)
    assert obs.shape == (2, 4) and info["cell_seed"].dtype == np.uint64  # seeds beyond int64 kept
    for _ in range(30):
        obs, reward, terminated, truncated, info = envs.step(np.zeros((2, 1)))
    assert obs.shape == (2, 4) and np.all(np.isfinite(obs))


# (w, cell, steps the engine's trial lasts): it balances for the whole 1500 steps, or falls
@pytest.mark.parametrize("w, cell, lasts", [(TYPICAL_ICO_WEIGHTS, CENTRE, 1500), (TYPICAL_ICO_WEIGHTS, 100, 36),
                                            ((0, 0, 0, 0), CENTRE, 295), (TYPICAL_ICO_WEIGHTS, CORNER, 2)])
def test_fixed_w_episode_equals_the_engine_trajectory(w, cell, lasts):
    """Same start (the engine's draw for the cell), same forces, same states, bit for bit."""
    steps, grid_seed = 1500, 7
    cfg = fixed_config(w)
    policy = hg.IcoacPolicy(cfg)
    episode = policy.run_episode(make(steps), options={"cell": cell, "grid_seed": grid_seed}, trace=True)
    cells = plant_grid("cart_pole", grid_seed)
    assert episode.reset_info == {"cell": cell, "grid_seed": grid_seed, "cell_seed": int(cells[cell]["seed"])}
    engine = trajectory(cfg, cells[cell]["x0"], cells[cell]["theta0"], duration=steps * cfg.model.dt,
                        seed=int(cells[cell]["seed"]))
    assert episode.steps == engine.n_steps == lasts
    assert np.array_equal(episode.forces, engine.forces)
    assert np.array_equal(episode.observations, engine.states)
    assert episode.terminated == (lasts < steps) and episode.truncated == (lasts == steps)
    assert np.array_equal(policy.weights, np.asarray(w, dtype=B.real_dtype))  # learn = 0: w kept


def assert_episodes_are_the_engine_trials(policy, env, cell, trials, engine):
    """Episodes from the grid cell (seed 0), until the cap or a truncated (balanced) episode, are
    the engine's trials of that cell: their number, lengths and the learned weights."""
    episodes = []
    while len(episodes) < trials and not (episodes and episodes[-1].truncated):
        episodes.append(policy.run_episode(env, options={"cell": cell, "grid_seed": 0}))
    assert len(episodes) == engine["trials"]
    assert sum(e.steps for e in episodes) == engine["total_steps"]
    assert episodes[-1].steps == engine["last_trial_steps"]
    assert np.array_equal(policy.weights, engine["weights"][:policy.config.n_inputs])


@pytest.mark.parametrize("condition, cell", [("ico", 759), ("rl", 759), ("search", 1010)])
def test_learning_episodes_equal_the_engine_trial_loop(condition, cell):
    """K episodes of a learning controller on the env = the engine's cell run of K trials from the
    same cell (no initial velocity noise, so that every trial of the engine starts where the
    env's reset puts it): same trial lengths in total, same final weights and covariance."""
    trials, horizon = 12, 400  # cells: theta0 = 3 deg, x0 = 0; theta0 = 8 deg, x0 = 0.6 m
    cfg = build_config({"max_trials": trials, "success_steps": horizon, "init_velocity_noise": 0},
                       condition=condition)
    cells = plant_grid("cart_pole", 0)
    seed = int(cells[cell]["seed"])
    engine = run_cell(cfg, cells[cell]["x0"], cells[cell]["theta0"], seed=seed)
    policy = hg.IcoacPolicy(cfg, seed=int(B.lib.icoac_mix_seed(seed, 1)))
    assert_episodes_are_the_engine_trials(policy, make(horizon, init_velocity_noise=0), cell, trials, engine)
    assert np.array_equal(policy.covariance, engine["cov"][:4, :4])
    assert np.any(policy.weights != 0)  # it learned from the prior mean 0


def test_reset_draws_and_options():
    env = make()
    a, info_a = env.reset(seed=5)
    b, info_b = env.reset(seed=5)
    assert np.array_equal(a, b) and info_a == info_b and 0 <= info_a["cell"] < geometry.CELLS
    start = np.array([0.1, -0.2, 0.05, 0.3])
    obs, info = env.reset(options={"state": start})
    assert np.array_equal(obs, start) and info == {}
    obs, _, terminated, truncated, info = env.step(np.array([2.5]))
    c_model_step(env.unwrapped.parameters.model, start, 2.5)
    assert np.array_equal(obs, start) and not terminated and not truncated and info["force"] == 2.5
    for bad in ({"state": [0, 0, np.nan, 0]}, {"state": [0, 0]}, {"state": "abc"}, {"cell": geometry.CELLS},
                {"cell": 1.5}, {"grid_seed": -1}, {"state": [0, 0, 0, 0], "cell": 3}, {"theta0": 0.1}):
        with pytest.raises(ValueError, match="reset option|unknown reset option"):
            env.reset(options=bad)


def test_plant_parameters_reach_the_c_plant():
    env = make(dt=0.02, integrator="rk4", pole_mass=0.2)
    model = env.unwrapped.parameters.model
    pole_mass = [p["name"] for p in B.plant_info("cart_pole")["params"]].index("pole_mass")
    assert (model.dt, model.integrator, model.param[pole_mass]) == (0.02, B.INTEGRATORS["rk4"], 0.2)
    assert env.unwrapped.dt == 0.02
    s, _ = env.reset(seed=1)
    obs, *_ = env.step([-3.0])
    c_model_step(model, s, -3.0)
    assert np.array_equal(obs, s)
    with pytest.raises(B.ConfigError):
        make(gravity=-1.0)
    with pytest.raises(ValueError, match="unknown cart_pole parameter 'gain'"):
        make(gain=3)
    with pytest.raises(ValueError, match="render_mode"):
        hg.IcoacPlantEnv(render_mode="human")
    with pytest.raises(ValueError, match="force_limit"):
        make(force_limit=0)


def test_bad_actions_and_order():
    env = make(force_limit=50.0)
    with pytest.raises(ResetNeeded):
        env.step([0.0])
    env.reset(options={"cell": CORNER, "grid_seed": 0})
    for bad in ([np.nan], [np.inf], [1.0, 2.0], "left", "1.5", True, None, []):
        with pytest.raises(ValueError, match="one finite force"):
            env.step(bad)
    _, _, _, _, info = env.step([1e6])
    assert info["force"] == 50.0  # clipped to the action bound
    raw = env.unwrapped
    raw.reset(options={"state": [2.39, 5.0, 0.0, 0.0]})
    assert raw.step([0.0])[2] is True  # x beyond 2.4 m
    # a step the plant cannot represent (it overflows) terminates, the state kept as it was
    start = [0.0, 0.0, 0.0, 1e300]
    raw.reset(options={"state": start})
    obs, _, terminated, _, _ = raw.step([0.0])
    assert terminated is True and np.array_equal(obs, start)
    with pytest.raises(ResetNeeded, match="terminated"):
        raw.step([0.0])


def test_policy_rejects_bad_observations():
    policy = hg.IcoacPolicy()
    policy.reset()
    for bad in ([0.0, 0.0, np.nan, 0.0], [np.inf, 0, 0, 0], [1e300, 0, 0, 0]):
        with pytest.raises(B.IcoacError, match="non-finite observation") as err:
            policy.act(bad)
        assert err.value.status == B.ERR_NONFINITE_INPUT
    for bad in ([0.0, 0.0, 0.0], "xyz", None, ["0", "0", "0", "0"], [True] * 4):
        with pytest.raises(ValueError, match="observation must be 4 numbers"):
            policy.act(bad)
    assert np.isfinite(policy.act([0.0, 0.0, 0.01, 0.0]))
    policy.learn_from_failure([0.0, 0.0, 0.3, 0.0])
    with pytest.raises(B.IcoacError, match="trial") as err:
        policy.act([0.0, 0.0, 0.0, 0.0])  # the episode ended: icoac_reset first
    assert err.value.status == B.constant("ICOAC_ERR_TRIAL_ENDED")
    with pytest.raises(ValueError, match="Box of one force"):
        policy.run_episode(gymnasium.make("CartPole-v1"))  # discrete action: needs the wrapper
    with pytest.raises(B.ConfigError):
        hg.IcoacPolicy(condition="no-such-condition")
    with pytest.raises(ValueError, match="seed"):
        hg.IcoacPolicy(seed=-1)


def test_continuous_cartpole_is_the_icoac_plant():
    """Gymnasium's CartPole under the wrapper with dt = 0.01 steps as icoac's C plant (default
    parameters) does, to float64 rounding, under the same force from the same state: same
    equations, signs and units (the two round differently, so each step starts from Gymnasium's)."""
    env = hg.continuous_cartpole(dt=0.01)
    model = build_config().engine_model()
    env.reset(seed=3)
    rng = np.random.default_rng(0)
    for k in range(200):
        s = np.array(env.unwrapped.state, dtype=np.float64)
        force = float(rng.uniform(-3, 3)) + 30.0 * s[2] + 5.0 * s[3]  # keeps the pole up
        obs, reward, terminated, truncated, info = env.step(np.array([force]))
        c_model_step(model, s, force)
        assert np.allclose(env.unwrapped.state, s, rtol=1e-13, atol=1e-16), k
        assert np.array_equal(obs, env.unwrapped.state.astype(np.float32)) and info["force"] == force
        assert terminated == c_model_failed(model, s) and not terminated
    # a push to +x makes theta fall toward -x in both
    env.reset(options={"low": 0.0, "high": 0.0})
    assert env.step([10.0])[0][3] < 0
    # left at Gymnasium's period
    assert hg.continuous_cartpole().unwrapped.tau == 0.02
    with pytest.raises(TypeError, match="CartPoleEnv"):
        hg.ContinuousCartPole(gymnasium.make("Pendulum-v1"))


def test_policy_learns_on_gymnasium_cartpole():
    env = hg.continuous_cartpole()
    policy = hg.IcoacPolicy(condition="ico", seed=1)
    before = policy.weights
    episodes = [policy.run_episode(env, seed=k) for k in range(6)]
    assert all(e.terminated and e.steps > 0 for e in episodes)
    assert not np.array_equal(policy.weights, before) and np.all(np.isfinite(policy.weights))
    assert policy.ticks == sum(e.steps + 1 for e in episodes)  # every step and each terminal tick
    for condition in ("rl", "search"):  # the other modes run there too
        other = hg.IcoacPolicy(condition=condition, seed=2)
        assert all(other.run_episode(env, seed=k).steps > 0 for k in range(3))


def test_readme_example_prints_what_the_readme_shows():
    text = (REPO / "README.md").read_text()
    section = text[text.index("## Gymnasium"):]
    code, shown = re.findall(r"```[a-z]*\n(.*?)```", section, re.S)[:2]
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout == shown


# -- the registry plants served through the model API ----------------------------------------------------
# Every registry plant (the cart-pole's env also tested above), by env id.
NEW_PLANTS = {f"icoac/{gym_plants.gym_name(name)}-v0": name for name in
              (B.plant_info(i)["name"] for i in range(B.lib.icoac_sim_plant_count()))}


def c_model_start(model, plant, cell, grid_seed, noise):
    """The start of a grid cell straight from C: the plant's grid, the engine's start generator."""
    info = B.plant_info(plant)
    cells = np.zeros(info["rows"]["count"] * info["cols"]["count"], dtype=B.CELL_DTYPE)
    B.check_status(B.lib.icoac_sim_plant_grid(info["index"], cells, cells.size, grid_seed))
    rng = B.Rng()
    B.lib.icoac_rng_seed(ctypes.byref(rng), int(cells[cell]["seed"]), B.constant("ICOAC_SIM_START_STREAM"))
    s = np.zeros(B.MAX_STATE)
    B.check_status(B.lib.icoac_sim_model_start(ctypes.byref(model), cells[cell:cell + 1], noise,
                                               ctypes.byref(rng), s))
    return s, cells[cell]


@pytest.mark.parametrize("env_id, plant", NEW_PLANTS.items())
def test_registry_plant_spaces_from_the_descriptor_and_check_env(env_id, plant):
    info = B.plant_info(plant)
    env = gymnasium.make(env_id)
    spec = env.unwrapped.plant
    assert env.spec.max_episode_steps == build_config().run.success_steps
    assert env.observation_space.shape == (len(info["state"]),) and env.action_space.shape == (1,)
    assert [(v.name, v.unit) for v in spec.state] == info["state"]
    assert (spec.action.name, spec.action.unit) == info["input"]
    assert set(spec.parameter_names) >= {p["name"] for p in info["params"]}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    assert [str(w.message) for w in caught if not any(k in str(w.message) for k in KNOWN_WARNINGS)] == []


@pytest.mark.parametrize("env_id, plant", NEW_PLANTS.items())
def test_zero_action_episode_equals_the_c_model(env_id, plant):
    """From a tilted grid cell, an episode under zero input = icoac_sim_model_step from the same
    start, bit for bit, and it terminates where icoac_sim_model_failed first says so."""
    g = geometry.of(plant)
    cell, grid_seed = int(g.cell_index(min(2, g.rows - 1), min(2, g.cols - 1))), 7  # row 2: 10 deg from upright
    env = gymnasium.make(env_id)
    obs, info = env.reset(options={"cell": cell, "grid_seed": grid_seed})
    model = B.model_default(plant)
    s, row = c_model_start(model, plant, cell, grid_seed, build_config().run.init_velocity_noise)
    n = len(B.plant_info(plant)["state"])
    assert info == {"cell": cell, "grid_seed": grid_seed, "cell_seed": int(row["seed"])}
    assert np.array_equal(obs, s[:n]) and np.any(s[:n] != 0)
    failed = ctypes.c_int32(0)
    for k in range(1, 2000):
        obs, reward, terminated, truncated, _ = env.step(np.zeros(1))
        B.check_status(B.lib.icoac_sim_model_step(ctypes.byref(model), s, 0.0))
        B.check_status(B.lib.icoac_sim_model_failed(ctypes.byref(model), s, ctypes.byref(failed)))
        assert np.array_equal(obs, s[:n]), k
        assert terminated == bool(failed.value) and not truncated and reward == 1.0
        if terminated:
            break
    assert terminated and k > 1  # it falls, not at once
    with pytest.raises(ResetNeeded):
        env.step(np.zeros(1))
    # truncation: the step limit, from the upright rest state
    short = gymnasium.make(env_id, max_episode_steps=5)
    short.reset(options={"state": np.zeros(n)})
    outcomes = [short.step(np.zeros(1))[2:4] for _ in range(5)]
    assert outcomes == [(False, False)] * 4 + [(False, True)]


@pytest.mark.parametrize("env_id, plant", NEW_PLANTS.items())
def test_registry_plant_parameters_and_bad_input(env_id, plant):
    info = B.plant_info(plant)
    first = info["params"][0]["name"]
    env = gymnasium.make(env_id, dt=0.02, integrator="rk4", init_velocity_noise=0.0,
                         **{first: 2 * info["params"][0]["value"]})
    model = env.unwrapped.parameters.model
    assert (model.dt, model.integrator, model.param[0]) == (0.02, B.INTEGRATORS["rk4"], 2 * info["params"][0]["value"])
    n = len(info["state"])
    obs, _ = env.reset(options={"cell": 0})
    assert np.all(obs[[i for i in range(n) if info["drawn"][i]]] == 0)  # no noise
    s = np.zeros(B.MAX_STATE)
    s[:n] = obs
    obs, *_ = env.step([0.5])
    B.check_status(B.lib.icoac_sim_model_step(ctypes.byref(model), s, 0.5))
    assert np.array_equal(obs, s[:n])
    env.reset(options={"state": np.zeros(n)})
    for bad in ([np.nan], [np.inf], [1.0, 2.0], "1.5", True):
        with pytest.raises(ValueError, match="one finite"):
            env.step(bad)
    # a step the plant cannot represent (it overflows) terminates, as on the cart-pole
    env.reset(options={"state": np.full(n, 1e300)})
    obs, _, terminated, _, _ = env.step([0.0])
    assert terminated is True and np.array_equal(obs, np.full(n, 1e300))
    with pytest.raises(B.ConfigError):
        gymnasium.make(env_id, **{first: -1.0})
    with pytest.raises(B.ConfigError):
        gymnasium.make(env_id, init_velocity_noise=-1.0)
    with pytest.raises(ValueError, match=f"unknown {plant} parameter 'pole_mas'"):
        gymnasium.make(env_id, pole_mas=1.0)
    for bad in ({"state": np.zeros(n + 1)}, {"state": [np.nan] * n}, {"cell": 10 ** 6}, {"theta0": 0}):
        with pytest.raises(ValueError, match="reset option"):
            env.reset(options=bad)


def test_policy_refuses_an_env_of_another_plant():
    """A task is for one plant: a policy refuses any env of another, even of the same size."""
    with pytest.raises(ValueError, match="task is for the cart_pole, but the env simulates the double_cart_pole"):
        hg.IcoacPolicy().run_episode(gymnasium.make("icoac/DoubleCartPole-v0"))
    with pytest.raises(ValueError, match="task is for the double_cart_pole, but the env simulates the cart_pole"):
        hg.IcoacPolicy(plant="double_cart_pole").run_episode(gymnasium.make("icoac/CartPole-v0"))
    with pytest.raises(ValueError, match="task is for the cart_pole, but the env simulates the furuta; build "
                                         "the policy with plant='furuta'"):
        hg.IcoacPolicy().run_episode(gymnasium.make("icoac/Furuta-v0"))
    with pytest.raises(ValueError, match="task is for the furuta, but the env simulates the cart_pole"):
        hg.IcoacPolicy(plant="furuta").run_episode(hg.continuous_cartpole())
    assert hg.IcoacPolicy(plant="furuta").run_episode(gymnasium.make("icoac/Furuta-v0"), seed=1).steps > 0


@pytest.mark.parametrize("env_id, plant", NEW_PLANTS.items())
def test_plant_episodes_equal_the_engine_trial_loop(env_id, plant):
    """IcoacPolicy with a plant's task settings on its env = the engine's cell run on the plant's
    model: same trial lengths, same learned weights (no initial velocity noise, so that every trial
    of the engine starts where the env's reset puts it)."""
    g = geometry.of(plant)
    trials, horizon = 10, 300
    cell = int(g.cell_index(min(5, g.rows - 1), g.cols // 2))  # the row component at -7 deg, the column's at 0
    cfg = build_config({"max_trials": trials, "success_steps": horizon, "init_velocity_noise": 0}, plant=plant)
    n = len(B.plant_info(plant)["state"])
    assert hg.IcoacPolicy(condition="ico", plant=plant).weights.shape == (n,)
    cells = np.zeros(g.cells, dtype=B.CELL_DTYPE)
    B.check_status(B.lib.icoac_sim_plant_grid(B.plant_index(plant), cells, cells.size, 0))
    seed = int(cells[cell]["seed"])
    engine = run_cell(cfg, cells[cell]["x0"], cells[cell]["theta0"], seed=seed)
    env = gymnasium.make(env_id, max_episode_steps=horizon, init_velocity_noise=0)
    policy = hg.IcoacPolicy(cfg, seed=int(B.lib.icoac_mix_seed(seed, 1)))
    assert_episodes_are_the_engine_trials(policy, env, cell, trials, engine)
    assert np.any(policy.weights != 0)  # it learned
