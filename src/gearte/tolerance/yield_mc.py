"""Production yield: a tolerance Monte-Carlo through any physics, with a spec, yield and Cpk.

The engine is generic: a *model* is any vectorised function of the drawn errors,
``model(errors: Mapping[str, ndarray]) -> Mapping[str, ndarray]`` (one value per sample and
quantity: lost motion, TE, rigidity, ...). A :class:`ToleranceSet` says how each error is
distributed; a list of :class:`SpecLimit` says what a good part is. :func:`run_yield` draws
the errors chunk by chunk on the execution layer and returns the yield with its confidence
interval, the capability of each quantity and the worst samples (with what was drawn, so a
user can rebuild and run each one on its own).

Every tolerance draws **one standard normal** ``z`` per sample (plus one uniform phase for
radial errors) and maps it through its quantile function. That single convention gives

* correlated groups (e.g. all pins ground in one batch) by a Gaussian copula:
  ``z_i = √ρ·z_group + √(1−ρ)·ε_i`` before the mapping, whatever the marginal law;
* common random numbers: the same ``z`` at another tolerance width is the same part made
  to a tighter or looser tolerance — the allocation search (:mod:`gearte.tolerance.allocation`)
  compares tolerance sets on identical draws;
* exact zeros: a tolerance of width 0 maps every ``z`` to the nominal value exactly.

Kinds and the meaning of ``tolerance`` (``t``) and σ
---------------------------------------------------
``normal``            ``nominal ± t``, σ = ``t / sigmas`` (default ``sigmas = 3``: 99.73 % inside).
``truncated_normal``  as ``normal`` and cut at ``nominal ± t`` (parts outside scrapped).
``uniform``           uniform on ``nominal ± t`` (σ = ``t/√3``).
``rayleigh``          magnitude ``r ≥ 0`` of a radial error (eccentricity, run-out): Rayleigh with
                      scale ``t / sigmas``, default ``sigmas = √(−2 ln 0.0027) = 3.44`` so that
                      99.73 % of parts have ``r ≤ t``; ``phase = true`` adds a uniform direction
                      ``<key>_phase_rad`` on [0, 2π).
``empirical``         measured values (deviations from nominal) of real parts, resampled; ``t``
                      rescales them (``t`` = the largest |measured value| keeps them as measured).
``constant``          fixed at ``nominal`` (no variation).

Seeds: chunk ``k`` of a run uses ``SeedSequence(seed).spawn(n_chunks)[k]``; its draws depend
on the chunk size and the seed only, so threads, processes and Dask give identical results.

References
----------
Wilson E. B. (1927) Probable inference, the law of succession, and statistical inference.
J. Am. Stat. Assoc. 22, 209–212. doi:10.1080/01621459.1927.10502953
Clopper C. J., Pearson E. S. (1934) The use of confidence or fiducial limits illustrated in
the case of the binomial. Biometrika 26, 404–413. doi:10.1093/biomet/26.4.404
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from gearte.errors import ParameterError
from gearte.execution import RunningStats, map_chunks, seeded_chunks

__all__ = [
    "KINDS",
    "Tolerance",
    "CorrelatedGroup",
    "ToleranceSet",
    "SpecLimit",
    "QuantityStats",
    "YieldResult",
    "run_yield",
    "wilson_interval",
    "clopper_pearson_interval",
    "evaluate_checked",
]

KINDS = ("normal", "truncated_normal", "uniform", "rayleigh", "empirical", "constant")
_RAYLEIGH_9973 = math.sqrt(-2.0 * math.log(0.0027))
_TWO_PI = 2.0 * math.pi

Model = Callable[[Mapping[str, np.ndarray]], Mapping[str, np.ndarray]]


# ------------------------------------------------------------------------------------------------
# tolerances
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Tolerance:
    """How one error family varies from part to part.

    Parameters
    ----------
    key : str
        The error's key, the same as the measured error it bounds in the drive's description.
    kind : str
        One of :data:`KINDS` (module docstring gives each one's meaning of ``tolerance``).
    tolerance : float
        The stated tolerance ``t ≥ 0`` [unit of the error, mm inside gearte].
    nominal : float
        The nominal (design) value [same unit]; the mean of a symmetric law.
    sigmas : float, optional
        ``σ = t / sigmas`` (normal kinds, default 3) or Rayleigh scale ``= t / sigmas``
        (default 3.44, the 99.73 % quantile).
    phase : bool
        Radial errors: also draw a uniform direction ``<key>_phase_rad`` [rad].
    values : sequence of float, optional
        ``empirical``: measured deviations from nominal [same unit].
    family : str, optional
        The tolerance this error's law comes from when one stated tolerance covers many
        errors (every pin's radius, every cam of every crank); contributions are reported per
        family. Default: the key itself.
    """

    key: str
    kind: str
    tolerance: float
    nominal: float = 0.0
    sigmas: float | None = None
    phase: bool = False
    values: tuple[float, ...] | None = None
    family: str | None = None

    @property
    def family_name(self) -> str:
        """The contribution group: ``family`` or the key."""
        return self.family or self.key

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ParameterError(f"{self.key}.kind", self.kind, f"must be one of {KINDS}")
        t = float(self.tolerance)
        if not (math.isfinite(t) and t >= 0):
            raise ParameterError(f"{self.key}.tolerance", self.tolerance, "must be finite, >= 0")
        if not math.isfinite(float(self.nominal)):
            raise ParameterError(f"{self.key}.nominal", self.nominal, "must be finite")
        if self.sigmas is not None and not (math.isfinite(self.sigmas) and self.sigmas > 0):
            raise ParameterError(f"{self.key}.sigmas", self.sigmas, "must be finite and > 0")
        if self.phase and self.kind != "rayleigh":
            raise ParameterError(
                f"{self.key}.phase", True, "a uniform phase goes with kind = 'rayleigh' only"
            )
        if self.kind == "empirical":
            v = np.asarray(self.values if self.values is not None else [], dtype=float)
            if v.size < 2 or not np.all(np.isfinite(v)):
                raise ParameterError(
                    f"{self.key}.values", self.values, "empirical needs >= 2 finite values"
                )
            object.__setattr__(self, "values", tuple(sorted(float(x) for x in v)))

    @property
    def divisor(self) -> float:
        """``t / σ`` (normal kinds) or ``t / scale`` (Rayleigh)."""
        if self.sigmas is not None:
            return float(self.sigmas)
        return _RAYLEIGH_9973 if self.kind == "rayleigh" else 3.0

    @property
    def sd(self) -> float:
        """Standard deviation of the drawn value (of the magnitude for a Rayleigh) [unit]."""
        t = float(self.tolerance)
        if self.kind == "normal":
            return t / self.divisor
        if self.kind == "truncated_normal":
            from scipy.stats import truncnorm

            c = self.divisor
            return float(truncnorm(-c, c).std()) * t / c
        if self.kind == "uniform":
            return t / math.sqrt(3.0)
        if self.kind == "rayleigh":
            return math.sqrt((4.0 - math.pi) / 2.0) * t / self.divisor
        if self.kind == "empirical":
            return float(np.std(self._scaled_values(t)))
        return 0.0

    @property
    def second_moment_radial(self) -> float:
        """Rayleigh: ``E[r²] = 2·scale²`` [unit²] (0 for other kinds)."""
        return 2.0 * (float(self.tolerance) / self.divisor) ** 2 if self.kind == "rayleigh" else 0.0

    def with_tolerance(self, tolerance: float) -> Tolerance:
        """The same law at another width ``t`` (empirical values rescaled)."""
        return replace(self, tolerance=float(tolerance))

    def columns(self) -> list[str]:
        """Names of the drawn columns (``key`` and, with a phase, ``key_phase_rad``)."""
        return [self.key, f"{self.key}_phase_rad"] if self.phase else [self.key]

    def _scaled_values(self, t: float) -> np.ndarray:
        v = np.asarray(self.values, dtype=float)
        ref = float(np.max(np.abs(v)))
        return v * (t / ref) if ref > 0 else v

    def transform(self, z: np.ndarray, tolerance: float | None = None) -> np.ndarray:
        """Map standard normals ``z`` to values of the error [unit] at width ``tolerance``."""
        from scipy.special import ndtr, ndtri

        t = float(self.tolerance if tolerance is None else tolerance)
        nom = float(self.nominal)
        if self.kind == "constant" or t == 0.0:
            return np.full(z.shape, nom)
        if self.kind == "normal":
            return nom + z * (t / self.divisor)
        if self.kind == "truncated_normal":
            c = self.divisor
            lo = ndtr(-c)
            u = lo + ndtr(z) * (1.0 - 2.0 * lo)
            return nom + ndtri(u) * (t / c)
        if self.kind == "uniform":
            return nom + (2.0 * ndtr(z) - 1.0) * t
        if self.kind == "rayleigh":
            # quantile of Rayleigh(scale): scale·√(−2 ln(1 − u)), u = Φ(z), 1 − u = Φ(−z)
            return nom + (t / self.divisor) * np.sqrt(-2.0 * np.log(ndtr(-z)))
        v = self._scaled_values(t)
        idx = np.minimum((ndtr(z) * v.size).astype(np.int64), v.size - 1)
        return nom + v[idx]


@dataclass(frozen=True)
class CorrelatedGroup:
    """Errors made together (one grinding batch, one fixture): a Gaussian copula with
    correlation ``rho`` between every two members' standard normals."""

    name: str
    keys: tuple[str, ...]
    rho: float

    def __post_init__(self) -> None:
        if not (0.0 <= self.rho <= 1.0):
            raise ParameterError(f"groups.{self.name}.rho", self.rho, "must be in [0, 1]")
        if len(self.keys) < 1:
            raise ParameterError(f"groups.{self.name}.keys", self.keys, "needs >= 1 key")


@dataclass(frozen=True)
class ToleranceSet:
    """The tolerances of one drive and their correlated groups."""

    tolerances: tuple[Tolerance, ...]
    groups: tuple[CorrelatedGroup, ...] = ()

    def __post_init__(self) -> None:
        keys = [t.key for t in self.tolerances]
        dup = sorted({k for k in keys if keys.count(k) > 1})
        if dup:
            raise ParameterError("tolerances", dup, "each error key may have one tolerance")
        seen: set[str] = set()
        for g in self.groups:
            for k in self.group_members(g):
                if k in seen:
                    raise ParameterError(f"groups.{g.name}.keys", k, "is in two groups")
                seen.add(k)

    def group_members(self, group: CorrelatedGroup) -> list[str]:
        """Tolerance keys of a group (a family name stands for all its members)."""
        keys = [t.key for t in self.tolerances]
        out: list[str] = []
        for k in group.keys:
            if k in keys:
                out.append(k)
                continue
            members = [t.key for t in self.tolerances if t.family_name == k]
            if not members:
                raise ParameterError(
                    f"groups.{group.name}.keys", k, "is not a tolerance key or family"
                )
            out += members
        return out

    @property
    def keys(self) -> list[str]:
        return [t.key for t in self.tolerances]

    @property
    def families(self) -> dict[str, list[int]]:
        """Family name → indices of its tolerances (in order of first appearance)."""
        out: dict[str, list[int]] = {}
        for i, t in enumerate(self.tolerances):
            out.setdefault(t.family_name, []).append(i)
        return out

    def family_widths(self, widths: Mapping[str, float]) -> dict[str, float]:
        """Per-key widths from per-family (or per-key) widths."""
        out: dict[str, float] = {}
        for t in self.tolerances:
            if t.key in widths:
                out[t.key] = float(widths[t.key])
            elif t.family_name in widths:
                out[t.key] = float(widths[t.family_name])
        return out

    def __getitem__(self, key: str) -> Tolerance:
        for t in self.tolerances:
            if t.key == key:
                return t
        raise KeyError(key)

    def with_tolerances(self, widths: Mapping[str, float]) -> ToleranceSet:
        """A copy with some widths changed (keyed by tolerance key or by family)."""
        w = self.family_widths(widths)
        return replace(
            self,
            tolerances=tuple(
                t.with_tolerance(w[t.key]) if t.key in w else t for t in self.tolerances
            ),
        )

    def zero(self) -> ToleranceSet:
        """Every tolerance at width 0 (the nominal drive)."""
        return self.with_tolerances({k: 0.0 for k in self.keys})

    def draw_standard(self, rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Standard normals ``(n, k)`` (correlated within groups) and phases ``(n, k)`` [rad].

        Draw order (fixed, so a seed gives the same parts): all normals, one row per sample;
        then one normal per group and sample; then all phases.
        """
        k = len(self.tolerances)
        z = rng.standard_normal((n, k))
        if self.groups:
            self._correlate(z, rng.standard_normal((n, len(self.groups))))
        phases = rng.uniform(0.0, _TWO_PI, (n, k))
        return z, phases

    def _correlate(self, z: np.ndarray, zg: np.ndarray) -> None:
        """The Gaussian copula of the groups, in place: ``z_i = √ρ z_g + √(1−ρ) z_i``."""
        for j, g in enumerate(self.groups):
            cols = [self.keys.index(key) for key in self.group_members(g)]
            z[:, cols] = math.sqrt(g.rho) * zg[:, j : j + 1] + math.sqrt(1.0 - g.rho) * z[:, cols]

    @property
    def uniform_dimension(self) -> int:
        """Uniforms one drawn drive needs (:meth:`standard_from_uniform`): one per tolerance,
        one per correlated group, one per phase."""
        return len(self.tolerances) + len(self.groups) + sum(t.phase for t in self.tolerances)

    def standard_from_uniform(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Standard normals ``(n, k)`` and phases ``(n, k)`` [rad] from uniforms ``u`` of shape
        ``(n, uniform_dimension)`` (a quasi-random point set): the same laws and groups as
        :meth:`draw_standard`, columns in the order tolerances, groups, phases."""
        from scipy.special import ndtri

        k, g = len(self.tolerances), len(self.groups)
        u = np.asarray(u, dtype=float)
        if u.ndim != 2 or u.shape[1] != self.uniform_dimension:
            raise ParameterError(
                "u", u.shape, f"needs shape (n, {self.uniform_dimension}) for this tolerance set"
            )
        tiny = 2.0**-54  # a scrambled point is never 0 or 1 in practice; keep ndtri finite
        z = ndtri(np.clip(u[:, : k + g], tiny, 1.0 - tiny))
        zs = np.ascontiguousarray(z[:, :k])
        if g:
            self._correlate(zs, z[:, k:])
        phases = np.zeros((u.shape[0], k))
        cols = [i for i, t in enumerate(self.tolerances) if t.phase]
        phases[:, cols] = _TWO_PI * u[:, k + g :]
        return zs, phases

    def factors(self) -> dict[str, list[str]]:
        """The independent factors of a variance decomposition: factor name → its families.

        Families are independent of each other unless a correlated group joins them; the
        families a group joins form one factor (named after the group, or the families joined
        by ``" + "`` where that name is a family of its own), so that factors are independent
        and a Sobol index of a factor is well defined. A group within one family leaves it a
        factor of its own.
        """
        fams = list(self.families)
        fam_of = {t.key: t.family_name for t in self.tolerances}
        parent = {f: f for f in fams}

        def root(f: str) -> str:
            while parent[f] != f:
                f = parent[f]
            return f

        joined: list[tuple[str, str]] = []
        for g in self.groups:
            members = sorted({fam_of[k] for k in self.group_members(g)}, key=fams.index)
            for f in members[1:]:
                parent[root(f)] = root(members[0])
            if len(members) > 1:
                joined.append((members[0], g.name))
        names: dict[str, str] = {}
        for f, name in joined:
            names.setdefault(root(f), name)
        out: dict[str, list[str]] = {}
        for f in fams:
            out.setdefault(root(f), []).append(f)
        named: dict[str, list[str]] = {}
        for r, members in out.items():
            if len(members) == 1:
                named[r] = members
                continue
            name = names.get(r, r)
            if name in fams or name in named:
                name = " + ".join(members)
            named[name] = members
        return named

    def values(
        self, z: np.ndarray, phases: np.ndarray, widths: Mapping[str, float] | None = None
    ) -> dict[str, np.ndarray]:
        """The drawn errors by column name, at the set's widths (or ``widths`` where given)."""
        out: dict[str, np.ndarray] = {}
        w_all = None if widths is None else self.family_widths(widths)
        for i, t in enumerate(self.tolerances):
            w = None if w_all is None else w_all.get(t.key)
            out[t.key] = t.transform(z[:, i], w)
            if t.phase:
                out[f"{t.key}_phase_rad"] = phases[:, i].copy()
        return out

    def sample(self, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
        """``n`` drawn drives: errors by column name."""
        z, ph = self.draw_standard(rng, n)
        return self.values(z, ph)

    def nominal_values(self, n: int = 1) -> dict[str, np.ndarray]:
        """The nominal drive (every error at its nominal, phases 0)."""
        out: dict[str, np.ndarray] = {}
        for t in self.tolerances:
            out[t.key] = np.full(n, float(t.nominal))
            if t.phase:
                out[f"{t.key}_phase_rad"] = np.zeros(n)
        return out


# ------------------------------------------------------------------------------------------------
# spec, statistics
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SpecLimit:
    """One catalogue requirement: ``lower ≤ quantity ≤ upper`` (either limit optional)."""

    quantity: str
    lower: float | None = None
    upper: float | None = None

    def __post_init__(self) -> None:
        if self.lower is None and self.upper is None:
            raise ParameterError(f"spec.{self.quantity}", None, "needs a lower or upper limit")
        for name, v in (("lower", self.lower), ("upper", self.upper)):
            if v is not None and not math.isfinite(v):
                raise ParameterError(f"spec.{self.quantity}.{name}", v, "must be finite")
        if self.lower is not None and self.upper is not None and self.upper < self.lower:
            raise ParameterError(
                f"spec.{self.quantity}", (self.lower, self.upper), "upper must be >= lower"
            )

    def margin(self, y: np.ndarray) -> np.ndarray:
        """Distance inside the limits [unit of the quantity] (negative: out of spec)."""
        m = np.full(np.shape(y), np.inf)
        if self.upper is not None:
            m = np.minimum(m, self.upper - y)
        if self.lower is not None:
            m = np.minimum(m, y - self.lower)
        return m


def wilson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion ``k/n`` (Wilson 1927); ``confidence``
    [-] its two-sided level."""
    from statistics import NormalDist  # not scipy.stats: a ~1 s import

    if n <= 0:
        raise ParameterError("n", n, "needs >= 1 trial")
    z = -NormalDist().inv_cdf((1.0 - confidence) / 2.0)
    p = k / n
    den = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (max(0.0, centre - half), min(1.0, centre + half))


def clopper_pearson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper–Pearson 1934) interval of a binomial proportion ``k/n``; ``confidence``
    [-] its two-sided level."""
    from scipy.stats import beta

    if n <= 0:
        raise ParameterError("n", n, "needs >= 1 trial")
    a = 1.0 - confidence
    lo = 0.0 if k == 0 else float(beta.ppf(a / 2, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(1 - a / 2, k + 1, n - k))
    return (lo, hi)


@dataclass
class QuantityStats:
    """Mean, σ, extremes and (with a spec) Cpk and the fraction failing this quantity.

    ``stats`` and ``cpk`` are of the finite values; ``non_finite`` counts the samples whose
    value was NaN or infinite (each one fails a spec on this quantity)."""

    name: str
    stats: RunningStats
    fail_fraction: float | None
    cpk: float | None
    non_finite: int = 0


@dataclass
class YieldResult:
    """Result of :func:`run_yield`.

    ``yield_`` is the fraction of samples meeting every spec limit; ``ci`` its confidence
    interval (``ci_method``); ``cpk`` the smallest Cpk of the specified quantities;
    ``quantities`` per-quantity statistics; ``worst`` the samples with the smallest normalised
    margin, each ``{"sample", "chunk", "row", "margin", "errors": {...}, "values": {...}}``;
    ``head`` the first ``keep`` samples' quantities (for plots); ``non_finite_samples`` the
    samples with a non-finite value of any quantity (counted as failing every spec limit on
    it, left out of the mean, σ and Cpk; named in ``warnings``).
    """

    n: int
    passed: int
    yield_: float
    ci: tuple[float, float]
    ci_method: str
    confidence: float
    cpk: float | None
    quantities: dict[str, QuantityStats]
    worst: list[dict[str, Any]]
    head: dict[str, np.ndarray]
    seed: int | None
    chunk_size: int
    spec: tuple[SpecLimit, ...]
    extra: dict[str, Any] = field(default_factory=dict)
    non_finite_samples: int = 0
    warnings: list[str] = field(default_factory=list)


def evaluate_checked(
    model: Model, errors: Mapping[str, np.ndarray], n: int
) -> dict[str, np.ndarray]:
    """Call ``model`` on ``errors`` (one array of ``n`` samples per key [units of the keys]) and
    return one float per sample per quantity."""
    out = model(errors)
    res: dict[str, np.ndarray] = {}
    for k, v in out.items():
        a = np.asarray(v, dtype=float)
        if a.shape != (n,):
            a = np.broadcast_to(a, (n,)).copy()
        res[k] = a
    return res


@dataclass
class _Partial:
    n: int
    passed: int
    stats: dict[str, RunningStats]
    fails: dict[str, int]
    worst: list[dict[str, Any]]
    head: dict[str, np.ndarray]
    non_finite: dict[str, int] = field(default_factory=dict)
    non_finite_samples: int = 0


@dataclass(frozen=True)
class _Shared:
    model: Any
    tolset: ToleranceSet
    spec: tuple[SpecLimit, ...]
    keep_worst: int
    keep_head: int
    scale: dict[str, float]
    chunk_size: int  # samples per chunk (all but the last): where each chunk starts


def _norm_margin(shared: _Shared, out: Mapping[str, np.ndarray], n: int) -> np.ndarray:
    m = np.full(n, np.inf)
    for s in shared.spec:
        mm = s.margin(out[s.quantity]) / shared.scale[s.quantity]
        m = np.minimum(m, np.where(np.isnan(mm), -np.inf, mm))
    return m


def _chunk(chunk: Any, shared: _Shared) -> _Partial:
    rng = chunk.rng()
    n = chunk.size
    errors = shared.tolset.sample(rng, n)
    out = evaluate_checked(shared.model, errors, n)
    for s in shared.spec:
        if s.quantity not in out:
            raise ParameterError(
                f"spec.{s.quantity}", s.quantity, f"is not a quantity of the model {sorted(out)}"
            )
    margin = _norm_margin(shared, out, n)
    ok = margin >= 0
    finite = {k: np.isfinite(v) for k, v in out.items()}
    stats = {k: RunningStats.of(v[finite[k]]) for k, v in out.items()}
    non_finite = {k: int(v.size - np.count_nonzero(finite[k])) for k, v in out.items()}
    bad = int(n - np.count_nonzero(np.logical_and.reduce(list(finite.values())))) if out else 0
    fails = {
        s.quantity: int(np.count_nonzero(~(s.margin(out[s.quantity]) >= 0))) for s in shared.spec
    }
    worst = []
    if shared.keep_worst and shared.spec:
        order = np.argsort(margin, kind="stable")[: shared.keep_worst]
        for j in order:
            worst.append(
                {
                    "chunk": int(chunk.index),
                    "row": int(j),
                    "margin": float(margin[j]),
                    "errors": {k: float(v[j]) for k, v in errors.items()},
                    "values": {k: float(v[j]) for k, v in out.items()},
                }
            )
    # only the chunks that hold the run's first ``keep_head`` samples return theirs: every other
    # chunk's result is O(1) in its samples (counts, moment sums, the worst ``keep_worst``)
    rows = max(0, min(n, shared.keep_head - int(chunk.index) * shared.chunk_size))
    head = {k: v[:rows].copy() for k, v in out.items()}
    return _Partial(n, int(np.count_nonzero(ok)), stats, fails, worst, head, non_finite, bad)


class _Reducer:
    def __init__(self, keep_worst: int, keep_head: int, chunk_size: int) -> None:
        self.keep_worst = keep_worst
        self.keep_head = keep_head
        self.chunk_size = chunk_size

    def __call__(self, acc: _Partial | None, p: _Partial) -> _Partial:
        if acc is None:
            return p
        stats = {k: acc.stats[k].merge(p.stats[k]) for k in acc.stats}
        fails = {k: acc.fails[k] + p.fails[k] for k in acc.fails}
        worst = sorted(acc.worst + p.worst, key=lambda w: (w["margin"], w["chunk"], w["row"]))
        head = {k: np.concatenate([acc.head[k], p.head[k]])[: self.keep_head] for k in acc.head}
        nf = {k: acc.non_finite.get(k, 0) + p.non_finite.get(k, 0) for k in acc.stats}
        return _Partial(
            acc.n + p.n,
            acc.passed + p.passed,
            stats,
            fails,
            worst[: self.keep_worst],
            head,
            nf,
            acc.non_finite_samples + p.non_finite_samples,
        )


def run_yield(
    model: Model,
    tolerances: ToleranceSet,
    spec: Sequence[SpecLimit],
    n: int,
    *,
    seed: int | None = 0,
    chunk_size: int = 2_000,
    confidence: float = 0.95,
    ci_method: str = "wilson",
    keep_worst: int = 5,
    keep_head: int = 5_000,
    options: Any = None,
    progress: bool | None = False,
) -> YieldResult:
    """Yield of a drive against a spec by Monte-Carlo through its physics.

    Parameters
    ----------
    model : callable
        ``model(errors) -> {quantity: values}``, vectorised over samples; picklable (a
        module-level function or an object of a module-level class) for processes / Dask.
    tolerances : ToleranceSet
    spec : sequence of SpecLimit
        What a good part is; empty: statistics only (``yield`` = 1).
    n : int
        Samples (assembled drives), ``≥ 1``.
    seed : int
        Root seed of the chunk streams.
    chunk_size : int
        Samples per chunk (fixes the streams; memory per worker ∝ ``chunk_size``).
    confidence : float
        Level of the yield's confidence interval [-].
    ci_method : {"wilson", "clopper-pearson"}
    keep_worst : int
        Worst samples kept (smallest margin to the spec, normalised by each quantity's spec
        width or scale), with their drawn errors.
    keep_head : int
        Leading samples' quantities kept for histograms.
    options : RunOptions, optional
        ``workers``, ``scheduler`` (threads / processes / Dask) and ``progress``.

    Returns
    -------
    YieldResult
    """
    n = int(n)
    if n < 1:
        raise ParameterError("samples", n, "must be >= 1")
    if chunk_size < 1:
        raise ParameterError("chunk_size", chunk_size, "must be >= 1")
    if ci_method not in ("wilson", "clopper-pearson"):
        raise ParameterError("ci_method", ci_method, "must be 'wilson' or 'clopper-pearson'")
    if not 0.0 < confidence < 1.0:
        raise ParameterError("confidence", confidence, "must be in (0, 1)")
    spec = tuple(spec)
    # normalise margins by each quantity's scale so one worst list ranks several quantities
    scale: dict[str, float] = {}
    nominal = evaluate_checked(model, tolerances.nominal_values(1), 1)
    declared = getattr(model, "quantities", None)
    if declared is not None and sorted(declared) != sorted(nominal):
        # the pre-flight checks a spec against the declared names: they must be the outputs
        raise RuntimeError(
            f"{type(model).__name__}.quantities {sorted(declared)} differ from its outputs "
            f"{sorted(nominal)}"
        )
    for s in spec:
        if s.quantity not in nominal:
            raise ParameterError(
                f"spec.{s.quantity}",
                s.quantity,
                f"is not a quantity of the model {sorted(nominal)}",
            )
        if s.lower is not None and s.upper is not None and s.upper > s.lower:
            scale[s.quantity] = (s.upper - s.lower) / 2.0
        else:
            lim = s.upper if s.upper is not None else s.lower
            assert lim is not None  # SpecLimit has at least one limit
            scale[s.quantity] = max(abs(lim), abs(float(nominal[s.quantity][0])), 1e-300)
    shared = _Shared(model, tolerances, spec, keep_worst, keep_head, scale, chunk_size)
    chunks = seeded_chunks(n, chunk_size, seed)
    total = map_chunks(
        _chunk,
        chunks,
        shared=shared,
        reduce=_Reducer(keep_worst, keep_head, chunk_size),
        initial=None,
        options=options,
        progress=progress,
        description=f"yield Monte-Carlo ({n} samples)",
    )
    from gearte.tolerance.montecarlo import process_capability

    ci = (
        wilson_interval(total.passed, total.n, confidence)
        if ci_method == "wilson"
        else clopper_pearson_interval(total.passed, total.n, confidence)
    )
    quantities: dict[str, QuantityStats] = {}
    specs = {s.quantity: s for s in spec}
    cpks = []
    for k, st in total.stats.items():
        sp = specs.get(k)
        cpk = None
        ff = None
        if sp is not None:
            ff = total.fails[k] / total.n
            if st.count > 1:
                _, cpk = process_capability(st.mean, st.sd, sp.lower, sp.upper)
            if cpk is not None:
                cpks.append(cpk)
        quantities[k] = QuantityStats(k, st, ff, cpk, total.non_finite.get(k, 0))
    for w in total.worst:
        w["sample"] = w["chunk"] * chunk_size + w["row"]
    return YieldResult(
        n=total.n,
        passed=total.passed,
        yield_=total.passed / total.n,
        ci=ci,
        ci_method=ci_method,
        confidence=confidence,
        cpk=min(cpks) if cpks else None,
        quantities=quantities,
        worst=total.worst,
        head=total.head,
        seed=seed,
        chunk_size=chunk_size,
        spec=spec,
        non_finite_samples=total.non_finite_samples,
        warnings=_non_finite_warnings(total),
    )


def _non_finite_warnings(total: _Partial) -> list[str]:
    """What the non-finite samples of a run did to its statistics (nothing when none)."""
    if not total.non_finite_samples:
        return []
    per = ", ".join(f"{k}: {v}" for k, v in total.non_finite.items() if v)
    return [
        f"{total.non_finite_samples} of {total.n} samples gave a non-finite value ({per}): "
        "counted as failing every spec limit on that quantity, left out of its mean, σ and "
        "Cpk (Cpk of the finite samples only)"
    ]


def redraw_sample(tolerances: ToleranceSet, seed: int | None, chunk_size: int, sample: int, n: int):
    """The errors of sample ``sample`` of a run (``n`` samples, ``seed``, ``chunk_size``):
    rebuilds the chunk's stream and draws it again (reproducibility check of a kept case)."""
    chunks = seeded_chunks(n, chunk_size, seed)
    c = chunks[sample // chunk_size]
    errs = tolerances.sample(c.rng(), c.size)
    return {k: float(v[sample % chunk_size]) for k, v in errs.items()}
