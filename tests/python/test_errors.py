# SPDX-License-Identifier: Apache-2.0
import math

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core.config import build_config, make_prior


@pytest.mark.parametrize("overrides, condition, status, words", [
    ({"policy.gain": -1.0}, "ico", B.ERR_BAD_GAIN, "rejected: policy.gain=-1.0"),
    ({"policy.reflex_force": -2.0}, "ico", B.ERR_BAD_GAIN, "rejected: policy.reflex_force=-2.0"),
    ({"policy.input_range": [2.4, 0.0, 0.2, 2.0]}, "ico", B.ERR_BAD_SCALE, "rejected: policy.input_range[1]=0.0"),
    ({"task.rule_threshold": [2e6]}, "ico", B.ERR_BAD_ZONE, "rejected: task.rule_threshold[0]=2000000.0"),
    ({"ico.rate": -1e-4}, "ico", B.ERR_BAD_ICO_RATE, "rejected: ico.rate=-0.0001"),
    ({"critic.discount": 1.5}, "rl", B.ERR_BAD_CRITIC, "rejected: critic.discount=1.5"),
    ({"critic.td_clip": 0.0}, "rl", B.ERR_BAD_CRITIC, "rejected: critic.td_clip=0.0"),
    ({"actor.noise_std": 0.0}, "rl", B.ERR_BAD_ACTOR, "rejected: actor.noise_std=0.0"),
    # 0 (sigma_L = sigma_u) or [1e-3, 1e3]
    ({"actor.likelihood_std": 5e-4}, "rl", B.ERR_BAD_ACTOR, "rejected: actor.likelihood_std=0.0005"),
    ({"actor.likelihood_std": -1.0}, "rl", B.ERR_BAD_ACTOR, "rejected: actor.likelihood_std=-1.0"),
    ({"search.cov_scale": 0.5}, "search", B.ERR_BAD_SEARCH, "rejected: search.cov_scale=0.5"),
    ({"mode": 7}, None, B.ERR_BAD_MODE, "rejected: mode=7"),
    ({"ico.timing": 2}, "ico", B.ERR_BAD_MODE, "rejected: ico.timing=2"),
    ({"dt": 0.0}, None, B.SIM_ERR_BAD_PLANT, "plant"),
    ({"max_trials": 0}, None, B.SIM_ERR_BAD_RUN, "max_trials"),
])
def test_bad_values_raise_config_error_with_c_message(overrides, condition, status, words):
    with pytest.raises(B.ConfigError) as info:
        build_config(overrides, condition=condition)
    assert info.value.status == status
    assert info.value.c_message == B.status_str(status)
    assert B.status_str(status) in str(info.value)
    assert words in str(info.value)


def test_likelihood_std_zero_follows_the_noise():
    """actor.likelihood_std 0 (the default) is accepted: sigma_L = sigma_u; a refusal names the
    field and both forms of its range (from the C parameter table)."""
    assert build_config({"actor.likelihood_std": 0.0}, condition="rl").controller.actor.likelihood_std == 0.0
    with pytest.raises(B.ConfigError, match=r"actor\.likelihood_std=1e-05 \(valid: 0 or \[0\.001, 1000\]\)"):
        build_config({"actor.likelihood_std": 1e-5}, condition="rl")


def test_mode_checks_only_its_groups():
    """icoac_config_check validates the groups the mode uses: a bad critic passes in ICO mode."""
    build_config({"critic.discount": 1.5}, condition="ico")
    with pytest.raises(B.ConfigError):
        build_config({"critic.discount": 1.5}, condition="rl")
    build_config({"ico.rate": -1.0}, condition="rl")
    with pytest.raises(B.ConfigError):
        build_config({"ico.rate": -1.0}, condition="ico")


def test_python_side_rejection_carries_the_c_status():
    """A value rejected before C sees it (NaN, subnormal, overflow) has the status C gives that field."""
    for name, status in [("policy.gain", B.ERR_BAD_GAIN), ("critic.range", B.ERR_BAD_CRITIC),
                         ("actor.forgetting", B.ERR_BAD_ACTOR), ("ico.rate", B.ERR_BAD_ICO_RATE),
                         ("gravity", B.SIM_ERR_BAD_PLANT), ("init_velocity_noise", B.SIM_ERR_BAD_RUN)]:
        value = [float("nan")] * 4 if name == "critic.range" else float("nan")
        with pytest.raises(B.ConfigError) as info:
            build_config({name: value})
        assert info.value.status == status, name


@pytest.mark.parametrize("name", ["policy.gain", "ico.rate", "gravity", "init_velocity_noise"])
def test_nan_rejected(name):
    with pytest.raises(B.ConfigError) as info:
        build_config({name: float("nan")})
    assert info.value.status in set(range(10, 18)) | {100, 101}


def test_unknown_name_lists_valid_names():
    with pytest.raises(B.ConfigError) as info:
        build_config({"gian": 10})
    text = str(info.value)
    assert "gian" in text and "policy.gain" in text and "max_trials" in text and "did you mean policy.gain" in text


def test_bad_symbolic_value():
    with pytest.raises(B.ConfigError, match="unit, gain"):
        build_config({"policy.reflex_mode": "huge"})
    with pytest.raises(B.ConfigError):
        build_config({"policy.input_range": [1, 2]})
    with pytest.raises(B.ConfigError):
        build_config({"policy.gain": "ten"})


def test_bad_prior():
    cov = np.eye(4)
    cov[0, 1] = 2.0
    with pytest.raises(B.ConfigError) as info:
        build_config(prior=make_prior(np.zeros(4), cov))
    assert info.value.status == B.ERR_BAD_PRIOR
    with pytest.raises(B.ConfigError):
        build_config(prior=make_prior([math.nan, 0, 0, 0], np.eye(4)))
    build_config(prior=make_prior([0.1, 0, 0.3, 0], np.eye(4)))


def test_status_exception_classes():
    with pytest.raises(B.Cancelled):
        B.check_status(B.SIM_CANCELLED)
    with pytest.raises(B.IcoacError) as info:
        B.check_status(B.SIM_ERR_THREAD)
    assert not isinstance(info.value, B.ConfigError)
    B.check_status(B.OK)
