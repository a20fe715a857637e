# SPDX-License-Identifier: Apache-2.0
import ctypes
import math

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import geometry, options
from icoac.core.config import CONDITION_OVERRIDES, NAMED_CONFIGURATIONS, build_config, named_sets, parse_sets
from icoac.core.errors import LibraryError
from icoac.core.registry import CONDITIONS, REGISTRY


def test_struct_sizes_match_c():
    assert ctypes.sizeof(B.Config) == B.lib.icoac_sizeof_config()
    assert ctypes.sizeof(B.Prior) == B.lib.icoac_sizeof_prior()
    assert ctypes.sizeof(B.Run) == B.lib.icoac_sim_sizeof_run()
    assert B.CELL_DTYPE.itemsize == B.lib.icoac_sim_sizeof_cell()
    assert ctypes.sizeof(B.c_real) == B.lib.icoac_sizeof_real()
    assert ctypes.sizeof(B.Input) == B.lib.icoac_sizeof_input()
    assert ctypes.sizeof(B.Output) == B.lib.icoac_sizeof_output()
    for name, (py, c) in B.layout_report().items():
        assert py == c, name


def test_library_lookup_order(monkeypatch, tmp_path):
    """ICOAC_SIM_LIBRARY when set (even to a missing file); else the installed package's own
    library; else the checkout's development build."""
    package, build = tmp_path / "pkg" / "libicoac_sim.so", tmp_path / "build" / "libicoac_sim.so"
    monkeypatch.setattr(B, "PACKAGE_LIBRARY", package)
    monkeypatch.setattr(B, "DEFAULT_LIBRARY", build)
    monkeypatch.delenv(B.LIBRARY_ENV, raising=False)
    assert B._library_path() == (build, "build")
    package.parent.mkdir()
    package.write_bytes(b"")
    assert B._library_path() == (package, "package")
    monkeypatch.setenv(B.LIBRARY_ENV, str(tmp_path / "none.so"))
    assert B._library_path() == (tmp_path / "none.so", "env")
    monkeypatch.setenv(B.LIBRARY_ENV, "")   # empty: not set
    assert B._library_path() == (package, "package")
    with pytest.raises(LibraryError, match="make build"):
        B._load(tmp_path / "none.so", "env")
    package.unlink()
    with pytest.raises(LibraryError, match="installed package.*development build"):
        B._load(build, "build")


def test_checkout_is_not_an_installed_package():
    # harness/icoac/lib/ exists only in an installed package (pyproject.toml, the wheel build).
    assert not B.PACKAGE_LIBRARY.exists() or B.LIBRARY_SOURCE == "package"
    assert B.abi_info()["library_source"] == B.LIBRARY_SOURCE in ("env", "package", "build")


def test_state_is_opaque_aligned_storage():
    assert ctypes.sizeof(B.State) == B.lib.icoac_sizeof_state() == B.STATE_SIZE == B.CONSTANTS["ICOAC_STATE_SIZE"]
    assert ctypes.alignment(B.State) == 8
    assert [name for name, _ in B.State._fields_] == ["opaque"]  # no internal layout mirrored


def test_abi_versions():
    assert B.lib.icoac_abi_version() == B.ABI_VERSION == B.CONSTANTS["ICOAC_ABI_VERSION"] == 10
    assert B.lib.icoac_sim_abi_version() == B.SIM_ABI_VERSION == B.CONSTANTS["ICOAC_SIM_ABI_VERSION"] == 10
    info = B.abi_info()
    assert info["sizeof_real"] in (4, 8)
    # the host build's defaults: the dense critic kernel, two lanes per engine thread
    assert info["critic_kernel"] == "dense" and B.CONSTANTS["ICOAC_CRITIC_DENSE"] == 1
    assert info["max_lanes"] == B.CONSTANTS["ICOAC_SIM_MAX_LANES"] == 64


def test_every_mirror_matches_the_c_field_table():
    assert set(B.MIRRORS) <= set(B.FIELDS)
    for c_type, (mirror, _) in B.MIRRORS.items():
        assert B.mirror_fields(mirror) == B.FIELDS[c_type], c_type
    assert "policy.gain" in B.FIELDS["icoac_config_t"] and "actor.act_with_sample" in B.FIELDS["icoac_config_t"]
    for name in ("critic.quirks", "actor.update", "actor.rate", "actor.likelihood_std", "actor.batch",
                 "actor.explore_ticks", "search.batch", "search.elite_fraction", "search.step", "search.floor",
                 "search.cov_scale"):
        assert name in B.FIELDS["icoac_config_t"], name
    # the C field table covers icoac_config_t: every byte (float reals: no padding) or all but padding
    ends = sorted((off, off + size) for off, size in B.FIELDS["icoac_config_t"].values())
    covered = sum(e - o for o, e in ends)
    assert all(ends[i][1] <= ends[i + 1][0] for i in range(len(ends) - 1))
    assert covered == B.lib.icoac_sizeof_config() or (B.real_dtype == np.float64 and
                                                      covered < B.lib.icoac_sizeof_config())


class _WrongPolicy(ctypes.Structure):
    """icoac_policy_config_t with gain and clip_inputs swapped: same fields and size, wrong offsets."""
    _fields_ = [("input_range", B.c_real * B.MAX_INPUTS), ("gain", B.c_real), ("clip_inputs", ctypes.c_int32),
                ("reflex_mode", ctypes.c_int32), ("reflex_force", B.c_real)]


class _WrongConfig(ctypes.Structure):
    _fields_ = [("mode", ctypes.c_int32), ("learn", ctypes.c_int32), ("task", B.TaskConfig), ("policy", _WrongPolicy),
                ("ico", B.IcoConfig),
                ("critic", B.CriticConfig), ("actor", B.ActorConfig), ("search", B.SearchConfig)]


def test_field_check_catches_a_wrong_offset():
    assert ctypes.sizeof(_WrongConfig) == ctypes.sizeof(B.Config)
    offset = B.FIELDS["icoac_config_t"]["policy.clip_inputs"][0]
    with pytest.raises(LibraryError, match=rf"icoac_config_t\.policy\.clip_inputs: C offset {offset} size 4, "
                                           rf"binding offset {offset + 4}"):
        B.check_mirror("icoac_config_t", _WrongConfig, c_size=B.lib.icoac_sizeof_config())
    B.check_mirror("icoac_config_t", B.Config, c_size=B.lib.icoac_sizeof_config())


def test_field_check_catches_missing_extra_size_and_dtype():
    class Missing(ctypes.Structure):
        _fields_ = [("mean", B.c_real * B.N_INPUTS)]

    with pytest.raises(LibraryError, match=r"icoac_prior_t\.cov is in the C layout but not in the binding"):
        B.check_mirror("icoac_prior_t", Missing)

    class Extra(ctypes.Structure):
        _fields_ = B.Counters._fields_ + [("spare", ctypes.c_uint32)]

    with pytest.raises(LibraryError, match=r"icoac_counters_t\.spare is in the binding but not in the C layout"):
        B.check_mirror("icoac_counters_t", Extra)
    with pytest.raises(LibraryError, match=r"sizeof\(icoac_sim_run_t\): C 40, binding 32"):
        B.check_mirror("icoac_sim_run_t", B.Run, c_size=40)
    names = list(B.CELL_DTYPE.names)
    wrong = np.dtype([(n, B.CELL_DTYPE.fields[n][0]) if n != "outcome" else ("outcome", np.int64)
                      for n in names], align=True)
    with pytest.raises(LibraryError, match=r"icoac_sim_cell_t\.outcome: C offset 24 size 4, binding offset 24 size 8"):
        B.check_mirror("icoac_sim_cell_t", wrong)
    # a made-up table: the binding is checked against whatever C says
    table = dict(B.FIELDS["icoac_sim_model_t"], dt=(40, 8))
    with pytest.raises(LibraryError, match=r"icoac_sim_model_t\.dt: C offset 40"):
        B.check_mirror("icoac_sim_model_t", B.Model, c_fields=table)


def test_constants_from_c():
    c = B.CONSTANTS
    assert B.MODES == {"ico": c["ICOAC_MODE_ICO"], "rl": c["ICOAC_MODE_RL"], "search": c["ICOAC_MODE_SEARCH"]}
    assert B.MODE_SEARCH == c["ICOAC_MODE_SEARCH"] == 2
    assert B.ACTOR_UPDATES == {"posterior": c["ICOAC_ACTOR_POSTERIOR"], "mean": c["ICOAC_ACTOR_MEAN"],
                               "gradient": c["ICOAC_ACTOR_GRADIENT"]}
    assert B.ERR_BAD_SEARCH == c["ICOAC_ERR_BAD_SEARCH"] == 18 and B.ERR_BAD_SEARCH in B.CONFIG_STATUSES
    assert B.SEARCH_BATCH_MAX == c["ICOAC_SEARCH_BATCH_MAX"] and B.EXPLORE_TICKS_MAX == c["ICOAC_EXPLORE_TICKS_MAX"]
    assert B.REFLEX_MODES == {"unit": c["ICOAC_REFLEX_UNIT"], "gain": c["ICOAC_REFLEX_GAIN"]}
    assert B.ICO_TIMINGS == {"code": c["ICOAC_ICO_TIMING_CODE"], "literal": c["ICOAC_ICO_TIMING_LITERAL"]}
    assert B.INTEGRATORS == {"euler": c["ICOAC_SIM_EULER"], "rk4": c["ICOAC_SIM_RK4"]}
    assert B.ERR_NUMERIC == c["ICOAC_ERR_NUMERIC"] and B.SIM_CANCELLED == c["ICOAC_SIM_CANCELLED"]
    assert B.OUTCOME_NAMES == {c["ICOAC_SIM_PENDING"]: "pending", c["ICOAC_SIM_SUCCESS"]: "success",
                               c["ICOAC_SIM_FAILED"]: "failed", c["ICOAC_SIM_ERROR"]: "error"}
    assert B.CONFIG_STATUSES == {v for k, v in c.items() if k.startswith(("ICOAC_ERR_BAD_", "ICOAC_SIM_ERR_BAD_"))}
    assert geometry.CELLS == geometry.THETAS * geometry.XS == 1225
    assert geometry.N_INTERIOR == (geometry.THETAS - 2) * (geometry.XS - 2)
    assert B.PI == math.pi
    with pytest.raises(LibraryError, match="ICOAC_NO_SUCH"):
        B.constant("ICOAC_NO_SUCH")


def test_status_texts_from_both_libraries():
    assert B.status_str(B.ERR_NUMERIC) == B.lib.icoac_status_str(B.ERR_NUMERIC).decode()
    assert B.status_str(B.SIM_ERR_THREAD) == B.lib.icoac_sim_status_str(B.SIM_ERR_THREAD).decode()
    assert B.status_name(B.ERR_NUMERIC) == "numeric failure"
    assert B.status_name(B.SIM_CANCELLED) == "cancelled"


def test_counters_and_posterior_accessors():
    cfg = build_config()
    state = B.State()
    B.check_status(B.lib.icoac_init(ctypes.byref(cfg.controller), ctypes.byref(state), None, 1))
    inp, out = B.Input(), B.Output()
    for s in ([0.1, 0.0, 0.01, 0.0], [math.nan, 0.0, 0.0, 0.0], [0.1, 0.0, 0.02, 0.0]):
        for i, v in enumerate(s):
            inp.s[i] = v
        B.lib.icoac_step(ctypes.byref(state), ctypes.byref(inp), ctypes.byref(out))
    counters = B.get_counters(state)
    assert (counters.ticks, counters.nonfinite, counters.numeric_faults) == (3, 1, 0)
    post = B.get_posterior(state)
    # the cart-pole task's 4 x 4 block (N(0, I) without a prior), 0 past it
    eye = np.zeros((B.MAX_INPUTS, B.MAX_INPUTS))
    eye[:4, :4] = np.eye(4)
    assert list(post.mean) == [0.0] * B.MAX_INPUTS and [list(r) for r in post.cov] == eye.tolist()


def test_cell_dtype_offsets():
    names = B.CELL_DTYPE.names
    assert names == ("x0", "theta0", "seed", "outcome", "status", "trials", "total_steps",
                     "last_trial_steps", "elapsed_time", "weights", "cov")
    assert B.CELL_DTYPE.fields["weights"][1] == B.FIELDS["icoac_sim_cell_t"]["weights"][0]
    assert B.CELL_DTYPE.fields["cov"][1] == B.FIELDS["icoac_sim_cell_t"]["cov"][0]


def test_config_defaults_match_spec():
    d = build_config().to_dict()
    c, p, r = d["controller"], d["plant"], d["run"]
    assert set(c) == {"mode", "learn", "task", "policy", "ico", "critic", "actor", "search"}
    assert c["learn"] is True
    pol, ico, cri, act, sea = c["policy"], c["ico"], c["critic"], c["actor"], c["search"]
    assert c["mode"] == "ico" and pol["reflex_mode"] == "unit" and ico["timing"] == "code"
    assert pol["gain"] == 10.0
    assert pol["reflex_force"] == 1.0
    assert ico["rate"] == pytest.approx(1e-4)
    assert pol["input_range"] == pytest.approx([2.4, 3.5, 0.2094384, 2.0] + [0.0] * (B.MAX_INPUTS - 4))
    task = c["task"]  # the cart-pole task: Eq. (4)'s zone as four rules, the first match wins
    assert task["n_inputs"] == 4 and task["late_source"] == "rules" and task["n_rules"] == 4
    assert task["rule_input"][:4] == [2, 0, 2, 0] and task["rule_side"][:4] == ["above", "below", "below", "above"]
    z, x = math.radians(11.5), 2.35
    assert task["rule_threshold"][:4] == pytest.approx([z, -x, -z, x], rel=1e-6)
    assert task["rule_reflex"][:4] == [1.0, 1.0, -1.0, -1.0]
    assert c["critic"]["units"][:4] == [3, 3, 6, 3]
    assert cri["rate"] == pytest.approx(0.6)
    assert cri["discount"] == pytest.approx(0.95)
    assert act["noise_std"] == 3.0 and act["scale"] == 0.5 and act["forgetting"] == 1.0
    assert pol["clip_inputs"] is True and act["reflex"] is True and act["act_with_sample"] is False
    # method.md, L2-L4, A10: the literal critic, per-tick updates and sigma_L = sigma_u (0); the actor
    # reading, its exploration schedule and the search group chosen by the learner sweeps
    assert cri["quirks"] is False
    assert act["update"] == "gradient" and act["rate"] == pytest.approx(0.001) and act["likelihood_std"] == 0.0
    assert act["batch"] is False and act["explore_ticks"] == 1000
    assert sea == {"batch": 8, "elite_fraction": 0.25, "step": 0.5, "floor": 1.0, "cov_scale": 64.0}
    assert p == {"gravity": 9.8, "cart_mass": 1.0, "pole_mass": 0.1, "half_length": 0.5, "dt": 0.01,
                 "x_limit": 2.4, "theta_limit": pytest.approx(math.radians(12)), "integrator": "euler",
                 "name": "cart_pole", "max_force": 1e6}
    assert r == {"max_trials": 100000, "success_steps": 100000, "init_velocity_noise": pytest.approx(1e-4),
                 "lanes": 16}
    assert d["prior"] is None


def test_condition_overrides():
    """Every condition over the C defaults: each learner's mode, its control the same with
    learn = 0; search from N(0, I) with Sigma0 = 4 I (search.cov_scale 4), ico-search with the C
    default c = 64; ICO->RL and the ICO mean with sigma_w^2 I on the C defaults' reading; the
    two RL conditions with a zero mean on the readings their sweeps chose (mean reading, sigma_L
    0.1, sigma_u 5, alpha 0.1, exploration until tick 1000); nothing else overridden. Each
    actor-critic and search condition has its prior rule. The LQR baseline is ICO mode with every
    update off; so is CMA-ES, which learns outside the controller from the search control's
    N(0, 4 I)."""
    assert set(CONDITION_OVERRIDES) == set(CONDITIONS) and CONDITIONS == (
        "ico", "ico-rl", "ico-rl-control", "ico-mean-rl", "ico-mean-rl-control", "rl-ico-cov", "rl-ico-cov-control",
        "rl", "rl-control", "ico-search", "ico-search-control", "search", "search-control", "lqr", "cma-es")
    assert {c.name: c.control_of for c in REGISTRY.values() if c.control_of} == {
        "ico-rl-control": "ico-rl", "ico-mean-rl-control": "ico-mean-rl", "rl-ico-cov-control": "rl-ico-cov",
        "rl-control": "rl", "ico-search-control": "ico-search", "search-control": "search"}
    assert {c.name: c.prior for c in REGISTRY.values() if c.learns and c.prior} == {
        "ico-rl": ("ico", "ico"), "ico-mean-rl": ("ico", "isotropic"), "rl-ico-cov": ("zero", "ico"),
        "rl": ("zero", "isotropic"), "ico-search": ("ico", "ico"), "search": ("zero", "identity"),
        "cma-es": ("zero", "identity")}
    default = build_config().flat()
    modes = {"ico": "ico", "ico-rl": "rl", "ico-mean-rl": "rl", "rl-ico-cov": "rl", "rl": "rl",
             "ico-search": "search", "search": "search", "lqr": "ico", "cma-es": "ico"}
    zero_mean = ("rl-ico-cov", "rl")
    for condition in CONDITIONS:
        flat = build_config(condition=condition).flat()
        base = REGISTRY[condition].base
        controller_learns = REGISTRY[condition].learns and REGISTRY[condition].optimiser is None
        assert flat["mode"] == modes[base] and flat["learn"] is controller_learns
        assert flat["search.cov_scale"] == (4.0 if base in ("search", "cma-es") else 64.0)
        changed = {n for n in flat if flat[n] != default[n]}
        reading = {"actor.update", "actor.likelihood_std", "actor.noise_std", "actor.scale"}
        assert changed <= {"mode", "learn", "search.cov_scale"} | (reading if base in zero_mean else set()), condition
        if base in zero_mean:  # each from its own sweep: RL alone's explores wider (sigma_u 12 N)
            assert (flat["actor.update"], flat["actor.likelihood_std"], flat["actor.noise_std"], flat["actor.scale"],
                    flat["actor.explore_ticks"]) == ("mean", pytest.approx(0.1), {"rl-ico-cov": 5.0, "rl": 12.0}[base],
                                                     pytest.approx(0.1), 1000)
        if REGISTRY[condition].control_of:  # a control is its condition with every update off
            assert {n: v for n, v in flat.items() if n != "learn"} == \
                {n: v for n, v in build_config(condition=base).flat().items() if n != "learn"}


def test_literal_configuration():
    """--configuration literal: the paper's literal reading over the defaults (the posterior step
    with sigma_L = sigma_u, per tick, exploring at every tick, the literal critic); default: none."""
    assert options.CONFIGURATION_NAMES == tuple(NAMED_CONFIGURATIONS) == ("default", "literal")
    assert named_sets("default") == []
    for condition in ("ico-rl", "rl"):
        default = build_config(condition=condition).flat()
        literal = build_config(parse_sets(named_sets("literal")), condition=condition).flat()
        assert literal["actor.update"] == "posterior" and literal["actor.likelihood_std"] == 0.0
        assert literal["actor.noise_std"] == 1.0 and literal["actor.scale"] == 0.5
        assert literal["actor.batch"] is False and literal["actor.explore_ticks"] == 0 and literal["critic.quirks"] is False
        # the same literal configuration whatever the condition's own reading
        assert literal == build_config(parse_sets(named_sets("literal")), condition="ico-rl").flat()
    assert {n for n in literal if literal[n] != build_config(condition="ico-rl").flat()[n]} == {
        "actor.update", "actor.explore_ticks", "actor.noise_std"}


def test_overrides_by_name():
    cfg = build_config({"policy.reflex_mode": "gain", "ico.timing": "literal", "integrator": "rk4", "max_trials": 2000,
                        "actor.noise_std": 2.0, "policy.input_range": [2.4, 3.5, 0.2094384, 2.0],
                        "policy.clip_inputs": "false"})
    c = cfg.controller
    assert c.policy.reflex_mode == B.REFLEX_MODES["gain"] and c.ico.timing == B.ICO_TIMINGS["literal"]
    assert cfg.model.integrator == B.INTEGRATORS["rk4"] and cfg.run.max_trials == 2000
    assert c.actor.noise_std == 2.0 and c.policy.clip_inputs == 0
    d = cfg.to_dict()
    assert d["controller"]["policy"]["reflex_mode"] == "gain" and d["plant"]["integrator"] == "rk4"


def test_paper_grid_layout():
    from icoac.core.grid import plant_grid
    cells = plant_grid("cart_pole", 0)
    assert cells.size == geometry.CELLS == 1225
    assert np.all(cells["outcome"] == B.PENDING)
    assert cells["x0"][0] == pytest.approx(-2.4) and cells["x0"][48] == pytest.approx(2.4)
    assert np.degrees(cells["theta0"][0]) == pytest.approx(-12) and np.degrees(cells["theta0"][-1]) == pytest.approx(12)
    assert np.degrees(cells["theta0"][49]) == pytest.approx(-11)
    assert len(set(cells["seed"].tolist())) == 1225
    assert not np.array_equal(plant_grid("cart_pole", 1)["seed"], cells["seed"])
    rows, cols = geometry.grid_index(cells)
    assert np.array_equal(geometry.cell_index(rows, cols), np.arange(cells.size))
    assert geometry.THETA_STEP_DEG == 1.0 and geometry.map_extent() == (-2.45, 2.45, -12.5, 12.5)


def test_retune_and_the_configuration_in_force():
    """The state keeps its configuration: an edit of the caller's struct changes nothing,
    icoac_retune applies a checked one (a bad field: ConfigError, a mode change:
    ICOAC_ERR_RETUNE_MODE, the state unchanged either way), icoac_get_config reads it back; a
    tick after a terminal tick is ICOAC_ERR_TRIAL_ENDED and a corrupted state's reset
    ICOAC_ERR_CORRUPT_STATE, each a named IcoacError."""
    cfg = build_config(condition="rl")
    state = B.State()
    B.check_status(B.lib.icoac_init(ctypes.byref(cfg.controller), ctypes.byref(state), None, 1))
    in_force = B.Config()

    def config_in_force():
        B.check_status(B.lib.icoac_get_config(ctypes.byref(state), ctypes.byref(in_force)))
        return bytes(in_force)

    kept = config_in_force()
    cfg.controller.actor.noise_std = 2.0
    assert config_in_force() == kept  # an edit alone changes nothing
    B.check_status(B.lib.icoac_retune(ctypes.byref(state), ctypes.byref(cfg.controller)))
    assert config_in_force() == bytes(cfg.controller)
    before = bytes(state)
    bad = build_config(condition="rl")
    bad.controller.actor.noise_std = math.nan
    with pytest.raises(B.ConfigError, match="actor"):
        B.check_status(B.lib.icoac_retune(ctypes.byref(state), ctypes.byref(bad.controller)))
    other = build_config(condition="search")
    with pytest.raises(B.IcoacError, match="mode") as err:
        B.check_status(B.lib.icoac_retune(ctypes.byref(state), ctypes.byref(other.controller)))
    assert err.value.status == B.CONSTANTS["ICOAC_ERR_RETUNE_MODE"] and bytes(state) == before
    inp, out = B.Input(), B.Output()
    inp.flags = B.INPUT_TERMINAL
    B.check_status(B.lib.icoac_step(ctypes.byref(state), ctypes.byref(inp), ctypes.byref(out)))
    inp.flags = 0
    status = B.lib.icoac_step(ctypes.byref(state), ctypes.byref(inp), ctypes.byref(out))
    assert status == out.status == B.CONSTANTS["ICOAC_ERR_TRIAL_ENDED"] and out.force == 0
    assert "icoac_reset" in B.status_str(status)
    raw = bytearray(bytes(state))
    raw[12:16] = (99).to_bytes(4, "little")  # the configuration copy's mode (the state's layout is private: it
    ctypes.memmove(ctypes.addressof(state), bytes(raw), len(raw))  # follows a 4-byte magic, has_prev, batch_token)
    with pytest.raises(B.IcoacError, match="corrupted"):
        B.check_status(B.lib.icoac_reset(ctypes.byref(state)))
