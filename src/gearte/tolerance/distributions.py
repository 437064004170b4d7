"""Probability distributions of tolerance contributors.

Every distribution knows its analytic mean and variance, its *limits* (the range a designer
states for it: the limit deviations of a normal, the tolerance of a Rayleigh, ...) and how to
draw samples, both vectorised (``sample(rng, n)``) and one at a time (``draw_one(rng)``), from a
``numpy.random.Generator``. The compiled Monte-Carlo kernel of
:mod:`gearte.tolerance.montecarlo` draws the kernel-drawable ones from its own streams
(:mod:`gearte.tolerance.rng`) with the same laws; its plain reference is
:func:`gearte.tolerance.montecarlo.linear_stack_reference`.

The conventions follow Jiang et al. (2024) §2.1 and the tolerance literature they cite: a
dimension between limit deviations is normal with its mean at the middle and ``σ = range / 6``
(99.73 % inside the limits); a radial error such as a geometric eccentricity has a Rayleigh
magnitude whose scale is tied to a stated tolerance (``σx = F″i / 6``) and a uniform phase.

Units are whatever the caller uses consistently (gearte uses mm inside).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError

__all__ = [
    "Distribution",
    "Normal",
    "Uniform",
    "Rayleigh",
    "RadialPhase",
    "Truncated",
    "Empirical",
    "Constant",
    "KERNEL_CODES",
]

#: Codes of the distributions the compiled linear-stack kernel can draw (see montecarlo.py).
KERNEL_CODES: dict[str, int] = {
    "normal": 0,
    "uniform": 1,
    "rayleigh": 2,
    "rayleigh_phase": 3,
    "empirical": 4,
    "constant": 5,
    "rayleigh_phase_polar": 6,
}

_TWO_PI = 2.0 * math.pi


def _finite(field_name: str, value: float) -> float:
    v = float(value)
    if not math.isfinite(v):
        raise ParameterError(field_name, value, "must be a finite number")
    return v


class Distribution(ABC):
    """Base class: analytic moments, limits, vectorised and scalar sampling."""

    #: kernel code name or ``None`` when the compiled kernel cannot draw it
    _KERNEL: ClassVar[str | None] = None

    @property
    def kernel_kind(self) -> str | None:
        """Name of the compiled-kernel code for this distribution, ``None`` if not drawable."""
        return self._KERNEL

    @property
    @abstractmethod
    def mean(self) -> float:
        """Analytic mean."""

    @property
    @abstractmethod
    def variance(self) -> float:
        """Analytic variance."""

    @property
    def sd(self) -> float:
        """Analytic standard deviation."""
        return math.sqrt(self.variance)

    @property
    @abstractmethod
    def limits(self) -> tuple[float, float]:
        """The stated range ``(low, high)`` used by worst-case and RSS stacks."""

    @abstractmethod
    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` independent draws as a float array."""

    @abstractmethod
    def draw_one(self, rng: np.random.Generator) -> float:
        """One draw (the scalar reference of the compiled kernel)."""

    def kernel_params(self) -> tuple[float, float, float, float]:
        """Up to four parameters the compiled kernel needs (only if ``kernel_kind``)."""
        raise NotImplementedError

    def kernel_pool(self) -> np.ndarray | None:
        """Sample pool of an empirical distribution (``None`` for parametric ones)."""
        return None


@dataclass(frozen=True)
class Normal(Distribution):
    """Normal distribution ``N(mu, sd²)``.

    Parameters
    ----------
    mu : float
        Mean [unit of the quantity].
    sigma : float
        Standard deviation [same unit], ``≥ 0`` (0 is a fixed value).
    lower, upper : float, optional
        Stated limits; default ``mu ∓ 3 sigma``.
    """

    mu: float
    sigma: float
    lower: float | None = None
    upper: float | None = None
    _KERNEL: ClassVar[str | None] = "normal"

    def __post_init__(self) -> None:
        _finite("mu", self.mu)
        if not (math.isfinite(self.sigma) and self.sigma >= 0.0):
            raise ParameterError("sigma", self.sigma, "standard deviation must be finite and >= 0")

    @classmethod
    def from_limits(
        cls, lower: float, upper: float, *, field: str = "limits", sigmas: float = 6.0
    ) -> Normal:
        """Normal between limit deviations: mean at the middle, ``σ = (upper − lower)/sigmas``.

        ``sigmas = 6`` is the paper's convention (99.73 % of parts inside the limits).
        Raises :class:`ParameterError` naming ``field`` if the limits are inverted.
        """
        lo = _finite(f"{field}.lower", lower)
        hi = _finite(f"{field}.upper", upper)
        if hi < lo:
            raise ParameterError(
                field, (lower, upper), "inverted limits: the upper limit must be >= the lower"
            )
        if not sigmas > 0:
            raise ParameterError("sigmas", sigmas, "must be > 0")
        return cls(0.5 * (lo + hi), (hi - lo) / sigmas, lo, hi)

    @classmethod
    def from_tolerance(cls, tolerance: float, *, field: str = "tolerance") -> Normal:
        """Symmetric limits ``±tolerance`` (``tolerance ≥ 0``), ``σ = tolerance / 3``."""
        t = _finite(field, tolerance)
        if t < 0:
            raise ParameterError(field, tolerance, "a ± tolerance must be >= 0")
        return cls.from_limits(-t, t, field=field)

    @property
    def mean(self) -> float:
        return float(self.mu)

    @property
    def variance(self) -> float:
        return float(self.sigma) ** 2

    @property
    def limits(self) -> tuple[float, float]:
        lo = self.mu - 3.0 * self.sigma if self.lower is None else self.lower
        hi = self.mu + 3.0 * self.sigma if self.upper is None else self.upper
        return (float(lo), float(hi))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return self.mu + self.sigma * rng.standard_normal(n)

    def draw_one(self, rng: np.random.Generator) -> float:
        return self.mu + self.sigma * rng.standard_normal()

    def kernel_params(self) -> tuple[float, float, float, float]:
        return (float(self.mu), float(self.sigma), 0.0, 0.0)


@dataclass(frozen=True)
class Uniform(Distribution):
    """Uniform distribution on ``[lower, upper)``."""

    lower: float
    upper: float
    _KERNEL: ClassVar[str | None] = "uniform"

    def __post_init__(self) -> None:
        _finite("lower", self.lower)
        _finite("upper", self.upper)
        if self.upper < self.lower:
            raise ParameterError(
                "limits", (self.lower, self.upper), "inverted limits: upper must be >= lower"
            )

    @property
    def mean(self) -> float:
        return 0.5 * (self.lower + self.upper)

    @property
    def variance(self) -> float:
        return (self.upper - self.lower) ** 2 / 12.0

    @property
    def limits(self) -> tuple[float, float]:
        return (float(self.lower), float(self.upper))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.uniform(self.lower, self.upper, n)

    def draw_one(self, rng: np.random.Generator) -> float:
        return rng.uniform(self.lower, self.upper)

    def kernel_params(self) -> tuple[float, float, float, float]:
        return (float(self.lower), float(self.upper), 0.0, 0.0)


@dataclass(frozen=True)
class Rayleigh(Distribution):
    """Rayleigh distribution of a radial error magnitude (e.g. a geometric eccentricity).

    Parameters
    ----------
    scale : float
        Scale parameter ``σx`` [unit of the quantity], ``> 0``.
    tolerance : float, optional
        The tolerance the scale was tied to; it is the upper limit. Default: the 99.73 %
        quantile ``σx·sqrt(−2 ln 0.0027)``.

    Notes
    -----
    ``mean = σx·sqrt(π/2)``, ``variance = (4 − π)/2·σx²``, ``E[r²] = 2σx²``.
    """

    scale: float
    tolerance: float | None = None
    _KERNEL: ClassVar[str | None] = "rayleigh"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.scale) and self.scale > 0):
            raise ParameterError("scale", self.scale, "Rayleigh scale must be finite and > 0")

    @classmethod
    def from_tolerance(
        cls,
        tolerance: float,
        *,
        divisor: float = 6.0,
        factor: float = 1.0,
        field: str = "tolerance",
    ) -> Rayleigh:
        """Scale tied to a tolerance: ``σx = factor · tolerance / divisor``.

        Jiang et al. (2024): ``σx = F″i/6`` for a spur gear, ``σx = √2·F″iΣ/6`` for a bevel gear.
        Raises :class:`ParameterError` naming ``field`` if the resulting scale is ``≤ 0``.
        """
        t = _finite(field, tolerance)
        scale = factor * t / divisor
        if not scale > 0:
            raise ParameterError(
                field,
                tolerance,
                f"the Rayleigh scale factor*tolerance/divisor = {scale} must be > 0",
            )
        return cls(scale, factor * t)

    @property
    def mean(self) -> float:
        return self.scale * math.sqrt(math.pi / 2.0)

    @property
    def variance(self) -> float:
        return (4.0 - math.pi) / 2.0 * self.scale**2

    @property
    def second_moment(self) -> float:
        """``E[r²] = 2σx²``."""
        return 2.0 * self.scale**2

    @property
    def limits(self) -> tuple[float, float]:
        hi = (
            self.tolerance
            if self.tolerance is not None
            else self.scale * math.sqrt(-2.0 * math.log(0.0027))
        )
        return (0.0, float(hi))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.rayleigh(self.scale, n)

    def draw_one(self, rng: np.random.Generator) -> float:
        return rng.rayleigh(self.scale)

    def kernel_params(self) -> tuple[float, float, float, float]:
        return (float(self.scale), 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class RadialPhase(Distribution):
    """Projection ``r·sin φ`` of a radial error with random magnitude ``r`` and uniform phase.

    This is how an eccentricity ``e`` (or a runout) changes a centre distance: ``Δa = e sin φ``
    with ``φ ~ U[0, 2π)`` (Jiang et al. 2024, §2.1 items 3 and 5).

    Parameters
    ----------
    magnitude : Distribution
        Distribution of ``r ≥ 0`` (e.g. :class:`Rayleigh` with ``σx = F″i/6``).
    polar : bool
        Only for a Rayleigh magnitude: make the scalar draw (and the compiled kernel) draw ``r``
        and ``φ`` separately instead of the equivalent normal (same distribution, ~5× slower).

    Notes
    -----
    For any magnitude distribution, ``E[r sin φ] = 0`` and ``Var = E[r²]/2``. For a Rayleigh
    magnitude, ``r sin φ`` is *exactly* normal ``N(0, σx²)`` (a Rayleigh radius with a uniform
    angle is an isotropic 2-D normal; ``r sin φ`` is one of its components), which is why the
    paper's variances ``F″²sin²α/9`` come out as they do. The scalar draw and the compiled kernel
    use that identity (one ``standard_normal`` call); the vectorised :meth:`sample` always
    draws the magnitude and the phase separately, so comparing the two engines checks it.
    """

    magnitude: Distribution
    polar: bool = False

    def __post_init__(self) -> None:
        lo, _ = self.magnitude.limits
        if lo < 0:
            raise ParameterError(
                "magnitude", self.magnitude, "a radial magnitude must not be negative"
            )

    @property
    def kernel_kind(self) -> str | None:
        if not isinstance(self.magnitude, Rayleigh):
            return None
        return "rayleigh_phase_polar" if self.polar else "rayleigh_phase"

    @property
    def mean(self) -> float:
        return 0.0

    @property
    def variance(self) -> float:
        m = self.magnitude
        return 0.5 * (m.variance + m.mean**2)

    @property
    def limits(self) -> tuple[float, float]:
        hi = self.magnitude.limits[1]
        return (-float(hi), float(hi))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        r = self.magnitude.sample(rng, n)
        phi = rng.uniform(0.0, _TWO_PI, n)
        return r * np.sin(phi)

    def draw_one(self, rng: np.random.Generator) -> float:
        if isinstance(self.magnitude, Rayleigh) and not self.polar:
            return self.magnitude.scale * rng.standard_normal()
        r = self.magnitude.draw_one(rng)
        return r * math.sin(rng.uniform(0.0, _TWO_PI))

    def kernel_params(self) -> tuple[float, float, float, float]:
        return (float(self.magnitude.scale), 0.0, 0.0, 0.0)  # type: ignore[attr-defined]


@dataclass(frozen=True)
class Truncated(Distribution):
    """A base distribution truncated to ``[lower, upper]`` (e.g. parts outside the limits scrapped).

    Moments are computed by quadrature of the base density; sampling is by inverse CDF
    (``u ~ U[F(lower), F(upper)]``, ``x = F⁻¹(u)``). Works for :class:`Normal`, :class:`Uniform`,
    :class:`Rayleigh` and :class:`RadialPhase` with a Rayleigh magnitude (which is normal).
    """

    base: Distribution
    lower: float
    upper: float
    _frozen: object = field(init=False, repr=False, compare=False)
    _cdf_lo: float = field(init=False, repr=False, compare=False)
    _cdf_hi: float = field(init=False, repr=False, compare=False)
    _moments: tuple[float, float] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        from scipy import stats

        lo = _finite("lower", self.lower)
        hi = _finite("upper", self.upper)
        if not hi > lo:
            raise ParameterError(
                "limits", (self.lower, self.upper), "truncation limits must satisfy lower < upper"
            )
        b = self.base
        if isinstance(b, Normal):
            frozen = stats.norm(b.mu, b.sigma) if b.sigma > 0 else None
        elif isinstance(b, Uniform):
            frozen = stats.uniform(b.lower, b.upper - b.lower)
        elif isinstance(b, Rayleigh):
            frozen = stats.rayleigh(scale=b.scale)
        elif isinstance(b, RadialPhase) and isinstance(b.magnitude, Rayleigh):
            frozen = stats.norm(0.0, b.magnitude.scale)
        else:
            raise ParameterError("base", b, "truncation supports Normal, Uniform, Rayleigh")
        if frozen is None:
            raise ParameterError("base.sigma", 0.0, "cannot truncate a fixed value")
        c_lo, c_hi = float(frozen.cdf(lo)), float(frozen.cdf(hi))
        if not c_hi - c_lo > 1e-12:
            raise ParameterError(
                "limits", (lo, hi), "the truncation interval holds no probability of the base"
            )
        mean = float(frozen.expect(lambda x: x, lb=lo, ub=hi, conditional=True))
        m2 = float(frozen.expect(lambda x: (x - mean) ** 2, lb=lo, ub=hi, conditional=True))
        object.__setattr__(self, "_frozen", frozen)
        object.__setattr__(self, "_cdf_lo", c_lo)
        object.__setattr__(self, "_cdf_hi", c_hi)
        object.__setattr__(self, "_moments", (mean, m2))

    @property
    def mean(self) -> float:
        return self._moments[0]

    @property
    def variance(self) -> float:
        return self._moments[1]

    @property
    def limits(self) -> tuple[float, float]:
        return (float(self.lower), float(self.upper))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        u = rng.uniform(self._cdf_lo, self._cdf_hi, n)
        return np.clip(self._frozen.ppf(u), self.lower, self.upper)  # type: ignore[attr-defined]

    def draw_one(self, rng: np.random.Generator) -> float:
        return float(self.sample(rng, 1)[0])


@dataclass(frozen=True, eq=False)
class Empirical(Distribution):
    """Measured values of real parts, resampled with replacement (bootstrap).

    Parameters
    ----------
    values : array_like
        At least two finite measurements [unit of the quantity].

    Notes
    -----
    The variance is the population variance (``ddof = 0``): that is exactly the variance of a
    draw with replacement from the measured set.
    """

    values: np.ndarray
    _KERNEL: ClassVar[str | None] = "empirical"

    def __init__(self, values: ArrayLike, *, field: str = "values") -> None:
        v = np.asarray(values, dtype=float).ravel()
        if v.size < 2:
            raise ParameterError(field, v.size, "an empirical distribution needs >= 2 values")
        if not np.all(np.isfinite(v)):
            raise ParameterError(field, "non-finite", "all measured values must be finite")
        v = v.copy()
        v.setflags(write=False)
        object.__setattr__(self, "values", v)

    @property
    def mean(self) -> float:
        return float(np.mean(self.values))

    @property
    def variance(self) -> float:
        return float(np.var(self.values))

    @property
    def limits(self) -> tuple[float, float]:
        return (float(self.values.min()), float(self.values.max()))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return self.values[rng.integers(0, self.values.size, n)]

    def draw_one(self, rng: np.random.Generator) -> float:
        return float(self.values[rng.integers(0, self.values.size)])

    def kernel_params(self) -> tuple[float, float, float, float]:
        return (0.0, float(self.values.size), 0.0, 0.0)

    def kernel_pool(self) -> np.ndarray | None:
        return self.values


@dataclass(frozen=True)
class Constant(Distribution):
    """A fixed value (no variation)."""

    value: float
    _KERNEL: ClassVar[str | None] = "constant"

    @property
    def mean(self) -> float:
        return float(self.value)

    @property
    def variance(self) -> float:
        return 0.0

    @property
    def limits(self) -> tuple[float, float]:
        return (float(self.value), float(self.value))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return np.full(n, float(self.value))

    def draw_one(self, rng: np.random.Generator) -> float:
        return float(self.value)

    def kernel_params(self) -> tuple[float, float, float, float]:
        return (float(self.value), 0.0, 0.0, 0.0)
