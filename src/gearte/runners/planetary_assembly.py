"""Assembly phases of a planetary that minimise the coupled transmission error.

Two solvers on a :class:`gearte.models.planetary_errors.TermSet`:

* :func:`paper_rule_assembly` — Wang et al. 2013 §1 and §3.1: a zero-frequency group is cancelled
  (its angle turned so that the constant vanishes); in each same-frequency group every free
  "unit" (the terms sharing one assembly angle) is turned parallel (lambda = +1) or antiparallel
  (lambda = -1) to the group's fixed part, with the signs minimising ``|Σ lambda_i A_i|`` (eq 6);
  groups without a fixed part and different-frequency couplings are left "arbitrary".
* :func:`optimal_assembly` — the global minimum of the *exact* coupled amplitude
  ``max_t |Σe(t)|`` over every free angle: a batch of quasi-random (Halton) starts evaluated with
  the compiled exact kernel, then Nelder–Mead from the best starts. The Nelder–Mead runs compiled
  (:func:`gearte.models.planetary_errors.minimize_amplitude`: :mod:`gearte.solvers.nelder_mead`,
  a line-by-line port of SciPy 1.17's ``_minimize_neldermead`` with ``adaptive=True`` and no
  bounds, in the same kernel as the compiled amplitude); its plain twin is
  SciPy's ``minimize(method="Nelder-Mead")`` on the same objective
  (:func:`_polish_scipy`, used by the tests and ``benchmarks/bench_planetary_assembly.py``).

Units: magnitudes [mm], angles [rad].
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gearte.errors import ParameterError
from gearte.models.planetary_terms import TermSet

# The models (numba kernels) are imported where they are used: the report process unpickles an
# AssemblyPlan without importing numba (docs/report.md).

__all__ = [
    "AssemblyPlan",
    "halton_starts",
    "paper_rule_assembly",
    "optimal_assembly",
    "relevant_angles",
]


@dataclass(frozen=True)
class AssemblyPlan:
    """Angles of an assembly and its coupled TE.

    Attributes
    ----------
    angles : dict
        Angle per key [rad], in [0, 2 pi), relative to the reference angle (held at 0).
    set_by_rule : tuple of str
        Angles the method fixes; the others are "arbitrary" (kept at their given value).
    amplitude : float
        Exact coupled amplitude max |Σe| times |scale| [rad] at ``angles``.
    amplitude_sum : float
        Wang 2013's own measure ``|c| + Σ_g |Z_g|`` times |scale| [rad] at ``angles``.
    peak_to_peak : float
        [rad].
    """

    angles: dict[str, float]
    set_by_rule: tuple[str, ...]
    amplitude: float
    amplitude_sum: float
    peak_to_peak: float


def relevant_angles(terms: TermSet, magnitudes: Mapping[str, float]) -> tuple[str, ...]:
    """Free angles of ``terms`` that act on at least one term of non-zero amplitude, given the
    ``magnitudes`` [mm] per magnitude key."""
    out = []
    for a in terms.free_angles:
        if any(
            t.angle == a and t.gain * magnitudes.get(t.magnitude, 0.0) != 0 for t in terms.terms
        ):
            out.append(a)
    return tuple(out)


def _unit_phasor(terms: TermSet, mags: Mapping[str, float], idx: list[int], var: str | None):
    """Σ over terms idx of the group phasor at theta = 0, and the sign s of theta in it."""
    G = 0j
    s = 0
    for k in idx:
        t = terms.terms[k]
        a = t.gain * mags[t.magnitude]
        if t.frequency >= 0:
            G += a * np.exp(1j * t.phase)
            sk = t.angle_coeff
        else:
            G += -a * np.exp(-1j * t.phase)
            sk = -t.angle_coeff
        if var is not None:
            if s not in (0, sk):
                raise ParameterError(
                    "terms", var, "an angle enters one frequency group with both signs"
                )
            s = sk
    return G, s


def _plan(terms: TermSet, mags: Mapping[str, float], angles: dict[str, float], rule: tuple):
    from gearte.models.planetary_errors import coupled_te

    r = coupled_te(terms, mags, angles)
    return AssemblyPlan(
        angles={k: float(np.mod(v, 2 * np.pi)) for k, v in angles.items()},
        set_by_rule=tuple(rule),
        amplitude=r.amplitude,
        amplitude_sum=r.amplitude_sum,
        peak_to_peak=r.peak_to_peak,
    )


def paper_rule_assembly(
    terms: TermSet,
    magnitudes: Mapping[str, float],
    given_angles: Mapping[str, float] | None = None,
) -> AssemblyPlan:
    """Wang 2013's phase-allocation rule (eq 6 signs lambda = ±1; Table 3).

    Parameters
    ----------
    terms : TermSet
    magnitudes : mapping
        Error magnitudes [mm] (the paper uses the tolerances of Table 1).
    given_angles : mapping, optional
        Angles [rad] of the reference and of the "arbitrary" angles (default 0).

    Returns
    -------
    AssemblyPlan
        For eq 9 as printed: gamma_s = beta_l + 7 pi/9, gamma_c = beta_l + 8 pi/9, gamma_p = 0
        (Table 3) and the paper's measure ``|c| + Σ|Z_g|`` = 28.75 µm → 131.5″.

    Notes
    -----
    Each angle is allocated in the lowest-frequency group it enters; in a group, a unit's
    phasor is ``G_v e^{i s theta_v}``; the fixed part F (reference, angle-free terms, angles
    owned by other groups) sets the direction; the unit is turned to ``lambda_v |G_v| F/|F|``.
    Without a fixed part the largest unit keeps its given angle and sets the direction. In the
    zero-frequency group each unit is turned so that its constant ``Im(G_v e^{i s theta})`` is 0
    (the smaller of the two solutions in [0, 2 pi)).
    """
    mags = dict(magnitudes)
    ang, rule = paper_rule_angles(terms, mags, given_angles)
    return _plan(terms, mags, ang, tuple(rule))


def paper_rule_angles(
    terms: TermSet,
    magnitudes: Mapping[str, float],
    given_angles: Mapping[str, float] | None = None,
) -> tuple[dict[str, float], list[str]]:
    """The angles [rad] of :func:`paper_rule_assembly` and the angles the rule set, without
    evaluating the TE (the study's pre-flight runs it to check the term keys and that no angle
    enters a frequency group with both signs).

    Raises
    ------
    ParameterError
        ``terms``: an angle enters one frequency group with both signs; a missing magnitude.
    """
    from gearte.models.planetary_errors import frequency_basis, keyed_vector

    mags = dict(magnitudes)
    keyed_vector(terms.magnitudes, mags, "magnitudes", required=True)
    ang = {a: float((given_angles or {}).get(a, 0.0)) for a in terms.angles}
    _, harm, group = frequency_basis(terms)
    owned: dict[str, int] = {}
    order = [-1] + list(range(len(harm)))
    for g in order:
        for k, t in enumerate(terms.terms):
            if group[k] == g and t.angle in terms.free_angles and t.angle not in owned:
                owned[t.angle] = g
    rule: list[str] = []
    for g in order:
        ks = [k for k in range(len(terms.terms)) if group[k] == g]
        units: dict[str, list[int]] = {}
        fixed: list[int] = []
        for k in ks:
            a = terms.terms[k].angle
            if a is not None and owned.get(a) == g:
                units.setdefault(a, []).append(k)
            else:
                fixed.append(k)
        if not units:
            continue
        if g == -1:
            for v, idx in units.items():
                Gv, s = _unit_phasor(terms, mags, idx, v)
                if abs(Gv) == 0:
                    continue
                th = np.mod(-np.angle(Gv) / s, np.pi)  # Im(G e^{i s th}) = 0
                ang[v] = float(th)
                rule.append(v)
            continue
        # fixed part of the group at the current angles
        F = 0j
        for k in fixed:
            t = terms.terms[k]
            amp = t.gain * mags[t.magnitude]
            ph = t.phase + (t.angle_coeff * ang[t.angle] if t.angle is not None else 0.0)
            F += amp * np.exp(1j * ph) if t.frequency > 0 else -amp * np.exp(-1j * ph)
        phasors = {v: _unit_phasor(terms, mags, idx, v) for v, idx in units.items()}
        free = [v for v in phasors if abs(phasors[v][0]) > 0]
        if abs(F) == 0:
            if len(free) <= 1:
                continue  # a lone unit: its angle is arbitrary
            lead = max(free, key=lambda v: abs(phasors[v][0]))
            Gl, sl = phasors[lead]
            F = Gl * np.exp(1j * sl * ang[lead])
            free = [v for v in free if v != lead]
        mags_free = np.array([abs(phasors[v][0]) for v in free])
        best = None
        for signs in itertools.product((1.0, -1.0), repeat=len(free)):
            val = abs(abs(F) + float(np.dot(signs, mags_free)))
            if best is None or val < best[0] - 1e-15:
                best = (val, signs)
        assert best is not None
        for v, lam in zip(free, best[1], strict=True):
            Gv, s = phasors[v]
            target = np.angle(F) + (0.0 if lam > 0 else np.pi)
            ang[v] = float(np.mod((target - np.angle(Gv)) / s, 2 * np.pi))
            rule.append(v)
    return ang, rule


def halton_starts(n: int, d: int, seed: int) -> np.ndarray:
    """``n`` quasi-random points in the unit cube ``[0, 1)^d`` [-]: the Halton sequence (radical
    inverses of ``i = 1..n`` in the first ``d`` primes) with a random Cranley–Patterson shift
    drawn from ``numpy.random.default_rng(seed)``.

    Low discrepancy along every axis like a scrambled Sobol set, in plain numpy: SciPy's
    ``qmc.Sobol`` costs a ~1 s import of ``scipy.stats`` per run.
    """
    if n < 1 or d < 1:
        raise ParameterError("starts", (n, d), "need at least one start in at least 1 dimension")
    primes: list[int] = []
    k = 2
    while len(primes) < d:
        if all(k % p for p in primes):
            primes.append(k)
        k += 1
    out = np.empty((n, d))
    for j, b in enumerate(primes):
        i = np.arange(1, n + 1, dtype=np.int64)
        r = np.zeros(n)
        f = 1.0
        while i.any():
            f /= b
            r += f * (i % b)
            i //= b
        out[:, j] = r
    return np.mod(out + np.random.default_rng(seed).random(d), 1.0)


def _polish_compiled(
    cand: list[np.ndarray],
    base: np.ndarray,
    pos: list[int],
    mvec: np.ndarray,
    terms: TermSet,
    workers: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Compiled Nelder–Mead (:func:`gearte.models.planetary_errors.minimize_amplitude`) from
    each start in ``cand`` [rad], restarted once from its result (a minimax can stall a simplex
    on a kink): (x per start, amplitude [mm] per start).

    The starts are independent: they run on ``workers`` threads (default: the cores this process
    may use; the kernel releases the GIL), each start's steps and result the same as in one
    thread."""
    from gearte.execution.streams import default_workers
    from gearte.models.planetary_errors import minimize_amplitude

    def polish(starts: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        return minimize_amplitude(
            terms, mvec, base, pos, starts, xatol=1e-10, fatol=1e-14, maxiter=4000 * len(pos)
        )

    n = min(default_workers() if workers is None else workers, len(cand))
    if n <= 1:
        return polish(cand)
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(n, thread_name_prefix="gearte-polish") as pool:
        parts = list(pool.map(polish, [[x] for x in cand]))
    return np.concatenate([x for x, _ in parts]), np.concatenate([f for _, f in parts])


def _polish_scipy(amp, cand: list[np.ndarray], d: int) -> tuple[np.ndarray, np.ndarray]:
    """Plain twin of :func:`_polish_compiled`: SciPy's Nelder–Mead on ``amp`` (angles [rad] →
    amplitude [mm]) from each start in ``cand``, restarted once; (x per start, value per start)."""
    from scipy.optimize import minimize

    opts = {"xatol": 1e-10, "fatol": 1e-14, "maxiter": 4000 * d, "adaptive": True}
    xs, fs = [], []
    for x0 in cand:
        res = minimize(lambda x: float(amp(x)[0]), x0, method="Nelder-Mead", options=opts)
        res = minimize(lambda x: float(amp(x)[0]), res.x, method="Nelder-Mead", options=opts)
        xs.append(res.x)
        fs.append(float(res.fun))
    return np.array(xs), np.array(fs)


def optimal_assembly(
    terms: TermSet,
    magnitudes: Mapping[str, float],
    reference_value: float = 0.0,
    *,
    starts: int = 4096,
    polish: int = 12,
    seed: int = 20130808,
    extra_starts: list[Mapping[str, float]] | None = None,
    compiled: bool = True,
    workers: int | None = None,
) -> AssemblyPlan:
    """Global minimum over all free angles of the exact coupled amplitude max_t |Σe(t)|.

    Parameters
    ----------
    terms : TermSet
    magnitudes : mapping
        Error magnitudes [mm].
    reference_value : float
        Value of the reference angle [rad] (0: angles are relative to the datum).
    starts : int
        Quasi-random start points (:func:`halton_starts`) evaluated in one compiled batch.
    polish : int
        Number of best starts refined by Nelder–Mead (xatol 1e-10 rad).
    seed : int
        Seed of the random shift of the start points (the result is deterministic).
    extra_starts : list of mappings, optional
        Further start points, angle name → angle [rad] (e.g. the paper's rule), always polished.
    compiled : bool
        Run the Nelder–Mead polish compiled (default) or with SciPy on the Python objective
        (the plain twin: same steps, ~100× slower).
    workers : int, optional
        Threads of the compiled polish (default: the cores this process may use; the result does
        not depend on it).

    Returns
    -------
    AssemblyPlan
        Angles of the relevant free angles (others 0) and the exact amplitude there.
    """
    from gearte.models.planetary_errors import keyed_vector, sample_extremes

    mags = dict(magnitudes)
    mvec = keyed_vector(terms.magnitudes, mags, "magnitudes", required=True)
    free = relevant_angles(terms, mags)
    base = np.zeros(len(terms.angles))
    if terms.reference_angle is not None:
        base[terms.angles.index(terms.reference_angle)] = reference_value
    pos = [terms.angles.index(a) for a in free]

    def full(x: np.ndarray) -> np.ndarray:
        th = np.broadcast_to(base, x.shape[:-1] + base.shape).copy()
        th[..., pos] = x
        return th

    def amp(x: np.ndarray) -> np.ndarray:
        th = full(np.atleast_2d(x))
        fmax, fmin = sample_extremes(terms, np.broadcast_to(mvec, (th.shape[0], mvec.size)), th)
        return np.maximum(fmax, -fmin)

    if not free:
        return _plan(terms, mags, dict(zip(terms.angles, base, strict=True)), ())
    d = len(free)
    sob = halton_starts(starts, d, seed) * (2 * np.pi)
    vals = amp(sob)
    cand = [sob[i] for i in np.argsort(vals)[:polish]]
    for st in extra_starts or []:
        cand.append(np.array([float(st.get(a, 0.0)) for a in free]))
    if compiled:
        xs, fs = _polish_compiled(cand, base, pos, mvec, terms, workers)
    else:
        xs, fs = _polish_scipy(amp, cand, d)
    best_x, best_v = None, np.inf
    for x, f in zip(xs, fs, strict=True):
        if f < best_v:
            best_x, best_v = x, float(f)
    assert best_x is not None
    angles = dict(zip(terms.angles, full(best_x), strict=True))
    return _plan(terms, mags, angles, free)
