# SPDX-License-Identifier: Apache-2.0
"""Tests load the real shared library; nothing is built or skipped here."""
import os
import signal
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

REPO = Path(__file__).resolve().parents[2]

# Property tests: a few dozen examples each, reproducible (derandomized), no example database
# written into the working tree. HYPOTHESIS_PROFILE=explore runs more, random examples.
settings.register_profile("icoac", max_examples=60, deadline=None, database=None, derandomize=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("explore", max_examples=1000, deadline=None, database=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "icoac"))


def pytest_configure(config):
    # A suite started in the background by a non-interactive shell inherits SIGINT ignored, and
    # so would every harness it starts: the Ctrl-C tests (test_kill, test_dask) would then see
    # a run that ignores SIGINT. A handler (unlike SIG_IGN) is reset to the default at exec.
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    lib = Path(os.environ.get("ICOAC_SIM_LIBRARY", REPO / "build/release/sim_host/libicoac_sim.so"))
    if not lib.is_file():
        raise pytest.UsageError(f"icoac_sim shared library missing at {lib}: build it with `make build` "
                                "(or set ICOAC_SIM_LIBRARY)")


SMALL = {"max_trials": 6000, "success_steps": 2000}
# Row 12 (theta0 = 0) around the centre, plus two cells that fail within the cap.
SMALL_CELLS = [0, 48, 610, 611, 612, 613]


@pytest.fixture(scope="session")
def small_cfg():
    from icoac.core.config import build_config
    return build_config(SMALL)


@pytest.fixture(scope="session")
def small_run(small_cfg):
    from icoac.core import grid
    cells = grid.make_cells(7, SMALL_CELLS)
    res = grid.run_grid(small_cfg, cells, threads=2, progress=False)
    assert not res.cancelled
    return cells


# An ICO results directory (six cells, SMALL caps), the --prior-from of the RL, search and Dask tests.
ICO_CELLS = [0, 610, 611, 612, 613, 1224]


@pytest.fixture(scope="session")
def ico_dir(tmp_path_factory):
    from icoac.core import grid, store
    from icoac.core.config import build_config
    out = tmp_path_factory.mktemp("ico")
    cfg = build_config(SMALL)
    cells = grid.make_cells(0, ICO_CELLS)
    grid.run_grid(cfg, cells, threads=2, progress=False)
    store.save(out, cells, cfg, condition="ico", seed=0, wall_time=0.0, threads=2, cell_indices=ICO_CELLS)
    return out
