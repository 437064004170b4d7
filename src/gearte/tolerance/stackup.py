"""Tolerance stack-up: linear sensitivities or any vectorised function of the contributors.

Two kinds of stack share one interface (``names``, ``distributions``, ``sample_inputs``,
``evaluate``, ``sample``) so that Monte-Carlo (:mod:`gearte.tolerance.montecarlo`) and
contributions (:mod:`gearte.tolerance.contributions`) work with both:

* :class:`LinearStack` — ``y = c + Σ sᵢ xᵢ`` with analytic mean ``c + Σ sᵢ μᵢ``, variance
  ``Σ sᵢ² σᵢ²`` (independent contributors), worst case and RSS limits;
* :class:`FunctionStack` — ``y = f(x₁, …, xₙ)`` for any vectorised ``f``; its analytic
  approximation is the first-order (delta-method) linearisation :meth:`FunctionStack.linearised`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from gearte.errors import ParameterError
from gearte.tolerance.distributions import Distribution

__all__ = [
    "Contributor",
    "LinearStack",
    "FunctionStack",
    "z_for_confidence",
]


def z_for_confidence(confidence: float) -> float:
    """Two-sided normal quantile: ``z`` [-] with ``P(|Z| ≤ z) = confidence`` [-] (0.9973 → 3.0).

    The standard library's ``NormalDist.inv_cdf`` (Wichura's AS 241, ~1e-16 relative): the
    ~1 s import of ``scipy.stats`` was most of a warm run of a fast chain case."""
    from statistics import NormalDist

    if not 0.0 < confidence < 1.0:
        raise ParameterError("confidence", confidence, "must be in (0, 1), e.g. 0.9973")
    return -NormalDist().inv_cdf((1.0 - confidence) / 2.0)


@dataclass(frozen=True)
class Contributor:
    """One tolerance contributor of a stack.

    Parameters
    ----------
    name : str
        Label used in contributions and reports.
    distribution : Distribution
        Its variation.
    sensitivity : float
        ``∂y/∂x`` for a linear stack (ignored by :class:`FunctionStack`).
    group : str, optional
        Contributions of contributors sharing a group can be summed (e.g. four profile faces).
    """

    name: str
    distribution: Distribution
    sensitivity: float = 1.0
    group: str | None = None

    def __post_init__(self) -> None:
        if not math.isfinite(self.sensitivity):
            raise ParameterError(f"{self.name}.sensitivity", self.sensitivity, "must be finite")


def _check_names(contributors: Sequence[Contributor]) -> None:
    if not contributors:
        raise ParameterError("contributors", [], "a stack needs at least one contributor")
    names = [c.name for c in contributors]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise ParameterError("contributors", sorted(dup), "contributor names must be unique")


class _StackBase:
    contributors: tuple[Contributor, ...]

    @property
    def names(self) -> list[str]:
        return [c.name for c in self.contributors]

    @property
    def distributions(self) -> list[Distribution]:
        return [c.distribution for c in self.contributors]

    def sample_inputs(self, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
        """Draw ``n`` samples of every contributor (vectorised, contributor by contributor)."""
        return {c.name: c.distribution.sample(rng, n) for c in self.contributors}

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` samples of the stacked quantity."""
        return self.evaluate(self.sample_inputs(rng, n))

    def evaluate(self, inputs: Mapping[str, np.ndarray]) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError


class LinearStack(_StackBase):
    """Linear stack ``y = constant + Σ sᵢ xᵢ`` of independent contributors.

    Parameters
    ----------
    contributors : sequence of Contributor
    constant : float
        Nominal offset of the stacked quantity.
    name, unit : str
        Label and unit of ``y`` (for reports).
    """

    def __init__(
        self,
        contributors: Sequence[Contributor],
        constant: float = 0.0,
        *,
        name: str = "y",
        unit: str = "",
    ) -> None:
        _check_names(contributors)
        if not math.isfinite(constant):
            raise ParameterError("constant", constant, "must be finite")
        self.contributors = tuple(contributors)
        self.constant = float(constant)
        self.name = name
        self.unit = unit

    @property
    def sensitivities(self) -> np.ndarray:
        return np.array([c.sensitivity for c in self.contributors], dtype=float)

    # -- analytic -------------------------------------------------------------------------------
    @property
    def mean(self) -> float:
        """``c + Σ sᵢ μᵢ``."""
        return self.constant + sum(c.sensitivity * c.distribution.mean for c in self.contributors)

    @property
    def variance(self) -> float:
        """``Σ sᵢ² σᵢ²`` (independent contributors)."""
        return sum(c.sensitivity**2 * c.distribution.variance for c in self.contributors)

    @property
    def sd(self) -> float:
        return math.sqrt(self.variance)

    def contributor_means(self) -> dict[str, float]:
        """``sᵢ μᵢ`` per contributor."""
        return {c.name: c.sensitivity * c.distribution.mean for c in self.contributors}

    def contributor_variances(self) -> dict[str, float]:
        """``sᵢ² σᵢ²`` per contributor."""
        return {c.name: c.sensitivity**2 * c.distribution.variance for c in self.contributors}

    def statistical_limits(self, confidence: float = 0.9973) -> tuple[float, float]:
        """``mean ∓ z·sd`` with ``z`` the two-sided normal quantile of ``confidence``.

        This is the paper's "6σ range at 99.7 %" when ``confidence = 0.9973``.
        """
        z = z_for_confidence(confidence)
        return (self.mean - z * self.sd, self.mean + z * self.sd)

    def worst_case(self) -> tuple[float, float]:
        """Arithmetic worst case: every contributor at the limit that moves ``y`` the same way."""
        lo = hi = self.constant
        for c in self.contributors:
            a, b = c.distribution.limits
            ya, yb = c.sensitivity * a, c.sensitivity * b
            lo += min(ya, yb)
            hi += max(ya, yb)
        return (lo, hi)

    def rss(self) -> tuple[float, float]:
        """Root-sum-square limits: middle of the limits ∓ ``sqrt(Σ (sᵢhᵢ)²)``, ``hᵢ`` half-width."""
        mid = self.constant
        acc = 0.0
        for c in self.contributors:
            a, b = c.distribution.limits
            mid += c.sensitivity * 0.5 * (a + b)
            acc += (c.sensitivity * 0.5 * (b - a)) ** 2
        half = math.sqrt(acc)
        return (mid - half, mid + half)

    def shifted(self, delta: float, *, name: str | None = None) -> LinearStack:
        """The same stack with its constant moved by ``delta`` (e.g. a shim)."""
        return LinearStack(
            self.contributors, self.constant + delta, name=name or self.name, unit=self.unit
        )

    # -- sampling -------------------------------------------------------------------------------
    def evaluate(self, inputs: Mapping[str, np.ndarray]) -> np.ndarray:
        y: np.ndarray = np.asarray(0.0)
        for c in self.contributors:
            y = y + c.sensitivity * np.asarray(inputs[c.name], dtype=float)
        return self.constant + y

    def kernel_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """``(codes, params[k,4], sensitivities, pool)`` for the compiled kernel, or ``None``.

        ``pool`` concatenates the values of empirical contributors; their ``params`` hold the
        offset into the pool and the count.
        """
        from gearte.tolerance.distributions import KERNEL_CODES

        codes = np.empty(len(self.contributors), dtype=np.int64)
        params = np.zeros((len(self.contributors), 4))
        pools: list[np.ndarray] = []
        offset = 0
        for i, c in enumerate(self.contributors):
            kind = c.distribution.kernel_kind
            if kind is None:
                return None
            codes[i] = KERNEL_CODES[kind]
            params[i] = c.distribution.kernel_params()
            pool = c.distribution.kernel_pool()
            if pool is not None:
                params[i, 0] = offset
                pools.append(pool)
                offset += pool.size
        pool_arr = np.concatenate(pools) if pools else np.zeros(1)
        return codes, params, self.sensitivities, pool_arr


class FunctionStack(_StackBase):
    """Nonlinear stack ``y = func(inputs)`` of independent contributors.

    Parameters
    ----------
    func : callable
        ``func(inputs: Mapping[str, ndarray]) -> ndarray``, vectorised over samples.
    contributors : sequence of Contributor
        Sensitivities are ignored.
    name, unit : str
    """

    def __init__(
        self,
        func: Callable[[Mapping[str, np.ndarray]], np.ndarray],
        contributors: Sequence[Contributor],
        *,
        name: str = "y",
        unit: str = "",
    ) -> None:
        _check_names(contributors)
        self.func = func
        self.contributors = tuple(contributors)
        self.name = name
        self.unit = unit

    def evaluate(self, inputs: Mapping[str, np.ndarray]) -> np.ndarray:
        return np.asarray(self.func(inputs), dtype=float)

    def linearised(self, *, rel_step: float = 1e-6) -> LinearStack:
        """First-order (delta-method) linear stack at the means, central differences.

        The step of contributor ``i`` is ``rel_step·max(σᵢ, |μᵢ|, 1e-12)``.
        """
        means = {c.name: np.array([c.distribution.mean]) for c in self.contributors}
        y0 = float(self.evaluate(means)[0])
        lin = []
        const = y0
        for c in self.contributors:
            d = c.distribution
            h = rel_step * max(d.sd, abs(d.mean), 1e-12)
            up = dict(means)
            dn = dict(means)
            up[c.name] = means[c.name] + h
            dn[c.name] = means[c.name] - h
            s = float((self.evaluate(up)[0] - self.evaluate(dn)[0]) / (2 * h))
            lin.append(Contributor(c.name, d, s, c.group))
            const -= s * d.mean
        return LinearStack(lin, const, name=self.name, unit=self.unit)
