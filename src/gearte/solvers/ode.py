"""One interface for time integration: compiled RK4 / DOPRI5 kernels and scipy as reference.

A system is a compiled right-hand side ``rhs(t, y, args, dydt, work)`` (numba ``@njit``), a compiled
scalar output ``output(t, y, args) -> float`` (e.g. the dynamic transmission error) and the
``args`` tuple of arrays, plus plain-Python twins for :func:`scipy.integrate.solve_ivp`.

The kernels run the whole time loop in compiled code without the GIL (``nogil=True``), so threads
run realisations in parallel; they reduce the output to summary statistics (min, max, mean, rms
after a settling time) inside the loop and record only a decimated trace when asked, so a batch
never stores trajectories. Non-finite states are detected in the loop and raised as
:class:`gearte.errors.DivergenceError`; a fixed RK4 step above the stability limit of the
linearised system is refused with the limit in the message.

Caching: the kernels are copies of module-level templates whose globals bind the system's
``rhs``/``output`` (``output`` inlined at its one call site), compiled with ``cache=True`` under a
name that carries a hash of the source files of ``rhs`` and ``output``: editing the model gives a
new cache entry instead of silently reusing a kernel with a stale inlined rhs (numba itself only
checks the kernel's own file). No closures: numba keys cached closures by their pickled cells,
which change every process.
"""

from __future__ import annotations

import hashlib
import inspect
import time
import types
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from gearte._jit import kernel
from gearte.errors import DivergenceError, ParameterError
from gearte.solvers.ode_result import ODEResult

#: Lower estimate of the time of one compiled RK4 step of a 30-DOF system [s], for the time
#: budget (``gearte.limits.check_time``) checked before an integration.
_RK4_STEP_S = 1e-6

__all__ = [
    "ODESystem",
    "ODEResult",
    "integrate",
    "rk4_stability_limit",
    "cached_stability_limit",
    "kernels",
]

_STATS = 5  # count, min, max, sum, sum of squares


@dataclass(frozen=True)
class ODESystem:
    """A first-order system y' = f(t, y) in compiled and plain form.

    Attributes
    ----------
    rhs : numba dispatcher ``rhs(t, y, args, dydt, work)`` writing dy/dt in place; ``work`` is a
        scratch array of ``work_size`` floats owned by one integration (NaN-filled at its start),
        e.g. to reuse time-only quantities between stages; never shared between threads.
    output : numba dispatcher ``output(t, y, args) -> float`` summarised by the kernels.
    args : tuple of arrays passed to both.
    key : str, hash of the rhs source (part of the cache key of the kernels).
    rhs_python : ``f(t, y) -> dydt`` plain twin for solve_ivp (optional).
    output_python : ``g(t, y) -> float`` plain twin (optional; defaults to ``output.py_func``).
    stability_eigenvalues : eigenvalues of the linearised state matrix at its stiffest [1/s]
        (optional); used to refuse RK4 steps above the stability limit.
    work_size : floats of the rhs's scratch array [-].
    stability_limit : the RK4 stability limit of those eigenvalues [s] (optional): computed once
        where the system is built (:func:`rk4_stability_limit`), so the workers of a batch do
        not each compute it again.
    """

    rhs: Any
    output: Any
    args: tuple
    key: str
    rhs_python: Callable[[float, np.ndarray], np.ndarray] | None = None
    output_python: Callable[[float, np.ndarray], float] | None = None
    stability_eigenvalues: np.ndarray | None = field(default=None, repr=False)
    work_size: int = 0
    stability_limit: float | None = None


def _rk4_amp(z: np.ndarray) -> np.ndarray:
    return np.abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24)


def rk4_stability_limit(eigenvalues: np.ndarray) -> float:
    """Largest step h [s] with |R(hλ)| ≤ 1 for every eigenvalue λ [1/s] in ``eigenvalues``
    (classical RK4).

    R(z) = 1 + z + z²/2 + z³/6 + z⁴/24. For each λ the first crossing of |R| = 1 along the ray
    h λ is bracketed on a fine grid and refined by bisection; purely imaginary λ (|R| > 1 for
    small h, a mild instability RK4 shares with every explicit scheme) are bounded at |hλ| = 2√2.
    All eigenvalues at once (one array per grid and bisection step).
    """
    lam = np.asarray(eigenvalues, dtype=complex).ravel()
    lam = lam[np.abs(lam) > 0]
    if lam.size == 0:
        return np.inf
    # |R(conj z)| = |R(z)| (real coefficients): one of each conjugate pair
    lam = np.unique(np.where(lam.imag < 0, np.conj(lam), lam))
    mag = np.abs(lam)
    s = np.linspace(1e-6, 3.5, 3501)[None, :] / mag[:, None]
    bad = _rk4_amp(s * lam[:, None]) > 1.0 + 1e-12
    first = np.argmax(bad, axis=1)
    rows = np.arange(lam.size)
    lo = s[rows, np.maximum(first - 1, 0)]
    hi = s[rows, first]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        over = _rk4_amp(mid * lam) > 1.0 + 1e-12
        hi = np.where(over, mid, hi)
        lo = np.where(over, lo, mid)
    limits = np.where(
        ~bad.any(axis=1),
        3.5 / mag,  # never unstable on the grid
        np.where(first == 0, 2.0 * np.sqrt(2.0) / mag, lo),  # marginal: imaginary-axis bound
    )
    return float(np.min(limits))


# Placeholders of the templates' free names; each specialised kernel rebinds them (_specialise).
rhs: Any = None
output: Any = None


# The helpers have one call site in each template: typed there (inline="always") they cost less
# than kernels of their own, which numba compiles, optimises and links into every caller.
@njit(cache=True, nogil=True, inline="always")
def _stats_update(stats, o):
    stats[0] += 1.0
    if o < stats[1]:
        stats[1] = o
    if o > stats[2]:
        stats[2] = o
    stats[3] += o
    stats[4] += o * o


@njit(cache=True, nogil=True, inline="always")
def _env_update(env, b, o):
    if o < env[b, 0]:
        env[b, 0] = o
    if o > env[b, 1]:
        env[b, 1] = o


def _rk4_template(
    y0, t0, dt, n_steps, args, settle_steps, rec_every, rec_idx, trace, rec, work_size, env
):
    n = y0.size
    work = np.full(work_size, np.nan)
    y = y0.copy()
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    tmp = np.empty(n)
    stats = np.zeros(_STATS)
    stats[1] = np.inf
    stats[2] = -np.inf
    nrec = 0  # samples recorded in all; trace/rec keep their last rows (ring buffers)
    cap_t = trace.shape[0]
    cap = rec.shape[0]
    n_env = env.shape[0]
    n_out = n_steps - settle_steps + 1  # output samples after settling (envelope buckets)
    h2 = 0.5 * dt
    h6 = dt / 6.0
    # s = -1 is the state at t0 (no step): one call site of output, which kernels() inlines
    for s in range(-1, n_steps):
        if s >= 0:
            t = t0 + s * dt
            rhs(t, y, args, k1, work)
            for i in range(n):
                tmp[i] = y[i] + h2 * k1[i]
            rhs(t + h2, tmp, args, k2, work)
            for i in range(n):
                tmp[i] = y[i] + h2 * k2[i]
            rhs(t + h2, tmp, args, k3, work)
            for i in range(n):
                tmp[i] = y[i] + dt * k3[i]
            t_next = t0 + (s + 1) * dt  # bit-identical to the next step's t (rhs may memoise)
            rhs(t_next, tmp, args, k4, work)
            acc = 0.0
            for i in range(n):
                y[i] += h6 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                acc += y[i]
            if not np.isfinite(acc):
                return y, stats, nrec, s + 1
        if s + 1 >= settle_steps:
            o = output(t0 + (s + 1) * dt, y, args)
            _stats_update(stats, o)
            j = s + 1 - settle_steps
            if n_env > 0:
                _env_update(env, (j * n_env) // n_out, o)
            if rec_every > 0 and j % rec_every == 0:
                if cap_t > 0:
                    trace[nrec % cap_t] = o
                if cap > 0:
                    r = nrec % cap
                    for c in range(rec_idx.size):
                        rec[r, c] = y[rec_idx[c]]
                nrec += 1
    return y, stats, nrec, -1


# Dormand–Prince 5(4) tableau
c2, c3, c4, c5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
a21 = 1 / 5
a31, a32 = 3 / 40, 9 / 40
a41, a42, a43 = 44 / 45, -56 / 15, 32 / 9
a51, a52, a53, a54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
a61, a62, a63, a64, a65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
b1, b3, b4, b5, b6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
e1, e3, e4, e5, e6, e7 = (
    71 / 57600,
    -71 / 16695,
    71 / 1920,
    -17253 / 339200,
    22 / 525,
    -1 / 40,
)


def _dopri5_template(
    y0,
    t0,
    t_end,
    h0,
    h_max,
    rtol,
    atol,
    args,
    t_settle,
    rec_dt,
    rec_idx,
    trace,
    rec,
    max_steps,
    work_size,
    env,
    n_out,
):
    n = y0.size
    work = np.full(work_size, np.nan)
    y = y0.copy()
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    k5 = np.empty(n)
    k6 = np.empty(n)
    k7 = np.empty(n)
    yn = np.empty(n)
    tmp = np.empty(n)
    stats = np.zeros(_STATS)
    stats[1] = np.inf
    stats[2] = -np.inf
    counters = np.zeros(3)  # accepted, rejected, rhs evaluations
    t = t0
    h = h0
    rhs(t, y, args, k1, work)
    counters[2] += 1
    next_rec = t_settle
    nrec = 0  # samples on the recording grid so far; trace/rec keep their last rows
    cap_t = trace.shape[0]
    cap = rec.shape[0]
    n_env = env.shape[0]
    while t < t_end:
        if counters[0] + counters[1] >= max_steps:
            return y, stats, nrec, counters, -2
        if t + h > t_end:
            h = t_end - t
        for i in range(n):
            tmp[i] = y[i] + h * a21 * k1[i]
        rhs(t + c2 * h, tmp, args, k2, work)
        for i in range(n):
            tmp[i] = y[i] + h * (a31 * k1[i] + a32 * k2[i])
        rhs(t + c3 * h, tmp, args, k3, work)
        for i in range(n):
            tmp[i] = y[i] + h * (a41 * k1[i] + a42 * k2[i] + a43 * k3[i])
        rhs(t + c4 * h, tmp, args, k4, work)
        for i in range(n):
            tmp[i] = y[i] + h * (a51 * k1[i] + a52 * k2[i] + a53 * k3[i] + a54 * k4[i])
        rhs(t + c5 * h, tmp, args, k5, work)
        for i in range(n):
            tmp[i] = y[i] + h * (
                a61 * k1[i] + a62 * k2[i] + a63 * k3[i] + a64 * k4[i] + a65 * k5[i]
            )
        rhs(t + h, tmp, args, k6, work)
        for i in range(n):
            yn[i] = y[i] + h * (b1 * k1[i] + b3 * k3[i] + b4 * k4[i] + b5 * k5[i] + b6 * k6[i])
        rhs(t + h, yn, args, k7, work)
        counters[2] += 6
        err = 0.0
        for i in range(n):
            ei = h * (e1 * k1[i] + e3 * k3[i] + e4 * k4[i] + e5 * k5[i] + e6 * k6[i] + e7 * k7[i])
            sc = atol[i] + rtol * max(abs(y[i]), abs(yn[i]))
            err += (ei / sc) ** 2
        err = np.sqrt(err / n)
        if not np.isfinite(err):
            if h < 1e-14:
                return y, stats, nrec, counters, 1
            h *= 0.1
            counters[1] += 1
            continue
        if err <= 1.0:
            t_new = t + h
            # record on the uniform grid by cubic Hermite interpolation of the step
            while next_rec <= t_new + 1e-15 and t_new > t:
                th = (next_rec - t) / h
                h00 = 2 * th**3 - 3 * th**2 + 1
                h10 = th**3 - 2 * th**2 + th
                h01 = -2 * th**3 + 3 * th**2
                h11 = th**3 - th**2
                for i in range(n):
                    tmp[i] = h00 * y[i] + h10 * h * k1[i] + h01 * yn[i] + h11 * h * k7[i]
                o = output(next_rec, tmp, args)
                _stats_update(stats, o)
                if n_env > 0:
                    _env_update(env, min((nrec * n_env) // n_out, n_env - 1), o)
                if cap_t > 0:
                    trace[nrec % cap_t] = o
                if cap > 0:
                    r = nrec % cap
                    for c in range(rec_idx.size):
                        rec[r, c] = tmp[rec_idx[c]]
                nrec += 1
                next_rec += rec_dt
            t = t_new
            acc = 0.0
            for i in range(n):
                y[i] = yn[i]
                k1[i] = k7[i]
                acc += y[i]
            if not np.isfinite(acc):
                return y, stats, nrec, counters, 1
            counters[0] += 1
            fac = 0.9 * err ** (-0.2) if err > 0 else 5.0
            h = h * min(5.0, max(0.2, fac))
        else:
            counters[1] += 1
            h = h * max(0.2, 0.9 * err ** (-0.2))
        if h > h_max:
            h = h_max
    return y, stats, nrec, counters, -1


def _specialise(template, rhs, output, key: str, name: str):
    """A copy of ``template`` whose globals bind ``rhs``/``output``, compiled with cache=True.

    numba files a cached function under its module and ``__qualname__`` and checks the source
    file's time stamp; the qualname carries ``key`` (a hash of the files defining rhs and output),
    so a changed model gets a new cache entry instead of a stale kernel with the old rhs inlined.
    """
    g = dict(template.__globals__)
    g["rhs"] = rhs
    g["output"] = _inline_twin(output)
    fn = types.FunctionType(template.__code__, g, f"{name}_{key}", template.__defaults__, None)
    fn.__qualname__ = f"{name}_{key}"
    fn.__module__ = template.__module__
    return kernel(fn)


def _source_key(*funcs) -> str:
    h = hashlib.sha256()
    for f in funcs:
        py = getattr(f, "py_func", f)
        h.update(py.__module__.encode())
        h.update(py.__qualname__.encode())
        h.update(Path(inspect.getsourcefile(py) or "").read_bytes())
    return h.hexdigest()[:16]


@lru_cache(maxsize=16)
def _inline_twin(fn):
    """``fn`` (a numba dispatcher, e.g. the system's output) as a kernel numba writes into its
    caller (``inline="always"``): the templates call the output at one site, and a small function
    typed there costs less than a kernel of its own (numba compiles, optimises and links a callee
    separately, about 0.1–0.2 s on a cold cache; docs/numba.md). Not cached on its own: nothing
    calls it from Python."""
    return njit(inline="always", nogil=True)(fn.py_func)


@lru_cache(maxsize=16)
def kernels(rhs, output, key: str = ""):
    """Compiled (RK4, DOPRI5) kernels specialised on ``rhs``/``output`` (cached on disk).

    The cache key combines ``key`` with a hash of the source files of ``rhs`` and ``output``.
    """
    k = hashlib.sha256((key + _source_key(rhs, output)).encode()).hexdigest()[:16]
    return (
        _specialise(_rk4_template, rhs, output, k, "rk4"),
        _specialise(_dopri5_template, rhs, output, k, "dopri5"),
    )


_LIMITS: dict[int, tuple[Any, float]] = {}


def cached_stability_limit(eigenvalues: np.ndarray) -> float:
    """:func:`rk4_stability_limit` [s] of ``eigenvalues`` [1/s], computed once per array object
    (a model that hands back the same eigenvalue array gets its limit without recomputing)."""
    hit = _LIMITS.get(id(eigenvalues))
    if hit is not None and hit[0] is eigenvalues:
        return hit[1]
    lim = rk4_stability_limit(eigenvalues)
    if len(_LIMITS) > 64:
        _LIMITS.clear()
    _LIMITS[id(eigenvalues)] = (eigenvalues, lim)
    return lim


def _cached_limit(system: ODESystem) -> float:
    """RK4 stability limit of a system: its own, or computed once per eigenvalue array."""
    if system.stability_limit is not None:
        return system.stability_limit
    ev = system.stability_eigenvalues
    if ev is None:
        raise ParameterError("stability_eigenvalues", None, "needed for the RK4 stability limit")
    return cached_stability_limit(ev)


def _finish_stats(stats: np.ndarray) -> dict[str, float]:
    cnt = stats[0]
    if cnt == 0:
        raise ParameterError("t_settle", None, "no output sample after the settling time")
    mean = stats[3] / cnt
    return {
        "min": float(stats[1]),
        "max": float(stats[2]),
        "mean": float(mean),
        "rms": float(np.sqrt(max(stats[4] / cnt, 0.0))),
        "peak_to_peak": float(stats[2] - stats[1]),
        "count": float(cnt),
    }


def _ring_order(rec: np.ndarray, nrec: int) -> np.ndarray:
    """Copy of the rows of a ring buffer ``rec`` that received ``nrec`` rows, oldest first."""
    cap = rec.shape[0]
    if nrec <= cap or cap == 0:
        return rec[: min(nrec, cap)].copy()
    k = nrec % cap
    return np.concatenate([rec[k:], rec[:k]])


def _new_envelope(n_env: int) -> np.ndarray:
    env = np.empty((n_env, 2))
    env[:, 0] = np.inf
    env[:, 1] = -np.inf
    return env


def check_rk4_steps(dt: float, span_s: float) -> None:
    """Refuse an RK4 integration of ``span_s`` [s] in steps of ``dt`` [s] whose step count
    (at :data:`_RK4_STEP_S` a step, a lower estimate) is over the time budget
    (``GEARTE_MAX_SECONDS``, :func:`gearte.limits.check_time`). Called by :func:`integrate`
    before any step and by the studies' pre-flight (``gearte validate``) before any analysis.

    Raises
    ------
    ParameterError
        Naming ``dt``, the step count and ``GEARTE_MAX_SECONDS``.
    """
    from gearte.limits import check_time

    # found by fuzzing: a stiff model's tiny step made ~1e150 steps, an integer the compiled
    # kernel cannot take, or a run of hours
    steps = span_s / dt
    check_time(
        "dt",
        dt,
        steps * _RK4_STEP_S,
        f"an RK4 integration of {steps:.3g} steps of {dt:.3g} s over {span_s:g} s (a stiff "
        "model: check its masses, inertias and stiffnesses)",
    )


def check_span(t_span: tuple[float, float], t_settle: float) -> None:
    """Refuse a time span [s] that :func:`integrate` cannot summarise: its end not after its
    start, or a settling time ``t_settle`` [s] outside ``[0, t1 - t0)`` (no output after
    settling; also a span whose length is lost beside ``t_settle`` in double precision). Called
    by :func:`integrate` and by the studies' pre-flight (``gearte validate``).

    Raises
    ------
    ParameterError
        Naming ``t_span`` or ``t_settle``.
    """
    t0, t1 = float(t_span[0]), float(t_span[1])
    if not t1 > t0:
        raise ParameterError("t_span", t_span, "end must be after start")
    if not 0.0 <= t_settle < t1 - t0:
        raise ParameterError("t_settle", t_settle, f"must be in [0, {t1 - t0:g}) s")


def integrate(
    system: ODESystem,
    y0: np.ndarray,
    t_span: tuple[float, float],
    *,
    method: str = "rk4",
    dt: float | None = None,
    rtol: float = 1e-7,
    atol: float | np.ndarray = 1e-12,
    t_settle: float = 0.0,
    record_dt: float | None = None,
    record_states: np.ndarray | list[int] | None = None,
    record_window: int | None = None,
    output_window: int | None = None,
    envelope_points: int = 0,
    max_records: int = 2_000_000,
    max_steps: int = 50_000_000,
    args: tuple | None = None,
) -> ODEResult:
    """Integrate ``system`` from ``y0`` over ``t_span`` [s].

    Parameters
    ----------
    method : "rk4" (compiled fixed step ``dt``), "dopri5" (compiled adaptive, ``rtol``/``atol``)
        or "scipy" (:func:`scipy.integrate.solve_ivp` RK45 on the plain twin, the reference).
    dt : float
        RK4 step [s]; refused above the stability limit when the system gives its eigenvalues.
        For DOPRI5 the initial step.
    t_settle : float
        Time [s] after t_span[0] before the output is summarised and recorded.
    record_dt : float, optional
        Recording interval [s] (a multiple of dt for RK4); ``None`` records nothing.
    record_states : sequence of int, optional
        Indices of state components recorded beside the output [-].
    record_window : int, optional
        Most recorded rows kept [-]: the kernel writes rows into a ring buffer of this many and
        the result holds the *last* ones (memory independent of the span). ``None`` keeps every
        row of the span.
    output_window : int, optional
        The same for the recorded output alone (``t``, ``output``; one float a row, so it can
        reach further back than the states); default ``record_window``.
    envelope_points : int
        Buckets [-] of the output's min/max envelope over the span after settling, updated at
        every RK4 step (DOPRI5, scipy: every recorded sample); 0 for none. Capped at the
        number of output samples.
    max_records : int
        Most recorded rows allowed [-] (memory bound; a longer record is an error: ask for a
        ``record_window`` or a longer ``record_dt``).
    max_steps : int
        Most DOPRI5 steps before giving up (stiff or diverging system).
    args : tuple, optional
        Replaces ``system.args`` (e.g. another error realisation) without recompiling.

    Raises
    ------
    ParameterError
        Bad method, step above the stability limit, inconsistent times, a record longer than
        ``max_records``.
    DivergenceError
        A non-finite state (the result is never returned).

    Notes
    -----
    The statistics (min, max, mean, rms) come from the output at every RK4 step after settling
    (DOPRI5, scipy: at every recording instant), whatever is recorded; so do the envelope's
    buckets. Only the recorded rows are bounded by ``record_window``.
    """
    t0, t1 = float(t_span[0]), float(t_span[1])
    check_span((t0, t1), t_settle)
    if record_window is not None and record_window < 1:
        raise ParameterError("record_window", record_window, "must be ≥ 1 row (or None: all)")
    if output_window is not None and output_window < 1:
        raise ParameterError("output_window", output_window, "must be ≥ 1 row (or None: all)")
    out_window = record_window if output_window is None else output_window
    if envelope_points < 0:
        raise ParameterError("envelope_points", envelope_points, "must be ≥ 0")
    y0 = np.ascontiguousarray(y0, dtype=float)
    if not np.all(np.isfinite(y0)):
        raise ParameterError("y0", "non-finite", "initial state must be finite")
    a = system.args if args is None else args
    idx = np.asarray([] if record_states is None else record_states, dtype=np.int64)

    def rows(needed: int, window: int | None) -> int:
        cap = needed if window is None else min(needed, window)
        if cap > max_records:
            raise ParameterError(
                "record_dt",
                record_dt,
                f"records {needed} rows over the span, more than max_records = {max_records}; "
                "give a record_window (the last rows) or a longer recording interval",
            )
        return cap

    t_start = time.perf_counter()
    if method == "rk4":
        if dt is None or not dt > 0:
            raise ParameterError("dt", dt, "RK4 needs a step > 0 s")
        if system.stability_eigenvalues is not None or system.stability_limit is not None:
            lim = _cached_limit(system)
            if dt > lim:
                big = (
                    f" (largest |λ| = {np.max(np.abs(system.stability_eigenvalues)):.4g} 1/s)"
                    if system.stability_eigenvalues is not None
                    else ""
                )
                raise ParameterError(
                    "dt",
                    dt,
                    f"above the RK4 stability limit {lim:.4g} s of this system{big}; use dt ≤ "
                    f"{lim:.4g} s",
                )
        # end exactly at t1: the step is shortened (never lengthened) to fit the span
        steps = (t1 - t0) / dt
        check_rk4_steps(dt, t1 - t0)
        n_steps = max(1, int(np.ceil(steps - 1e-9)))
        dt = (t1 - t0) / n_steps
        settle_steps = int(round(t_settle / dt))
        n_out = n_steps - settle_steps + 1
        if record_dt is None:
            rec_every, n_trace, n_rec = 0, 0, 0
        else:
            rec_every = max(1, int(round(record_dt / dt)))
            needed = (n_steps - settle_steps) // rec_every + 1
            n_trace = rows(needed, out_window)
            n_rec = rows(needed, record_window) if idx.size else 0
        trace = np.zeros(n_trace)
        rec = np.zeros((n_rec, idx.size))
        env = _new_envelope(min(envelope_points, n_out))
        rk4, _ = kernels(system.rhs, system.output, system.key)
        y, stats, nrec, status = rk4(
            y0, t0, dt, n_steps, a, settle_steps, rec_every, idx, trace, rec, system.work_size, env
        )
        if status >= 0:
            raise DivergenceError(
                f"RK4 diverged: non-finite state at t = {t0 + status * dt:.6g} s "
                f"(step {status} of {n_steps}, dt = {dt:.3g} s)"
            )
        records = int(nrec)

        def times(n: int) -> np.ndarray:
            return t0 + (settle_steps + rec_every * np.arange(max(0, nrec - n), nrec)) * dt

        per = n_out / max(env.shape[0], 1)  # output samples per envelope bucket
        env_t = t0 + (settle_steps + (np.arange(env.shape[0]) + 0.5) * per - 0.5) * dt
        n_rhs = 4 * n_steps
        steps = n_steps
    elif method == "dopri5":
        h0 = dt if dt is not None else 1e-6
        rec_dt = record_dt if record_dt is not None else (t1 - t0) / 10000
        n_out = int((t1 - t0 - t_settle) / rec_dt) + 1
        n_trace = 0 if record_dt is None else rows(n_out + 1, out_window)
        n_rec = 0 if record_dt is None or not idx.size else rows(n_out + 1, record_window)
        trace = np.zeros(n_trace)
        rec = np.zeros((n_rec, idx.size))
        env = _new_envelope(min(envelope_points, n_out))
        atol_arr = np.broadcast_to(np.asarray(atol, dtype=float), y0.shape).copy()
        _, dp = kernels(system.rhs, system.output, system.key)
        y, stats, nrec, counters, status = dp(
            y0,
            t0,
            t1,
            h0,
            t1 - t0,
            rtol,
            atol_arr,
            a,
            t0 + t_settle,
            rec_dt,
            idx,
            trace,
            rec,
            max_steps,
            system.work_size,
            env,
            n_out,
        )
        if status == 1:
            raise DivergenceError("DOPRI5 diverged: non-finite state or error estimate")
        if status == -2:
            raise DivergenceError(f"DOPRI5 exceeded {max_steps} steps (stiff or diverging)")
        if record_dt is None:
            nrec = 0
        records = int(nrec)

        def times(n: int) -> np.ndarray:
            return t0 + t_settle + rec_dt * np.arange(max(0, nrec - n), nrec)

        per = n_out / max(env.shape[0], 1)
        env_t = t0 + t_settle + ((np.arange(env.shape[0]) + 0.5) * per - 0.5) * rec_dt
        n_rhs = int(counters[2])
        steps = int(counters[0])
    elif method == "scipy":
        from scipy.integrate import solve_ivp

        if system.rhs_python is None:
            raise ParameterError("method", method, "the system has no plain-Python rhs")
        rec_dt = record_dt if record_dt is not None else dt if dt is not None else 1e-4
        t_eval = t0 + t_settle + rec_dt * np.arange(int(round((t1 - t0 - t_settle) / rec_dt)) + 1)
        t_eval = t_eval[t_eval <= t1 + 1e-12]
        t_eval[-1] = min(t_eval[-1], t1)
        sol = solve_ivp(
            system.rhs_python, (t0, t1), y0, method="RK45", t_eval=t_eval, rtol=rtol, atol=atol
        )
        if not sol.success or not np.all(np.isfinite(sol.y)):
            raise DivergenceError(f"solve_ivp failed or diverged: {sol.message}")
        out_fn = system.output_python or (lambda t, yy: system.output.py_func(t, yy, a))
        outs = np.array([out_fn(tt, sol.y[:, c]) for c, tt in enumerate(sol.t)])
        stats = np.array([outs.size, outs.min(), outs.max(), outs.sum(), np.sum(outs**2)])
        y = sol.y[:, -1]
        n_env = min(envelope_points, outs.size)
        env = _new_envelope(n_env)
        if n_env:
            b = (np.arange(outs.size) * n_env) // outs.size
            np.minimum.at(env[:, 0], b, outs)
            np.maximum.at(env[:, 1], b, outs)
        per = outs.size / max(n_env, 1)
        env_t = np.interp((np.arange(n_env) + 0.5) * per - 0.5, np.arange(outs.size), sol.t)
        records = outs.size
        n_trace = records if out_window is None else min(records, out_window)
        n_rec = records if record_window is None else min(records, record_window)
        trace = outs[records - n_trace :]
        rec = np.zeros((n_rec, idx.size))
        for c, i in enumerate(idx):
            rec[:, c] = sol.y[i, records - n_rec :]
        t_all = sol.t

        def times(n: int) -> np.ndarray:
            return t_all[t_all.size - n :] if n else t_all[:0]

        nrec = records
        n_rhs = int(sol.nfev)
        steps = int(sol.t.size)
    else:
        raise ParameterError("method", method, "must be 'rk4', 'dopri5' or 'scipy'")
    wall = time.perf_counter() - t_start
    st = _finish_stats(np.asarray(stats))
    if not np.all(np.isfinite(list(st.values()))):
        raise DivergenceError(f"{method}: non-finite output statistics")
    if method == "scipy":
        output_rows, state_rows = trace.copy(), rec.copy()
    else:
        output_rows, state_rows = _ring_order(trace, nrec), _ring_order(rec, nrec)
    del rec, trace
    if idx.size == 0:  # no states: as many empty rows as the output has
        state_rows = np.zeros((output_rows.size, 0))
    return ODEResult(
        method=method,
        t=times(output_rows.size),
        output=output_rows,
        states=state_rows,
        states_t=times(state_rows.shape[0]),
        y_final=np.asarray(y).copy(),
        stats=st,
        n_steps=steps,
        n_rhs=n_rhs,
        wall_time=wall,
        records=records,
        envelope=env,
        envelope_t=env_t,
    )
