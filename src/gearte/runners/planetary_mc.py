"""Monte-Carlo of planetary assembly strategies (Wang et al. 2013 §3.2, Figs 2-5).

Each sample draws error magnitudes [mm] and angles [rad], sums the equivalent mesh-error terms
into phasors and takes the *exact* coupled amplitude ``max_t |Σe(t)|`` over the common period
(compiled kernel :func:`gearte.models.planetary_errors.sample_extremes`). Work is split into
fixed-size chunks, each with its own ``numpy.random.Generator`` spawned from one seed, so the
statistics do not depend on the number of workers.

Scenarios
---------
``random_assembly``
    magnitudes = tolerances, every angle uniform on [0, 2 pi) (Fig 2).
``random_assembly_half_tolerance``
    magnitudes = tolerances / 2, angles uniform (Fig 3).
``allocated_assembly_random_magnitudes``
    magnitudes Rayleigh within the tolerance, angles set by Wang's rule (Table 3) relative to the
    reference, the rule's "arbitrary" angles uniform (Fig 4).
``optimal_assembly_random_magnitudes``
    as above with gearte's global-optimum angles (all free angles set).
``random_magnitudes_random_assembly``
    Rayleigh magnitudes, every angle uniform (Fig 5).

Rayleigh magnitudes: scale sigma = ``rayleigh_sigma_fraction`` × tolerance, truncated at the
tolerance (inverse-CDF sampling of the truncated law, so every sample costs the same draws).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from gearte.errors import ParameterError
from gearte.execution import RunningStats, chunk_sizes, map_chunks, spawn_seeds
from gearte.models.planetary_errors import TermSet, keyed_vector, sample_extremes

__all__ = ["SCENARIOS", "MCResult", "draw_chunk", "run_scenario", "te_upper_bound"]

SCENARIOS: tuple[str, ...] = (
    "random_assembly",
    "random_assembly_half_tolerance",
    "allocated_assembly_random_magnitudes",
    "optimal_assembly_random_magnitudes",
    "random_magnitudes_random_assembly",
)


@dataclass
class MCResult:
    """Statistics of one scenario.

    ``stats`` of the exact amplitude [rad]; ``stats_p2p`` of the peak-to-peak [rad];
    ``hist`` counts on ``edges`` [rad] (fixed a-priori bins on [0, upper bound]).
    """

    scenario: str
    stats: RunningStats
    stats_p2p: RunningStats
    edges: np.ndarray
    hist: np.ndarray
    samples: int
    notes: list[str] = field(default_factory=list)


def te_upper_bound(terms: TermSet, tolerances: np.ndarray) -> float:
    """Σ|gain| × tolerance × |scale| [rad]: no sample of any scenario can exceed it.

    ``terms`` the term set, ``tolerances`` [mm] per magnitude key (``terms.magnitudes`` order).
    """
    idx = [terms.magnitudes.index(t.magnitude) for t in terms.terms]
    return float(sum(abs(t.gain) * tolerances[i] for t, i in zip(terms.terms, idx, strict=True)))


def _rayleigh_truncated(rng: np.random.Generator, sigma: np.ndarray, top: np.ndarray, n: int):
    """Rayleigh(sigma) conditioned on x <= top, by inverse CDF [same unit as sigma]."""
    u = rng.random((n, sigma.size))
    with np.errstate(divide="ignore", invalid="ignore"):
        fmax = -np.expm1(-0.5 * (top / np.where(sigma > 0, sigma, 1.0)) ** 2)
        x = sigma * np.sqrt(-2.0 * np.log1p(-u * fmax))
    return np.where(sigma > 0, x, 0.0)


def draw_chunk(
    terms: TermSet,
    scenario: str,
    tolerances: np.ndarray,
    fixed_angles: np.ndarray,
    fixed_mask: np.ndarray,
    rng: np.random.Generator,
    n: int,
    rayleigh_sigma_fraction: float = 0.5,
) -> tuple[np.ndarray, np.ndarray]:
    """Magnitudes (n, n_mag) [mm] and angles (n, n_ang) [rad] of one chunk of a scenario.

    ``terms`` the term set, ``tolerances`` [mm] per magnitude key (in ``terms.magnitudes``
    order), ``rng`` the chunk's generator, ``n`` samples, ``rayleigh_sigma_fraction`` [-]
    Rayleigh scale / tolerance. ``fixed_angles`` [rad] / ``fixed_mask`` [-] (bool): the
    assembly angles a strategy sets (relative to the reference, which is itself held at 0 in the
    allocated/optimal scenarios).
    """
    na = len(terms.angles)
    if scenario in ("random_assembly", "random_assembly_half_tolerance"):
        f = 0.5 if scenario.endswith("half_tolerance") else 1.0
        mags = np.broadcast_to(tolerances * f, (n, tolerances.size))
        angs = rng.random((n, na)) * (2 * np.pi)
    elif scenario == "random_magnitudes_random_assembly":
        mags = _rayleigh_truncated(rng, tolerances * rayleigh_sigma_fraction, tolerances, n)
        angs = rng.random((n, na)) * (2 * np.pi)
    elif scenario in ("allocated_assembly_random_magnitudes", "optimal_assembly_random_magnitudes"):
        mags = _rayleigh_truncated(rng, tolerances * rayleigh_sigma_fraction, tolerances, n)
        angs = rng.random((n, na)) * (2 * np.pi)
        angs[:, fixed_mask] = fixed_angles[fixed_mask]
    else:
        raise ParameterError("scenario", scenario, f"must be one of {SCENARIOS}")
    return np.ascontiguousarray(mags), np.ascontiguousarray(angs)


def _chunk(task: tuple) -> tuple:
    terms, scenario, tol, fa, fm, seedseq, n, frac, edges = task
    rng = np.random.default_rng(seedseq)
    mags, angs = draw_chunk(terms, scenario, tol, fa, fm, rng, n, frac)
    fmax, fmin = sample_extremes(terms, mags, angs)
    s = abs(terms.scale)
    amp = np.maximum(fmax, -fmin) * s
    p2p = (fmax - fmin) * s
    hist, _ = np.histogram(amp, bins=edges)
    return RunningStats.of(amp), RunningStats.of(p2p), hist


def run_scenario(
    terms: TermSet,
    scenario: str,
    tolerances: Mapping[str, float],
    *,
    samples: int = 50_000,
    seed: int | None = 2013,
    chunk_size: int = 10_000,
    assembly_angles: Mapping[str, float] | None = None,
    rayleigh_sigma_fraction: float = 0.5,
    bins: int = 120,
    workers: int | None = None,
    scheduler: object = None,
    progress: bool = False,
) -> MCResult:
    """Monte-Carlo statistics of the exact coupled amplitude for one assembly scenario.

    Parameters
    ----------
    terms : TermSet
    scenario : str
        One of :data:`SCENARIOS`.
    tolerances : mapping
        Tolerance (maximum magnitude) per magnitude key [mm].
    samples, chunk_size : int
        Sample count and fixed chunk size (results depend on these and ``seed``, never on the
        number of workers).
    seed : int
        Root seed; chunk i uses ``SeedSequence(seed).spawn(n_chunks)[i]``.
    assembly_angles : mapping, optional
        Angles [rad] the strategy sets (allocated/optimal scenarios); others are drawn uniformly.
    rayleigh_sigma_fraction : float
        Rayleigh scale / tolerance [-] (0.5: the tolerance is 2 sigma) in (0, 10].
    bins : int
        Histogram bins on [0, :func:`te_upper_bound`].
    workers, scheduler, progress
        Where the chunks run (:func:`gearte.execution.map_chunks`) and whether to show progress.
    """
    if scenario not in SCENARIOS:
        raise ParameterError("scenario", scenario, f"must be one of {SCENARIOS}")
    if not (0 < rayleigh_sigma_fraction <= 10):
        raise ParameterError(
            "rayleigh_sigma_fraction", rayleigh_sigma_fraction, "must be in (0, 10]"
        )
    if samples < 1:
        raise ParameterError("samples", samples, "must be >= 1")
    tol = keyed_vector(terms.magnitudes, dict(tolerances), "tolerances", required=True)
    fa = np.zeros(len(terms.angles))
    fm = np.zeros(len(terms.angles), dtype=bool)
    if scenario.endswith("_random_magnitudes"):
        if assembly_angles is None:
            raise ParameterError("assembly_angles", None, f"scenario {scenario!r} needs them")
        for i, a in enumerate(terms.angles):
            if a in assembly_angles:
                fa[i] = float(assembly_angles[a])
                fm[i] = True
        if terms.reference_angle is not None:
            i = terms.angles.index(terms.reference_angle)
            fa[i] = float(assembly_angles.get(terms.reference_angle, 0.0))
            fm[i] = True
    upper = te_upper_bound(terms, tol) * abs(terms.scale)
    edges = np.linspace(0.0, upper * (1 + 1e-9), bins + 1)
    sizes = chunk_sizes(samples, chunk_size)
    seeds = spawn_seeds(seed, len(sizes))
    tasks = [
        (terms, scenario, tol, fa, fm, s, n, rayleigh_sigma_fraction, edges)
        for s, n in zip(seeds, sizes, strict=True)
    ]
    parts = map_chunks(
        _chunk,
        tasks,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        description=f"Monte-Carlo {scenario}",
        sizes=sizes,
    )
    st, sp = RunningStats(), RunningStats()
    hist = np.zeros(bins, dtype=np.int64)
    for a, p, h in parts:
        st = st.merge(a)
        sp = sp.merge(p)
        hist += h
    return MCResult(scenario, st, sp, edges, hist, samples)
