"""Running the lumped RV model: DTE time history, spectrum with labelled peaks, error batches.

Composes :mod:`gearte.models.rv_dynamics` (the model) with :mod:`gearte.solvers.ode` (the
integrators) and :mod:`gearte.execution` (parallel chunks); no physics here.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import partial

import numpy as np

from gearte.errors import ParameterError
from gearte.models.orders import label_frequency
from gearte.models.rv_dynamics import (
    RHS_SOURCE_KEY,
    RHS_WORK_SIZE,
    RVDynamicModel,
    RVErrors,
    rv_dte,
    rv_rhs,
)
from gearte.runners.rv_records import DTEResult
from gearte.solvers.ode import ODESystem, cached_stability_limit, integrate
from gearte.units import ARCSEC_PER_RAD

__all__ = [
    "ode_system",
    "DTEResult",
    "simulate_dte",
    "dte_spectrum",
    "label_frequency",
    "ErrorTolerances",
    "draw_errors",
    "dte_batch",
    "default_step",
    "RECORD_POINTS",
    "TRACE_POINTS",
    "ENVELOPE_POINTS",
]


def _dte_python(t: float, y: np.ndarray, n_dof: int, ratio: float) -> float:
    """Plain twin of :func:`rv_dte` [rad] (module level, so the system pickles)."""
    return float(y[n_dof - 1] - y[2] / ratio)


def ode_system(model: RVDynamicModel, errors: RVErrors | None = None) -> ODESystem:
    """The model as a :class:`gearte.solvers.ode.ODESystem` with DTE [rad] as output.

    Compiled right-hand side :func:`~gearte.models.rv_dynamics.rhs.rv_rhs` with its plain twin
    :meth:`RVDynamicModel.rhs_numpy`; ``errors`` [mm, rad] replace the model's errors.
    Everything in it pickles (no local closures), so it crosses process boundaries
    (``--scheduler processes``, Dask workers). The RK4 stability limit is computed here, once,
    and travels with the system.
    """
    args = model.kernel_args(errors)
    m = model if errors is None else model.with_errors(errors)
    eig = model.damped_eigenvalues(mesh="max")
    return ODESystem(
        rhs=rv_rhs,
        output=rv_dte,
        args=args,
        key=RHS_SOURCE_KEY,
        rhs_python=m.rhs_numpy,
        output_python=partial(_dte_python, n_dof=m.n_dof, ratio=m.params.ratio),
        stability_eigenvalues=eig,
        work_size=RHS_WORK_SIZE,
        stability_limit=cached_stability_limit(eig),
    )


#: Rows of recorded states kept by default (the last ones): one output revolution of the
#: Li 2023 reducer at 1500 rpm (4.84 s) at the default 1e-4 s interval fits (46 670 rows).
RECORD_POINTS = 65536
#: Samples of the recorded DTE trace kept by default (the last ones; the spectrum's window):
#: 27 s at the default 1e-4 s interval, 2 MB.
TRACE_POINTS = 262144
#: Buckets of the full-rate DTE envelope (min/max) over the whole span.
ENVELOPE_POINTS = 4096


def default_step(model: RVDynamicModel, fraction: float = 0.85) -> float:
    """RK4 step [s] for ``model``: ``fraction`` [-] of the stability limit at the stiffest mesh
    state."""
    if not 0 < fraction <= 1:
        raise ParameterError("fraction", fraction, "must be in (0, 1]")
    return fraction * cached_stability_limit(model.damped_eigenvalues(mesh="max"))


def simulate_dte(
    model: RVDynamicModel,
    duration_s: float,
    *,
    settle_s: float = 0.1,
    method: str = "rk4",
    dt: float | None = None,
    record_dt: float | None = 1e-4,
    record_bodies: tuple[str, ...] = ("sun", "planet1", "disc1", "output"),
    record_points: int | None = RECORD_POINTS,
    trace_points: int | None = TRACE_POINTS,
    envelope_points: int = ENVELOPE_POINTS,
    rtol: float = 1e-8,
    atol: float = 1e-12,
) -> DTEResult:
    """Integrate ``model`` from static equilibrium at t = 0 and return the DTE after ``settle_s``.

    The DTE is θ_o − θ_s / i (absolute rotations, so the nominal motion cancels) in arcsec.
    Recorded states: x, y, θ and their rates of each body in ``record_bodies`` (trajectories and
    phase portraits, paper Fig 10).

    Parameters
    ----------
    model : RVDynamicModel
    duration_s : float
        Span recorded after settling [s].
    settle_s : float
        Span discarded first [s] (transient from the static equilibrium).
    method : str
        ``"rk4"`` (fixed step), ``"dopri5"`` (adaptive) or ``"scipy"`` (solve_ivp, plain twin).
    dt : float, optional
        RK4 step [s]; default :func:`default_step`.
    record_dt : float, optional
        Recording interval [s] (rounded to a multiple of the RK4 step); None records nothing.
        The RK4 step itself records at the full rate.
    record_bodies : tuple of str
        Bodies whose states are recorded.
    record_points : int, optional
        Most rows of recorded states kept [-]: a longer span keeps its last ``record_points``
        rows, so memory does not grow with ``duration_s``; ``None`` keeps every row (memory
        grows with the duration: the full-rate option, with ``record_dt`` = ``dt``).
    trace_points : int, optional
        The same for the recorded DTE trace [-] (the spectrum's window); ``None``: every sample.
    envelope_points : int
        Buckets [-] of the DTE's min/max envelope over the whole span, from every step.
    rtol, atol : float
        Tolerances [-] of the adaptive methods (relative; absolute in the states' units).

    Notes
    -----
    Peak-to-peak, RMS and mean are reduced inside the time loop from every step after settling
    (every recording instant for DOPRI5 and scipy), not from the recorded trace.
    """
    if not duration_s > 0:
        raise ParameterError("duration_s", duration_s, "must be > 0")
    if record_points is not None and record_points < 8:
        raise ParameterError("record_points", record_points, "must be ≥ 8 (or None: all rows)")
    if trace_points is not None and trace_points < 8:
        raise ParameterError("trace_points", trace_points, "must be ≥ 8 (or None: all samples)")
    system = ode_system(model)
    q0 = model.static_equilibrium(0.0)
    y0 = np.concatenate([q0, np.zeros_like(q0)])
    idx, names = [], []
    for b in record_bodies:
        i0 = model.body(b)
        for c, lab in enumerate(("x", "y", "theta")):
            idx.append(i0 + c)
            names.append(f"{b}.{lab}")
        for c, lab in enumerate(("vx", "vy", "omega")):
            idx.append(model.n_dof + i0 + c)
            names.append(f"{b}.{lab}")
    if method == "rk4" and dt is None:
        dt = default_step(model)
    if method == "rk4" and record_dt is not None and dt is not None:
        record_dt = max(1, round(record_dt / dt)) * dt
    res = integrate(
        system,
        y0,
        (0.0, settle_s + duration_s),
        method=method,
        dt=dt,
        t_settle=settle_s,
        record_dt=record_dt,
        record_states=idx,
        record_window=record_points,
        output_window=trace_points,
        envelope_points=envelope_points,
        rtol=rtol,
        atol=atol,
    )
    mean = res.stats["mean"] * ARCSEC_PER_RAD
    rec_dt = float(np.mean(np.diff(res.t))) if res.t.size > 1 else float(record_dt or np.nan)
    return DTEResult(
        t=res.t,
        dte=res.output * ARCSEC_PER_RAD - mean,
        dte_mean=mean,
        peak_to_peak=res.stats["peak_to_peak"] * ARCSEC_PER_RAD,
        rms=float(np.sqrt(max(res.stats["rms"] ** 2 - res.stats["mean"] ** 2, 0.0)))
        * ARCSEC_PER_RAD,
        states=res.states,
        state_names=names,
        solver=res,
        dt=float(dt) if dt is not None else float("nan"),
        record_dt=rec_dt,
        covers_span=res.records == res.t.size,
        states_t=res.states_t,
        envelope_t=res.envelope_t,
        envelope=res.envelope * ARCSEC_PER_RAD - mean,
    )


def dte_spectrum(
    t: np.ndarray, dte: np.ndarray, sources: dict[str, float], n_peaks: int = 8
) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """Amplitude spectrum [arcsec] of a uniformly sampled DTE and its labelled peaks.

    ``t`` [s] sample times, ``dte`` [arcsec] the samples, ``sources`` name → frequency [Hz] for
    the labels, ``n_peaks`` [-] peaks kept.

    Hann window, amplitude-corrected; peaks are the ``n_peaks`` largest local maxima above
    0.1 % of the largest, labelled by :func:`label_frequency` within 1.5 frequency bins (at
    least 1 Hz).
    """
    n = dte.size
    if n < 8:
        raise ParameterError("dte", n, "needs at least 8 samples for a spectrum")
    dt = float(np.mean(np.diff(t)))
    w = np.hanning(n)
    spec = np.abs(np.fft.rfft((dte - dte.mean()) * w)) * 2.0 / np.sum(w)
    freq = np.fft.rfftfreq(n, dt)
    df = freq[1]
    inner = (spec[1:-1] > spec[:-2]) & (spec[1:-1] >= spec[2:])
    cand = np.nonzero(inner)[0] + 1
    cand = cand[spec[cand] >= 1e-3 * spec[1:].max()] if cand.size else cand
    cand = cand[np.argsort(spec[cand])[::-1]][:n_peaks]
    peaks = [
        {
            "frequency [Hz]": float(freq[c]),
            "amplitude [arcsec]": float(spec[c]),
            "source": label_frequency(float(freq[c]), sources, max(1.5 * df, 1.0)),
        }
        for c in cand
    ]
    return freq, spec, peaks


# --- error batches -------------------------------------------------------------------------------
@dataclass(frozen=True)
class ErrorTolerances:
    """Tolerances [mm] of the Table 3 errors: each realisation draws every part's amplitude
    uniformly in [0, tolerance] and its phase uniformly in [0, 2π), independently per crank/disc.
    """

    sun_eccentricity: float
    planet_eccentricity: float
    sun_assembly: float
    disc_hole: float
    cam: float
    carrier_hole: float
    output_assembly: float


def draw_errors(
    rng: np.random.Generator, tol: ErrorTolerances, crank_count: int, disc_count: int, **cl
) -> RVErrors:
    """One random realisation of the errors (amplitude U(0, tol), phase U(0, 2π)).

    Parameters
    ----------
    rng : numpy.random.Generator
        The random stream.
    tol : ErrorTolerances
        Amplitude tolerances [mm].
    crank_count : int
        Number of cranks [-].
    disc_count : int
        Number of discs [-].
    **cl
        Clearances [mm] passed on to :class:`RVErrors`.

    Returns
    -------
    RVErrors
        One realisation.
    """
    m, n = crank_count, disc_count

    def pair(t, shape=()):
        return np.stack([rng.uniform(0, t, shape), rng.uniform(0, 2 * np.pi, shape)], axis=-1)

    return RVErrors(
        crank_count=m,
        disc_count=n,
        sun_eccentricity=tuple(pair(tol.sun_eccentricity)),
        planet_eccentricity=pair(tol.planet_eccentricity, (m,)),
        sun_assembly=tuple(pair(tol.sun_assembly)),
        disc_hole=pair(tol.disc_hole, (m, n)),
        cam=pair(tol.cam, (m, n)),
        carrier_hole=pair(tol.carrier_hole, (m,)),
        output_assembly=tuple(pair(tol.output_assembly)),
        **cl,
    )


def _batch_chunk(task, shared) -> np.ndarray:
    """Run one chunk of realisations; returns rows (p2p [arcsec], rms [arcsec], mean [arcsec]).

    ``task`` is ``(n, rng)``; ``shared`` holds what every chunk needs (model, compiled system,
    tolerances, spans, step, clearances), sent once per Dask worker rather than with each chunk.
    """
    n, rng = task
    model, system, tol, duration, settle, dt, clearances = shared
    out = np.empty((n, 3))
    for k in range(n):
        err = draw_errors(rng, tol, model.params.crank_count, model.params.disc_count, **clearances)
        m = model.with_errors(err)
        args = m.kernel_args()  # packed once: the equilibrium's residual and the integration
        q0 = m.static_equilibrium(0.0, args=args)
        y0 = np.concatenate([q0, np.zeros_like(q0)])
        r = integrate(
            system, y0, (0.0, settle + duration), method="rk4", dt=dt, t_settle=settle, args=args
        )
        s = r.stats
        out[k] = (
            s["peak_to_peak"] * ARCSEC_PER_RAD,
            np.sqrt(max(s["rms"] ** 2 - s["mean"] ** 2, 0.0)) * ARCSEC_PER_RAD,
            s["mean"] * ARCSEC_PER_RAD,
        )
    return out


def dte_batch(
    model: RVDynamicModel,
    samples: int,
    *,
    tolerances: ErrorTolerances | None = None,
    seed: int | None = 0,
    duration_s: float = 0.5,
    settle_s: float = 0.1,
    dt: float | None = None,
    chunk_size: int = 1,
    workers: int | None = None,
    scheduler=None,
    progress: bool = False,
    clearances: dict | None = None,
) -> dict:
    """DTE statistics over random error realisations, in parallel chunks.

    Chunks of ``chunk_size`` realisations each get their own generator from
    ``gearte.execution.spawn_generators(seed, n_chunks)``, so the result does not depend on the
    worker count. A run takes seconds, so the default is one realisation per chunk: any batch
    of >= 2 runs keeps every worker busy (with 4 per chunk, a batch of 2 ran on one worker).
    The kernel reduces each run to (p2p, rms, mean) inside the time loop; nothing else is
    stored. Returns the per-realisation rows and their summary.

    Parameters
    ----------
    model : RVDynamicModel
        The compiled dynamic model.
    samples : int
        Number of error realisations [-].
    tolerances : ErrorTolerances, optional
        Amplitude tolerances [mm]; required unless the model's own.
    seed : int, optional
        Seed of the chunks' generators.
    duration_s : float
        Simulated time per realisation after settling [s].
    settle_s : float
        Settling time before the DTE is summarised [s].
    dt : float, optional
        RK4 step [s]; default the model's.
    chunk_size : int
        Realisations per chunk [-] (default 1; results depend on it and ``seed`` only).
    workers : int, optional
        Parallel workers.
    scheduler : optional
        Execution backend (:func:`gearte.execution.open_executor`).
    progress : bool
        Show a progress bar.
    clearances : dict, optional
        Bearing clearances [mm] of every realisation.

    Returns
    -------
    dict
        ``rows`` (p2p, rms, mean DTE [arcsec] per realisation) and the summary
        statistics of the p2p.
    """
    from gearte.execution import chunk_sizes, map_chunks, spawn_generators

    if samples < 1:
        raise ParameterError("samples", samples, "must be ≥ 1")
    if tolerances is None:
        raise ParameterError(
            "tolerances", None, "give the error tolerances (ErrorTolerances) of the batch"
        )
    tol = tolerances
    dt = default_step(model) if dt is None else dt
    sizes = chunk_sizes(samples, chunk_size)
    gens = spawn_generators(seed, len(sizes))
    cl = clearances or {}
    system = ode_system(model)  # one system (and stability limit) shared by every chunk
    tasks = list(zip(sizes, gens, strict=True))
    shared = (model, system, tol, duration_s, settle_s, dt, cl)

    t0 = time.perf_counter()
    rows = np.concatenate(
        map_chunks(
            _batch_chunk,
            tasks,
            workers=workers,
            scheduler=scheduler,
            progress=progress,
            description="DTE realisations",
            shared=shared,
            sizes=sizes,
        )
    )
    wall = time.perf_counter() - t0
    p2p = rows[:, 0]
    return {
        "rows": rows,
        "peak_to_peak_mean": float(p2p.mean()),
        "peak_to_peak_sd": float(p2p.std(ddof=1)) if p2p.size > 1 else float("nan"),
        "peak_to_peak_min": float(p2p.min()),
        "peak_to_peak_max": float(p2p.max()),
        "peak_to_peak_p95": float(np.percentile(p2p, 95)),
        "wall_s": wall,
        "simulated_s": samples * (duration_s + settle_s),
        "dt": dt,
    }
