# SPDX-License-Identifier: Apache-2.0
"""The paper's figures (Fig. 1b, 1c-f, 1g) as byte-stable PNGs (matplotlib Agg, fixed style)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from icoac.core.errors import MissingExtra

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import colors
    from matplotlib.patches import Rectangle
except ImportError as _exc:
    raise MissingExtra("drawing figures", "plot", _exc) from None

from icoac.core import binding as B  # noqa: E402
from icoac.core import geometry, metrics  # noqa: E402
from icoac.core.config import config_from_dict, make_prior  # noqa: E402
from icoac.core.grid import trajectory, trajectory_steps  # noqa: E402
from icoac.core.metrics import percent  # noqa: E402
from icoac.core.options import PRIOR_FRAME, TRAJECTORY_DURATION  # noqa: E402

DPI = 150
STYLE = {
    "font.family": "DejaVu Sans",
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.labelsize": 9,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "image.interpolation": "nearest",
    "savefig.dpi": DPI,
    "figure.dpi": DPI,
    "path.simplify": False,
    "svg.hashsalt": "icoac",
}
# Maps: cells centred on the grid points of the plant's grid (icoac.core.geometry; the cart-pole's
# x0 = -2.4..2.4 m, theta0 = -12..12 deg), the column component horizontal.
CART_POLE = geometry.CART_POLE
# Paper panel order of Fig. 1c-f and index into (w_x, w_xdot, w_theta, w_thetadot).
WEIGHT_PANELS = (("c", r"$w_\theta$", 2), ("d", r"$w_x$", 0), ("e", r"$w_{\dot\theta}$", 3), ("f", r"$w_{\dot x}$", 1))
FIG1G_START = (-0.5, -4.0)  # x0 m, theta0 deg


def save_figure(fig, path: str | Path) -> Path:
    """Save without time stamps or version strings so identical data gives identical bytes."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI, format="png", metadata={"Software": None})
    plt.close(fig)
    return path


def _figure(size):
    with plt.rc_context(STYLE):
        return plt.figure(figsize=size)


def draw_frame(ax, half_x: float, half_theta_deg: float, grid: geometry.PlantGrid = CART_POLE, **kw) -> None:
    """Dashed rectangle |x0| <= half_x, |theta0| <= half_theta_deg (the grid's display units) on a
    map axis."""
    style = dict(fill=False, linestyle="--", linewidth=1.2, edgecolor="black")
    style.update(kw)
    dx, dth = grid.col_step, grid.row_step  # the frame encloses whole cells
    ax.add_patch(Rectangle((-half_x - dx / 2, -half_theta_deg - dth / 2), 2 * half_x + dx, 2 * half_theta_deg + dth,
                           **style))


def draw_outline(ax, mask: np.ndarray, grid: geometry.PlantGrid = CART_POLE, **kw) -> None:
    """Outline of a (rows, cols) boolean domain (e.g. the ICO success domain on an RL map)."""
    style = dict(colors="black", linewidths=1.0, linestyles="--")
    style.update(kw)
    extent = grid.map_extent()
    x = np.linspace(extent[0], extent[1], grid.cols + 1)
    y = np.linspace(extent[2], extent[3], grid.rows + 1)
    m = np.asarray(mask, dtype=bool)
    for i in range(grid.rows):
        for j in range(grid.cols):
            if not m[i, j]:
                continue
            if i == 0 or not m[i - 1, j]:
                ax.hlines(y[i], x[j], x[j + 1], **style)
            if i == grid.rows - 1 or not m[i + 1, j]:
                ax.hlines(y[i + 1], x[j], x[j + 1], **style)
            if j == 0 or not m[i, j - 1]:
                ax.vlines(x[j], y[i], y[i + 1], **style)
            if j == grid.cols - 1 or not m[i, j + 1]:
                ax.vlines(x[j + 1], y[i], y[i + 1], **style)


def plot_map(ax, values: np.ndarray, *, cmap="viridis", norm=None, title: str | None = None,
             colorbar_label: str | None = None, frame: tuple[float, float] | None = None,
             outline: np.ndarray | None = None, grid: geometry.PlantGrid = CART_POLE):
    """A (rows, cols) map of the plant's grid, x0 (its column component) horizontal and theta0
    (its row component) vertical; NaN cells are white. Returns the image."""
    cm = plt.get_cmap(cmap)
    cm = cm.with_extremes(bad="white") if hasattr(cm, "with_extremes") else cm.copy()
    if not hasattr(cm, "with_extremes"):  # matplotlib < 3.4
        cm.set_bad("white")
    img = ax.imshow(np.ma.masked_invalid(values), origin="lower", extent=grid.map_extent(), aspect="auto",
                    cmap=cm, norm=norm, interpolation="nearest")
    ax.set_xlabel(r"$x_0$ (m)" if grid is CART_POLE else grid.col_label())
    ax.set_ylabel(r"$\theta_0$ (deg)" if grid is CART_POLE else grid.row_label())
    ax.set_xticks(np.linspace(grid.col_first, grid.col_last, 5).round(6))
    ax.set_yticks(np.linspace(grid.row_first, grid.row_last, 5).round(6))
    for side in ax.spines.values():
        side.set_linewidth(0.8)
    if title:
        ax.set_title(title)
    if frame is not None:
        draw_frame(ax, *frame, grid=grid)
    if outline is not None:
        draw_outline(ax, outline, grid=grid)
    if colorbar_label is not None:
        cb = ax.figure.colorbar(img, ax=ax, fraction=0.046, pad=0.03)
        cb.set_label(colorbar_label)
    return img


def success_title(label: str, summary: Mapping) -> str:
    """The map's title; a partial grid says how many of its cells are still pending (they count
    in the rate's denominator as not successful)."""
    pending = summary["outcomes"].get("pending", 0)
    cells = f"{summary['n_cells']} cells" + (f", {pending} still pending" if pending else "")
    return (f"{label}: success {percent(summary['success_rate'])} ({cells}), "
            f"interior {percent(summary['success_rate_interior'])}")


def plot_success_map(cells: np.ndarray, path: str | Path, *, label: str = "ICO",
                     frame: tuple[float, float] | None = None, outline: np.ndarray | None = None,
                     vmin: float | None = None, vmax: float | None = None,
                     grid: geometry.PlantGrid = CART_POLE) -> Path:
    """Fig. 1b style: colour = trials to success (log scale, whole decades around the data unless
    vmin/vmax are given, e.g. to compare conditions), failed cells white."""
    trials = metrics.trials_to_success(cells)
    values = grid.to_grid(cells, trials)
    finite = values[np.isfinite(values)]
    lo_data = float(finite.min()) if finite.size else 1.0
    hi_data = float(finite.max()) if finite.size else 10.0
    lo = vmin if vmin is not None else 10.0 ** math.floor(math.log10(max(lo_data, 1.0)))
    hi = vmax if vmax is not None else 10.0 ** math.ceil(math.log10(max(hi_data, 1.0)))
    if hi <= lo:
        hi = lo * 10.0
    norm = colors.LogNorm(vmin=lo, vmax=hi)
    with plt.rc_context(STYLE):
        fig, ax = plt.subplots(figsize=(6.4, 3.6))
        plot_map(ax, values, cmap="viridis", norm=norm, title=success_title(label, metrics.summary(cells, grid)),
                 colorbar_label="trials to success", frame=frame, outline=outline, grid=grid)
        fig.tight_layout()
        return save_figure(fig, path)


def plot_weight_maps(cells: np.ndarray, path: str | Path, *, label: str = "ICO",
                     frame: tuple[float, float] | None = PRIOR_FRAME,
                     grid: geometry.PlantGrid = CART_POLE) -> Path:
    """Fig. 1c-f: learned weights per cell (the cart-pole's w_theta, w_x, w_thetadot, w_xdot; another
    plant's in its input order, named by its state components); failed cells blank."""
    w = metrics.weights(cells, successful_only=True, grid=grid)
    panels = WEIGHT_PANELS if grid.plant == CART_POLE.plant else tuple(
        (chr(ord("c") + i), f"$w$ {name}", i) for i, name in enumerate(grid.state_names))
    rows = (len(panels) + 1) // 2
    with plt.rc_context(STYLE):
        fig, axes = plt.subplots(rows, 2, figsize=(9.0, 2.9 * rows))
        for ax in axes.flat[len(panels):]:
            ax.set_visible(False)
        for ax, (letter, name, idx) in zip(axes.flat, panels):
            values = grid.to_grid(cells, w[:, idx])
            finite = values[np.isfinite(values)]
            # A few edge cells learn weights 10-100x the central ones; clip the colour scale at the
            # 95th percentile so the structure of the band stays visible.
            lim = float(np.percentile(np.abs(finite), 95)) if finite.size else 1.0
            lim = lim if lim > 0 else 1.0
            if finite.size and finite.min() >= 0:
                cmap, norm = "viridis", colors.Normalize(0.0, lim, clip=True)
            else:
                cmap, norm = "RdBu_r", colors.Normalize(-lim, lim, clip=True)
            plot_map(ax, values, cmap=cmap, norm=norm, title=f"({letter}) {label} {name}",
                     colorbar_label=f"{name} (clipped at 95th pct.)", frame=frame, grid=grid)
        fig.tight_layout()
        return save_figure(fig, path)


def plot_trajectory(traj, path: str | Path, *, title: str | None = None, cfg=None) -> Path:
    """Fig. 1g: trajectory in (x, theta in degrees) space."""
    x = traj.states[:, 0]
    th = np.degrees(traj.states[:, 2])
    with plt.rc_context(STYLE):
        fig, ax = plt.subplots(figsize=(5.0, 3.6))
        ax.plot(x, th, color="tab:blue", linewidth=0.8)
        ax.plot(x[:1], th[:1], "o", color="tab:green", markersize=5, label="start")
        ax.plot(x[-1:], th[-1:], "s", color="tab:red", markersize=4, label="end")
        if cfg is not None:
            limits = {p["name"]: cfg.model.param[k] for k, p in enumerate(B.plant_info(cfg.model.plant)["params"])}
            xl, tl = limits["x_limit"], math.degrees(limits["theta_limit"])
            ax.add_patch(Rectangle((-xl, -tl), 2 * xl, 2 * tl, fill=False, linestyle=":", edgecolor="grey"))
        ax.set_xlabel("x (m)")
        ax.set_ylabel(r"$\theta$ (deg)")
        ax.set_title(title or f"trajectory, {traj.n_steps * traj.dt:.0f} s")
        ax.legend(loc="best", frameon=False)
        fig.tight_layout()
        return save_figure(fig, path)


def plot_bars(path: str | Path, labels: Sequence[str], values: Sequence[float],
              errors: Sequence[float] | None = None, *, ylabel: str = "", title: str | None = None) -> Path:
    """Bar chart over conditions (e.g. mean +- sd success rate over seeds)."""
    with plt.rc_context(STYLE):
        fig, ax = plt.subplots(figsize=(4.0, 3.2))
        pos = np.arange(len(labels))
        ax.bar(pos, values, yerr=errors, color="tab:blue", capsize=3, width=0.6)
        ax.set_xticks(pos)
        ax.set_xticklabels(labels, rotation=30, ha="right")
        ax.set_ylabel(ylabel)
        if title:
            ax.set_title(title)
        fig.tight_layout()
        return save_figure(fig, path)


def fig1g_trajectory(cells: np.ndarray, cfg, duration: float = TRAJECTORY_DURATION, seed: int = 0):
    """Trajectory from x0 = -0.5 m, theta0 = -4 deg with the final weights of that grid cell as prior mean.
    Returns None when the grid has no such cell."""
    x0, th0 = FIG1G_START
    rows, cols = geometry.grid_index(cells)
    row, col = (int(v) for v in geometry.row_col(x0, th0))
    hit = np.flatnonzero((rows == row) & (cols == col))
    if hit.size == 0:
        return None, None
    cell = cells[hit[0]]
    cfg.prior = make_prior(cell["weights"][:cfg.n_inputs], np.eye(cfg.n_inputs))
    traj = trajectory(cfg, x0, math.radians(th0), duration=duration, seed=seed)
    return traj, cell


def check_duration(record: Mapping, duration: float) -> int:
    """Plant steps of the Fig. 1g trajectory for a run record; ConfigError if the duration is not
    finite and > 0 or needs more than options.MAX_TRAJECTORY_STEPS steps at the record's dt."""
    return trajectory_steps(duration, config_from_dict(record["config"]).engine_model().dt)


def make_figures(cells: np.ndarray, record: Mapping, out: str | Path, *, label: str | None = None,
                 prefix: str = "fig1", duration: float = TRAJECTORY_DURATION) -> list[Path]:
    """Fig. 1b, 1c-f and 1g of one ICO results set; returns the files written."""
    out = Path(out)
    label = label or str(record.get("condition", "ICO")).upper()
    cfg = config_from_dict(record["config"])
    trajectory_steps(duration, cfg.engine_model().dt)  # a bad duration fails before any file is written
    grid = geometry.of(cfg.plant_name)
    frame = PRIOR_FRAME if grid is CART_POLE else grid.central_frame()
    written = [plot_success_map(cells, out / f"{prefix}b_success_map.png", label=label, grid=grid),
               plot_weight_maps(cells, out / f"{prefix}cf_weights.png", label=label, frame=frame, grid=grid)]
    if grid is not CART_POLE:  # Fig. 1g is the cart-pole's trajectory from the paper's start
        return written
    traj, cell = fig1g_trajectory(cells, cfg, duration=duration, seed=int(record.get("seed", 0)))
    if traj is not None:
        state = B.OUTCOME_NAMES.get(int(cell["outcome"]), "?")
        title = (f"(g) {label}: x0 = -0.5 m, theta0 = -4 deg, {traj.n_steps * traj.dt:.1f} s "
                 f"(cell {state})")
        written.append(plot_trajectory(traj, out / f"{prefix}g_trajectory.png", title=title, cfg=cfg))
    return written


# Reference lines of the best single w found (icoac.studies.ceiling) in Fig. 3a, by protocol label.
CEILING_STYLES = {"first trial": dict(colors="tab:green", linestyles="-."),
                  "retries": dict(colors="tab:purple", linestyles=":")}


def plot_fig3a(path: str | Path, labels: Sequence[str], all_stats: Sequence[Mapping],
               interior_stats: Sequence[Mapping], paper: Sequence[float | None],
               ceiling: Mapping[str, float] | None = None) -> Path:
    """Fig. 3a: mean success rate per condition (+- sd over seeds), all cells and interior cells,
    with the paper's values (e.g. ~68 % ICO, ~84 % ICO->RL) marked. ``ceiling`` ({protocol label:
    success rate over all cells}, e.g. {"first trial": 0.915, "retries": 0.967}, from
    icoac.studies.ceiling.reference_lines) adds horizontal lines "best single w found (label)" across
    the plot; without it the figure is exactly the one without ceiling."""
    def mv(stats):
        m = [np.nan if s is None or s.get("mean") is None else 100 * s["mean"] for s in stats]
        e = [0.0 if s is None or s.get("sd") is None else 100 * s["sd"] for s in stats]
        return np.array(m), np.array(e)

    m_all, e_all = mv(all_stats)
    m_in, e_in = mv(interior_stats)
    with plt.rc_context(STYLE):
        width = max(5.0, 0.75 * len(labels) + 1.0)
        fig, ax = plt.subplots(figsize=(width, 4.6) if ceiling else (width, 4.0))
        pos = np.arange(len(labels))
        width = 0.36
        ax.bar(pos - width / 2, np.nan_to_num(m_all), width, yerr=e_all, capsize=3, color="tab:blue",
               label="all cells")
        ax.bar(pos + width / 2, np.nan_to_num(m_in), width, yerr=e_in, capsize=3, color="tab:orange",
               label="interior cells")
        first = True
        for p, value in zip(pos, paper):
            if value is None:
                continue
            ax.hlines(100 * value, p - 0.45, p + 0.45, colors="black", linestyles="--", linewidth=1.2,
                      label="paper" if first else None)
            ax.annotate(f"paper ~{percent(value, 0)}", (p, 100 * value), textcoords="offset points",
                        xytext=(0, 3), ha="center", fontsize=7)
            first = False
        for name, rate in (ceiling or {}).items():
            style = dict(linewidth=1.0, **CEILING_STYLES.get(name, dict(colors="grey", linestyles="-.")))
            ax.hlines(100 * rate, -0.5, len(labels) - 0.5, label=f"best single w found ({name}) {percent(rate)}",
                      **style)
        if ceiling:
            ax.set_xlim(-0.5, len(labels) - 0.5)
        ax.set_xticks(pos)
        ax.set_xticklabels(labels, rotation=30, ha="right")
        ax.set_ylim(0, 105)
        ax.set_ylabel("success rate (%)")
        ax.set_title("(a) success rate, mean ± sd over seeds")
        if ceiling:  # above the axes: the reference lines run across the whole plot
            ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.08), ncol=3, frameon=False, fontsize=7)
        else:
            ax.legend(loc="upper left", frameon=False, fontsize=7)
        fig.tight_layout()
        return save_figure(fig, path)


def plot_fig3b(path: str | Path, labels: Sequence[str], stats: Sequence[Mapping]) -> Path:
    """Fig. 3b: mean elapsed simulated time of successful cells per condition (mean +- sd over seeds), log axis."""
    m = np.array([np.nan if s is None or s.get("mean") is None else s["mean"] for s in stats], dtype=float)
    e = np.array([0.0 if s is None or s.get("sd") is None else s["sd"] for s in stats], dtype=float)
    with plt.rc_context(STYLE):
        fig, ax = plt.subplots(figsize=(max(4.4, 0.7 * len(labels) + 1.0), 4.0))
        pos = np.arange(len(labels))
        ok = np.isfinite(m) & (m > 0)
        # Asymmetric error bars clipped above zero so the log axis can show them.
        lower = np.where(ok, np.minimum(e, m * 0.999), 0.0)
        ax.bar(pos[ok], m[ok], 0.6, yerr=np.vstack([lower[ok], e[ok]]), capsize=3, color="tab:green")
        for p in pos[~ok]:
            ax.annotate("no success", (p, 0.03), xycoords=("data", "axes fraction"), ha="center", fontsize=8)
        ax.set_yscale("log")
        if ok.any():
            lo = 10.0 ** math.floor(math.log10(max(np.min(m[ok] - lower[ok]), 1e-3)))
            hi = 10.0 ** math.ceil(math.log10(np.max(m[ok] + e[ok]) * 1.01))
            ax.set_ylim(lo, hi)
        ax.set_xticks(pos)
        ax.set_xticklabels(labels, rotation=30, ha="right")
        ax.set_ylabel("elapsed simulated time (s)")
        ax.set_title("(b) time to success, mean ± sd over seeds")
        fig.tight_layout()
        return save_figure(fig, path)


def plot_fig3c(path: str | Path, budgets: Sequence[int], curves: Sequence[Mapping], cap: float | None = None,
               ceiling: Mapping | None = None, title: str = "(c) success within k trials") -> Path:
    """Fig. 3c: success rate (all cells) against the trial budget k, log axis, one curve per
    condition (mean over seeds, the band +- sd), a no-learning control dashed in its condition's
    colour. ``curves``: {"label", "mean", "sd", "control": bool, "color": index}. ``ceiling``:
    {"label", "rate"} (one curve, the best single w found's retries at the same cap)."""
    k = np.asarray(budgets, dtype=float)
    keep = k <= (cap if cap is not None else k.max())
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    with plt.rc_context(STYLE):
        fig, ax = plt.subplots(figsize=(8.4, 4.4))
        for c in curves:
            m = np.array([np.nan if v is None else 100 * v for v in c["mean"]], dtype=float)[keep]
            sd = np.array([0.0 if v is None else 100 * v for v in c["sd"]], dtype=float)[keep]
            color = colors[c["color"] % len(colors)]
            ax.plot(k[keep], m, color=color, linestyle="--" if c["control"] else "-", linewidth=1.3,
                    label=c["label"])
            ax.fill_between(k[keep], m - sd, m + sd, color=color, alpha=0.15, linewidth=0)
        if ceiling is not None:
            r = np.array([np.nan if v is None else 100 * v for v in ceiling["rate"]], dtype=float)[keep]
            ax.plot(k[keep], r, color="black", linestyle=":", linewidth=1.3, label=ceiling["label"])
        ax.set_xscale("log")
        ax.set_xlim(1, k[keep].max())
        ax.set_ylim(0, 102)
        ax.set_xlabel("trial budget k")
        ax.set_ylabel("success within k trials (% of all cells)")
        ax.set_title(title)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False, fontsize=7)
        fig.tight_layout()
        return save_figure(fig, path)
