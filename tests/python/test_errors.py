import math

import numpy as np
import pytest

from harness import _binding as B
from harness.config import build_config, make_prior


@pytest.mark.parametrize("overrides, status, words", [
    ({"gain": -1.0}, B.ERR_BAD_GAIN, "gain"),
    ({"reflex_force": -2.0}, B.ERR_BAD_GAIN, "reflex_force"),
    ({"input_range": [2.4, 0.0, 0.2, 2.0]}, B.ERR_BAD_SCALE, "input_range"),
    ({"zone_x": 0.0}, B.ERR_BAD_ZONE, "zone"),
    ({"ico_rate": -1e-4}, B.ERR_BAD_ICO_RATE, "ico_rate"),
    ({"discount": 1.5}, B.ERR_BAD_CRITIC, "critic"),
    ({"noise_std": 0.0}, B.ERR_BAD_ACTOR, "noise_std"),
    ({"mode": 7}, B.ERR_BAD_MODE, "mode"),
    ({"dt": 0.0}, B.SIM_ERR_BAD_PLANT, "plant"),
    ({"max_trials": 0}, B.SIM_ERR_BAD_RUN, "max_trials"),
])
def test_bad_values_raise_config_error_with_c_message(overrides, status, words):
    with pytest.raises(B.ConfigError) as info:
        build_config(overrides)
    assert info.value.status == status
    assert info.value.c_message == B.status_str(status)
    assert B.status_str(status) in str(info.value)
    assert words in str(info.value)


@pytest.mark.parametrize("name", ["gain", "ico_rate", "zone_theta", "gravity", "init_velocity_noise"])
def test_nan_rejected(name):
    with pytest.raises(B.ConfigError) as info:
        build_config({name: float("nan")})
    assert info.value.status in set(range(10, 18)) | {100, 101}


def test_unknown_name_lists_valid_names():
    with pytest.raises(B.ConfigError) as info:
        build_config({"gian": 10})
    assert "gian" in str(info.value) and "gain" in str(info.value) and "max_trials" in str(info.value)


def test_bad_symbolic_value():
    with pytest.raises(B.ConfigError, match="unit, gain"):
        build_config({"reflex_mode": "huge"})
    with pytest.raises(B.ConfigError):
        build_config({"input_range": [1, 2]})
    with pytest.raises(B.ConfigError):
        build_config({"gain": "ten"})


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
