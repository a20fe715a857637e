import ctypes
import math

import numpy as np
import pytest

from harness import _binding as B
from harness.config import build_config


def test_struct_sizes_match_c():
    assert ctypes.sizeof(B.Config) == B.lib.icoac_sizeof_config()
    assert ctypes.sizeof(B.Prior) == B.lib.icoac_sizeof_prior()
    assert ctypes.sizeof(B.Plant) == B.lib.icoac_sim_sizeof_plant()
    assert ctypes.sizeof(B.Run) == B.lib.icoac_sim_sizeof_run()
    assert B.CELL_DTYPE.itemsize == B.lib.icoac_sim_sizeof_cell()
    assert ctypes.sizeof(B.c_real) == B.lib.icoac_sizeof_real()
    assert ctypes.sizeof(B.State) == B.lib.icoac_sizeof_state()
    assert ctypes.sizeof(B.Input) == B.lib.icoac_sizeof_input()
    assert ctypes.sizeof(B.Output) == B.lib.icoac_sizeof_output()
    for name, (py, c) in B.layout_report().items():
        assert py == c, name


def test_abi_versions():
    assert B.lib.icoac_abi_version() == B.ABI_VERSION == 3
    assert B.lib.icoac_sim_abi_version() == B.SIM_ABI_VERSION == 1
    info = B.abi_info()
    assert info["sizeof_real"] in (4, 8)


def test_cell_dtype_offsets():
    names = B.CELL_DTYPE.names
    assert names == ("x0", "theta0", "seed", "outcome", "status", "trials", "total_steps",
                     "last_trial_steps", "elapsed_time", "weights", "cov")
    assert B.CELL_DTYPE.fields["weights"][1] == 64
    assert B.CELL_DTYPE.fields["cov"][1] == 96


def test_config_defaults_match_spec():
    d = build_config().to_dict()
    c, p, r = d["controller"], d["plant"], d["run"]
    assert c["mode"] == "ico" and c["reflex_mode"] == "unit" and c["ico_timing"] == "code"
    assert c["gain"] == 10.0
    assert c["reflex_force"] == 1.0
    assert c["ico_rate"] == pytest.approx(1e-4)
    assert c["input_range"] == pytest.approx([2.4, 3.5, 0.2094384, 2.0])
    assert c["zone_theta"] == pytest.approx(math.radians(11.5), rel=1e-6)
    assert c["zone_x"] == pytest.approx(2.35)
    assert c["critic_rate"] == pytest.approx(0.6)
    assert c["discount"] == pytest.approx(0.95)
    assert c["noise_std"] == 1.0 and c["actor_scale"] == 0.5 and c["forgetting"] == 1.0
    assert c["clip_inputs"] is True
    assert p == {"gravity": 9.8, "cart_mass": 1.0, "pole_mass": 0.1, "half_length": 0.5, "dt": 0.01,
                 "x_limit": 2.4, "theta_limit": pytest.approx(math.radians(12)), "integrator": "euler",
                 "reserved": 0}
    assert r == {"max_trials": 100000, "success_steps": 100000, "init_velocity_noise": pytest.approx(1e-4)}
    assert d["prior"] is None


def test_overrides_by_name():
    cfg = build_config({"reflex_mode": "gain", "ico_timing": "literal", "integrator": "rk4", "max_trials": 2000,
                        "noise_std": 2.0, "input_range": [2.4, 3.5, 0.2094384, 2.0], "clip_inputs": "false"})
    assert cfg.controller.reflex_mode == 1 and cfg.controller.ico_timing == 1
    assert cfg.plant.integrator == 1 and cfg.run.max_trials == 2000
    assert cfg.controller.noise_std == 2.0 and cfg.controller.clip_inputs == 0
    d = cfg.to_dict()
    assert d["controller"]["reflex_mode"] == "gain" and d["plant"]["integrator"] == "rk4"


def test_paper_grid_layout():
    from harness.grid import paper_grid
    cells = paper_grid(0)
    assert cells.size == 1225
    assert np.all(cells["outcome"] == B.PENDING)
    assert cells["x0"][0] == pytest.approx(-2.4) and cells["x0"][48] == pytest.approx(2.4)
    assert np.degrees(cells["theta0"][0]) == pytest.approx(-12) and np.degrees(cells["theta0"][-1]) == pytest.approx(12)
    assert np.degrees(cells["theta0"][49]) == pytest.approx(-11)
    assert len(set(cells["seed"].tolist())) == 1225
    assert not np.array_equal(paper_grid(1)["seed"], cells["seed"])
