# SPDX-License-Identifier: Apache-2.0
"""The learning conditions, each defined once: its mode, its prior rule, its controller overrides,
its label and its no-learning control. Every other table of conditions (the command line's
choices, the configurations, the priors, the bench's stages and tables) is derived from REGISTRY.

Pure Python, importing nothing heavy: the command line builds its parser from it without loading
the shared library.

A no-learning control (method.md, L1) is generated from its condition: the same mode, prior and
overrides, plus learn = 0 (every update off), named "<condition>-control" and labelled
"<label> control".
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, Mapping, NamedTuple

# The controller modes a condition runs in (the names of the C enum, icoac.core.binding.MODES).
MODES = ("ico", "rl", "search")
# The optimisers that learn outside the controller, over its fixed policy (trials in C, the
# optimiser in Python between them): icoac.studies.baselines.
OPTIMISERS = ("cma-es",)
# The words of a prior rule. Mean: "ico" (the ICO prior's, from the final weights of an ICO grid,
# --prior-from), "zero", or "lqr" (the plant's LQR gain as a w, icoac.core.signs.lqr_weights). Covariance: "ico" (the ICO prior's), "isotropic" (sigma_w^2 I with
# sigma_w = --prior-std) or "identity" (I: the search's Sigma0 = search.cov_scale * I).
MEAN_RULES = ("ico", "zero", "lqr")
COV_RULES = ("ico", "isotropic", "identity")
CONTROL_SUFFIX = "-control"


class PriorRule(NamedTuple):
    """Where a condition's prior mean and covariance come from (method.md, A16 and L6)."""
    mean: str
    cov: str

    @property
    def takes_ico(self) -> bool:
        """Whether the prior takes anything from an ICO grid (then --prior-from is required)."""
        return "ico" in self


@dataclass(frozen=True)
class Condition:
    """One learning condition. ``overrides`` are set on top of the C defaults, after the mode."""
    name: str
    label: str
    mode: str
    prior: PriorRule | None = None          # None: no prior (ICO)
    overrides: Mapping[str, Any] = field(default_factory=dict)
    control: str | None = None              # the name of its no-learning control
    control_of: str | None = None           # a control: the condition it is the control of
    baseline: bool = False                  # a fixed policy that never learns (no control of its own)
    optimiser: str | None = None            # learns outside the controller (OPTIMISERS), its updates off

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError(f"condition {self.name}: unknown mode {self.mode!r}")
        if self.prior is not None and (self.prior.mean not in MEAN_RULES or self.prior.cov not in COV_RULES):
            raise ValueError(f"condition {self.name}: bad prior rule {self.prior!r}")
        if self.optimiser is not None and (self.optimiser not in OPTIMISERS or self.mode != "ico"):
            raise ValueError(f"condition {self.name}: an optimiser ({', '.join(OPTIMISERS)}) runs a fixed policy "
                             "(mode ico)")
        object.__setattr__(self, "overrides", MappingProxyType(dict(self.overrides)))

    @property
    def learns(self) -> bool:
        return self.control_of is None and not self.baseline

    @property
    def base(self) -> str:
        """The learning condition (itself, or the one a control is the control of)."""
        return self.control_of or self.name

    def config_overrides(self) -> dict[str, Any]:
        """Every controller field the condition sets over the C defaults (learn 0 where the controller
        does not learn: a control, a baseline, an optimiser's fixed policy)."""
        fixed = not self.learns or self.optimiser is not None
        return {"mode": self.mode, **self.overrides, **({"learn": 0} if fixed else {})}


def _learner(name: str, label: str, mode: str, prior: PriorRule | None = None,
             overrides: Mapping[str, Any] | None = None, with_control: bool = True) -> tuple[Condition, ...]:
    """A learning condition followed by its no-learning control (when it has one)."""
    cond = Condition(name, label, mode, prior, overrides or {})
    if not with_control:
        return (cond,)
    control = replace(cond, name=name + CONTROL_SUFFIX, label=label + " control", control_of=name)
    return replace(cond, control=control.name), control


# The conditions, in the order of the benchmark and its tables. The actor-critic runs from four
# priors: ICO->RL, and the prior taken apart (method.md, L6); the episodic search (L4) from the ICO
# prior or N(0, I). The overrides are the readings the learner sweeps chose (docs/sweeps.md,
# docs/sweeps-rl-alone.md); a condition without overrides runs the C defaults in its mode.
REGISTRY: Mapping[str, Condition] = MappingProxyType({c.name: c for c in (
    *_learner("ico", "ICO", "ico", with_control=False),
    # prior from an ICO grid (method.md, priors); the C defaults' reading
    *_learner("ico-rl", "ICO->RL", "rl", PriorRule("ico", "ico")),
    # the ICO mean with sigma_w^2 I: ICO->RL's reading
    *_learner("ico-mean-rl", "ICO mean->RL", "rl", PriorRule("ico", "isotropic")),
    # mean 0 with the ICO covariance (method.md, A16): the reading the learner sweeps chose for it
    *_learner("rl-ico-cov", "RL, ICO cov.", "rl", PriorRule("zero", "ico"), {
        "actor.update": "mean", "actor.likelihood_std": 0.1, "actor.noise_std": 5, "actor.scale": 0.1,
        "actor.explore_ticks": 1000}),
    # RL alone, N(0, sigma_w^2 I) with sigma_w = 1: the reading its own sweep chose (docs/sweeps-rl-alone.md)
    *_learner("rl", "RL alone", "rl", PriorRule("zero", "isotropic"), {
        "actor.update": "mean", "actor.likelihood_std": 0.1, "actor.noise_std": 12, "actor.scale": 0.1,
        "actor.explore_ticks": 1000}),
    # prior from an ICO grid, Sigma0 = search.cov_scale * its covariance (C default c = 64)
    *_learner("ico-search", "ICO->search", "search", PriorRule("ico", "ico")),
    # prior N(0, I) (method.md, L4); Sigma0 = 4 I by the sweeps
    *_learner("search", "search", "search", PriorRule("zero", "identity"), {"search.cov_scale": 4}),
    # no learning: the discrete LQR of the plant linearised upright, with the Q and R that give the
    # task its input signs (Q = diag(1 / input_range^2), R = 1 / G^2), acting as the fixed w of the
    # same policy (ICO mode with every update off acts with its prior mean)
    Condition("lqr", "LQR", "ico", PriorRule("lqr", "identity"), baseline=True),
    # CMA-ES per cell over the fixed w of the same policy, from the search control's N(0, 4 I)
    # (icoac.studies.baselines.cma_es); no control of its own: the search control is CMA-ES
    # without its adaptation
    Condition("cma-es", "CMA-ES", "ico", PriorRule("zero", "identity"), {"search.cov_scale": 4},
              optimiser="cma-es"),
)})

# Derived views.
CONDITIONS = tuple(REGISTRY)
# The conditions that run from a prior (everything but ICO), in order: the bench's stages after ICO.
PRIOR_CONDITIONS = tuple(c.name for c in REGISTRY.values() if c.prior is not None)
# The learners a sweep tunes (a prior condition that learns).
SWEEP_CONDITIONS = tuple(c.name for c in REGISTRY.values() if c.prior is not None and c.learns)


def _check() -> None:
    for c in REGISTRY.values():
        if c.control is not None:
            assert REGISTRY[c.control].control_of == c.name, c
        if c.control_of is not None:
            base = REGISTRY[c.control_of]
            assert base.control == c.name and (base.mode, base.prior, base.overrides) == \
                (c.mode, c.prior, c.overrides), c
        assert "mode" not in c.overrides and "learn" not in c.overrides, c
        assert not c.baseline or (c.control is None and c.control_of is None and c.prior is not None), c


_check()
