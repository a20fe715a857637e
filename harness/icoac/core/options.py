# SPDX-License-Identifier: Apache-2.0
"""Harness-side names, limits and defaults, each defined once (pure Python: the command line
builds its parser from them without loading the shared library). Everything the C library
defines - enum values, statuses, sizes, grid geometry - comes from the binding instead; the
learning conditions are defined in icoac.core.registry."""
from __future__ import annotations

PROFILE_NAMES = ("default", "paper", "quick")   # bench profiles (icoac.studies.bench.PROFILES)
CART_POLE = "cart_pole"  # the default plant: the C registry's first
# Named configurations (icoac.core.config.NAMED_CONFIGURATIONS): the defaults, or the paper's literal
# reading of the actor-critic (method.md: A10, A14; L2, L3), one option away (--configuration literal).
CONFIGURATION_NAMES = ("default", "literal")

# Integer limits of the command line and of the Python API.
INT64_MAX = 2 ** 63 - 1
SEED_LIMIT = 2 ** 64            # seeds are uint64: [0, 2^64)
MAX_THREADS = 1024              # --threads: 0 (all cores) .. MAX_THREADS
MAX_SEEDS = 1000                # --seeds: 1 .. MAX_SEEDS

# Checkpoints of a grid run: after this many newly finished cells, or after this many seconds
# with at least one newly finished cell.
DEFAULT_CHECKPOINT_CELLS = 25
DEFAULT_CHECKPOINT_EVERY = 2.0

# The Dask backend (icoac.cluster.backend: --scheduler ADDRESS or --workers N). Pending cells go out in
# chunks of --chunk-cells cells, one task each; by default ceil(pending / (AUTO_CHUNKS_PER_THREAD x
# worker threads)) cells, clipped to [1, AUTO_CHUNK_MAX], so every worker thread sees several chunks
# (load balance, small loss when a worker dies) and a chunk is still seconds of C work.
AUTO_CHUNKS_PER_THREAD = 8
AUTO_CHUNK_MAX = 16
MAX_CHUNK_CELLS = 1225           # at most this many cells per chunk (the paper grid's)
MAX_WORKERS = 1024               # --workers N: 1 .. MAX_WORKERS local worker processes
DASK_RETRIES = 3                 # retries of a chunk whose task raised (a dead worker is Dask's allowed-failures)
DASK_CONNECT_TIMEOUT = 30.0      # s to reach a scheduler
DASK_WORKER_TIMEOUT = 60.0       # s to wait for the first worker (and the longest a run waits with none)
DASK_CANCEL_GRACE = 5.0          # s a cancel waits for running chunks to return their finished cells
DASK_PROGRESS_EVERY = 0.5        # s between progress events of a running chunk

# Trajectories (Fig. 1g): default length and the bound of the C buffers (40 bytes per step).
TRAJECTORY_DURATION = 30.0      # s
MAX_TRAJECTORY_STEPS = 1_000_000

# Priors of the RL conditions (method.md, A15, A16).
FRAME_NAMES = ("central", "all")
PRIOR_FRAME = (1.2, 6.0)        # the central frame: |x0| <= 1.2 m, |theta0| <= 6 deg
PRIOR_RIDGE = 1e-6              # added to the prior covariance (times I)
PRIOR_STD = 1.0                 # sigma_w of the isotropic priors (--prior-std)

# sweep: trial cap of every setting unless --max-trials says otherwise.
SWEEP_MAX_TRIALS = 2000

# ceiling (method.md, L5): fixed-w evaluation of the policy class F = G * w^T x~ + U and the search for
# the best single w. Protocols: one trial per cell ("first"), or fresh initial velocities every
# trial up to a trial cap ("retries"); "both" runs the two.
CEILING_PROTOCOLS = ("first", "retries")
CEILING_PROTOCOL_CHOICES = CEILING_PROTOCOLS + ("both",)
CEILING_MAX_TRIALS = 1000        # trial cap of the retries protocol
CEILING_CANDIDATES = 1000        # distinct w screened by the search (starting points included)
CEILING_SCREEN_STEPS = 1000      # horizon of the screening runs (first protocol)
CEILING_CONFIRM = 5              # best screened w confirmed at the full horizon
CEILING_MAX_CANDIDATES = 100_000
CEILING_OPTIMISERS = ("pattern", "cma-es")  # the search's optimiser (the first: the default)
# A typical ICO weight vector (w_x, w_xdot, w_theta, w_thetadot): the start of the search when no
# ICO results directory is given (--prior-from).
TYPICAL_ICO_WEIGHTS = (0.094, 0.066, 0.365, 0.080)
# Where the bench looks for a ceiling to draw into Fig. 3a: OUT/<CEILING_DIR>/<CEILING_FILE>.
CEILING_DIR = "ceiling"
CEILING_FILE = "ceiling.json"
