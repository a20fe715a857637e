# SPDX-License-Identifier: Apache-2.0
"""The per-task overhead of the Dask backend (icoac.cluster.backend): N chunks of one trivial cell each
(max_trials 1, success_steps 1: microseconds of C work) on a LocalCluster, against the threaded
engine on the same cells.

    python -m icoac.tools.dask_overhead [--workers 2] [--tasks 200] [--repeat 5]

Prints the start-up time of the cluster, the fixed cost of a grid of one chunk, and for the N
tasks the wall time, the tasks per second and the worker-thread time per task (wall x worker
threads / N, the overhead a chunk costs a worker), medians over --repeat runs.
"""
from __future__ import annotations

import argparse
import statistics
import time


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m icoac.tools.dask_overhead")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--tasks", type=int, default=200)
    p.add_argument("--repeat", type=int, default=5)
    args = p.parse_args(argv)

    from icoac.cluster import backend as cluster
    from icoac.core import grid
    from icoac.core.config import build_config

    cfg = build_config({"max_trials": 1, "success_steps": 1})
    idx = list(range(args.tasks))

    def threaded() -> float:
        cells = grid.make_cells(0, idx)
        t0 = time.monotonic()
        grid.run_grid(cfg, cells, threads=args.workers, progress=False)
        return time.monotonic() - t0

    t0 = time.monotonic()
    with cluster.DaskSession(cluster.DaskSpec(workers=args.workers)) as session:
        startup = time.monotonic() - t0
        threads = session.nthreads()
        one, many = [], []
        for _ in range(args.repeat + 1):  # the first round warms the workers up (imports, library)
            cells = grid.make_cells(0, [0])
            t0 = time.monotonic()
            session.run_grid(cfg, cells, progress=False, chunk_cells=1)
            one.append(time.monotonic() - t0)
            cells = grid.make_cells(0, idx)
            t0 = time.monotonic()
            res = session.run_grid(cfg, cells, progress=False, chunk_cells=1)
            many.append(time.monotonic() - t0)
            assert res.complete
        ref = [threaded() for _ in range(args.repeat)]
    one, many = one[1:], many[1:]
    wall = statistics.median(many)
    print(f"LocalCluster of {args.workers} worker processes ({threads} threads): start-up {startup:.2f} s")
    print(f"grid of 1 chunk of 1 cell: {1e3 * statistics.median(one):.1f} ms (median of {args.repeat})")
    print(f"{args.tasks} chunks of 1 cell: {wall:.3f} s (runs {', '.join(f'{w:.3f}' for w in many)}), "
          f"{args.tasks / wall:.0f} tasks/s, {1e3 * wall * threads / args.tasks:.2f} ms of worker-thread time "
          f"per task; threaded engine on the same cells {1e3 * statistics.median(ref):.2f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
