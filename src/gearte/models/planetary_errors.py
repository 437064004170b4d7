"""Eccentricity errors of a 2K-H planetary → equivalent mesh errors → coupled output TE.

Every eccentricity (manufacturing ``E, beta`` turning with its part; assembly ``A, gamma`` fixed in
the housing for sun and carrier axes, fixed in the carrier for planet pins) is projected on the
external (sun–planet) and internal (planet–ring) lines of action. Each projection is one
sinusoidal *equivalent mesh error* term ``e(t) = g M sin(q w_in t + phi0 + k theta)`` [mm]; the
output transmission error is ``(e_w + e_n) * PlanetarySet.output_scale()`` [rad].

Sign convention: ``e > 0`` when the driving flank is *ahead* (the error pushes the output
forward). Wang et al. take the opposite sign ("away from the tooth is positive"), which flips every
term and leaves every amplitude unchanged.

Derivation (see ``docs/validation/wang2013.md``): with the planet i at carrier angle
``phi_i = w_c t + eta_i`` and positive torque on the sun, the unit vectors of the lines of action
(direction of the force on the planet) are ``n_w`` at angle ``phi_i - alpha + pi/2`` (sun–planet)
and ``n_n`` at ``phi_i + alpha + pi/2`` (ring–planet). Linearising the two contact conditions,

    r_bs dθ_s + e_w = a cos(alpha) dθ_c - r_bp dθ_p,   e_w = (d_s - X_i - d_pi) · n_w
    r_br dθ_r + e_n = a cos(alpha) dθ_c + r_bp dθ_p,   e_n = (d_r - X_i - d_pi) · n_n

with ``d_s, d_r`` the displacement of the sun's / ring's tooth centre, ``X_i`` the error of the
planet pin position (carrier axis offset + pin error) and ``d_pi`` the planet's tooth centre
relative to its pin. Adding them eliminates the planet rotation dθ_p:
``r_bs dθ_s + r_br dθ_r + e_w + e_n = (r_bs + r_br) dθ_c`` (the Willis equation for the errors).
Projecting a vector of length E at angle ``psi`` on a unit vector at angle ``nu`` gives
``E sin(psi - nu + pi/2)``, which yields the terms of :func:`derive_terms`.

References
----------
Wang C., Chen X., Li Y., Chen H. (2013). Coupling compensation of transmission error for planetary
gear. Trans. CSAM 44(8), 287-292. doi:10.6041/j.issn.1000-1298.2013.08.049 (Table 2, eqs 7-9).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction

import numpy as np
from numba import njit

from gearte._jit import kernel
from gearte.errors import ParameterError
from gearte.geometry.planetary import PlanetarySet, SunPlanetErrors
from gearte.models.planetary_terms import CoupledTE, ErrorTerm, TermSet
from gearte.solvers.nelder_mead import nm_best, nm_start, nm_tell
from gearte.solvers.trig_extremes import (
    SINCOS_MAX_ARG,
    exact_extremes,
    exact_extremes_numpy,
    extremes_kernel,
    grid_extremes_numpy,
    grid_points,
    node_tables,
    sincos_into,
)

__all__ = [
    "ErrorTerm",
    "keyed_vector",
    "TermSet",
    "CoupledTE",
    "derive_terms",
    "first_stage_keys",
    "terms_from_table",
    "frequency_basis",
    "group_phasors",
    "coupled_te",
    "exact_extremes",
    "exact_extremes_numpy",
    "grid_extremes_numpy",
    "sample_extremes",
    "minimize_amplitude",
]


def derive_terms(pset: PlanetarySet, planet_model: str = "reference") -> TermSet:
    """Equivalent mesh-error terms of all eccentricities, derived from kinematics.

    Parameters
    ----------
    pset : PlanetarySet
        The gear set (teeth, module [mm], pressure angle [rad], planets, members).
    planet_model : {"reference", "mean"}
        ``"reference"``: the output follows planet 1 alone (Wang 2013: "all planets in the same
        state, planet 1 studied"). ``"mean"``: the output follows the mean of the N planets'
        constraints (ideal load sharing): each term gets gain 1/N and sun/ring/carrier terms of
        the planets are summed with their position angles eta_i.

    Returns
    -------
    TermSet
        Terms with magnitudes ``E_s, A_s, E_r, A_r, A_c, E_p<i>, A_p<i>`` [mm] and angles
        ``beta_s, gamma_s, beta_r, gamma_r, gamma_c, beta_p<i>, gamma_p<i>`` [rad]; the ring's
        manufacturing-error angle ``beta_r`` is the reference (Wang 2013 §3.1) unless the ring
        turns, in which case ``beta_s`` is.

    Notes
    -----
    With ``x = phi_i`` the carrier angle of planet i, alpha the working pressure angle, speeds
    ``w`` from the Willis equation and planet angles measured from the planet's radial line:

    ========================  =====================  =========================================
    error                     line                   term [mm]
    ========================  =====================  =========================================
    sun manuf. (E_s, beta_s)  external               +E_s sin((w_s-w_c)t + beta_s + a - eta)
    sun assy (A_s, gamma_s)   external               +A_s sin(-w_c t + gamma_s + a - eta)
    ring manuf. (E_r, beta_r) internal               +E_r sin((w_r-w_c)t + beta_r - a - eta)
    ring assy (A_r, gamma_r)  internal               +A_r sin(-w_c t + gamma_r - a - eta)
    carrier assy (A_c)        external / internal    -A_c sin(-w_c t + gamma_c ± a - eta)
    planet pin (A_pi, gamma)  external / internal    -A_pi sin(gamma_pi ± a)
    planet manuf. (E_pi)      external / internal    -E_pi sin((w_p-w_c)t + beta_pi ± a)
    ========================  =====================  =========================================

    (+a on the external, -a on the internal line.) Wang 2013 Table 2 differs in three places:
    the planet's relative frequency (11/24 instead of -(z_s/z_p)(w_s-w_c) = -7/24 of w_s), the
    sign of the planet's manufacturing term on the external line, and the sign of the ring's
    term; see ``docs/validation/wang2013.md``.

    References
    ----------
    Wang C., Chen X., Li Y., Chen H. (2013). Trans. CSAM 44(8), 287-292.
    doi:10.6041/j.issn.1000-1298.2013.08.049
    """
    if planet_model not in ("reference", "mean"):
        raise ParameterError("planet_model", planet_model, "must be 'reference' or 'mean'")
    w = pset.speed_ratios()
    a = pset.pressure_angle
    q_sc = w["sun"] - w["carrier"]
    q_rc = w["ring"] - w["carrier"]
    q_c = -w["carrier"]
    q_pc = w["planet_rel"]
    planets = range(pset.n_planets) if planet_model == "mean" else range(1)
    g = 1.0 / pset.n_planets if planet_model == "mean" else 1.0
    terms: list[ErrorTerm] = []
    for i in planets:
        eta = float(pset.eta[i])
        p = f"p{i + 1}"
        suffix = f"/planet{i + 1}"
        terms += [
            ErrorTerm("E_s/external" + suffix, "E_s", g, q_sc, a - eta, "beta_s", 1, "external"),
            ErrorTerm("A_s/external" + suffix, "A_s", g, q_c, a - eta, "gamma_s", 1, "external"),
            ErrorTerm("E_r/internal" + suffix, "E_r", g, q_rc, -a - eta, "beta_r", 1, "internal"),
            ErrorTerm("A_r/internal" + suffix, "A_r", g, q_c, -a - eta, "gamma_r", 1, "internal"),
            ErrorTerm("A_c/external" + suffix, "A_c", -g, q_c, a - eta, "gamma_c", 1, "external"),
            ErrorTerm("A_c/internal" + suffix, "A_c", -g, q_c, -a - eta, "gamma_c", 1, "internal"),
            ErrorTerm(f"A_{p}/external", f"A_{p}", -g, Fraction(0), a, f"gamma_{p}", 1, "external"),
            ErrorTerm(
                f"A_{p}/internal", f"A_{p}", -g, Fraction(0), -a, f"gamma_{p}", 1, "internal"
            ),
            ErrorTerm(f"E_{p}/external", f"E_{p}", -g, q_pc, a, f"beta_{p}", 1, "external"),
            ErrorTerm(f"E_{p}/internal", f"E_{p}", -g, q_pc, -a, f"beta_{p}", 1, "internal"),
        ]
    ref = "beta_r" if w["ring"] == 0 else "beta_s"
    return TermSet(tuple(terms), pset.output_scale(), reference_angle=ref)


def first_stage_keys(errors: SunPlanetErrors) -> tuple[dict[str, float], dict[str, float]]:
    """The sun and planet eccentricities of the shared error object under the term keys of
    :func:`derive_terms`.

    Parameters
    ----------
    errors : SunPlanetErrors
        Sun eccentricity, sun assembly error, one eccentricity per planet [mm, rad] (the object
        the RV first stage holds too).

    Returns
    -------
    tuple of dict
        Magnitudes ``E_s, A_s, E_p<i>`` [mm] and angles ``beta_s, gamma_s, beta_p<i>`` [rad].

    References
    ----------
    Wang C., Chen X., Li Y., Chen H. (2013). Trans. CSAM 44(8), 287-292, Table 1.
    doi:10.6041/j.issn.1000-1298.2013.08.049
    """
    mags = {"E_s": errors.sun.amplitude, "A_s": errors.sun_assembly.amplitude}
    angs = {"beta_s": errors.sun.phase, "gamma_s": errors.sun_assembly.phase}
    for i, p in enumerate(errors.planets, start=1):
        mags[f"E_p{i}"] = p.amplitude
        angs[f"beta_p{i}"] = p.phase
    return mags, angs


def _parse_fraction(value: float | str | Fraction, field_name: str) -> Fraction:
    try:
        if isinstance(value, str):
            return Fraction(value.replace(" ", ""))
        if isinstance(value, Fraction):
            return value
        return Fraction(value).limit_denominator(10_000)
    except (ValueError, ZeroDivisionError) as exc:
        raise ParameterError(field_name, value, "must be a number or a fraction 'p/q'") from exc


def terms_from_table(
    rows: Sequence[Mapping[str, object]], scale: float, reference_angle: str | None = None
) -> TermSet:
    """Build a term set from a published list ("terms as given", e.g. Wang 2013 eq. 9).

    Parameters
    ----------
    rows : sequence of mappings
        Each with ``magnitude`` (key), ``gain`` (default 1), ``frequency`` (multiple of the input
        speed: number or ``"p/q"`` string), ``phase`` [rad], ``angle`` (key or None),
        ``angle_coeff`` (+1/-1, default +1), optional ``name``.
    scale : float
        Output rotation per mm of summed mesh error [rad/mm] (eq. 9: ``1/(r_bs i_sc)``).
    reference_angle : str, optional
        The angle held at 0 as the assembly datum.

    References
    ----------
    Wang C., Chen X., Li Y., Chen H. (2013). Trans. CSAM 44(8), 287-292.
    doi:10.6041/j.issn.1000-1298.2013.08.049
    """
    terms = []
    for k, r in enumerate(rows):
        angle = r.get("angle")
        coeff = int(r.get("angle_coeff", 1 if angle else 0))  # type: ignore[call-overload]  # row values are checked below
        if angle is not None and coeff not in (-1, 1):
            raise ParameterError(f"terms[{k}].angle_coeff", coeff, "must be +1 or -1")
        gain = float(r.get("gain", 1.0))  # type: ignore[arg-type]
        terms.append(
            ErrorTerm(
                name=str(r.get("name", f"e{k + 1}")),
                magnitude=str(r["magnitude"]),
                gain=gain,
                frequency=_parse_fraction(r["frequency"], f"terms[{k}].frequency"),  # type: ignore[arg-type]
                phase=float(r["phase"]),  # type: ignore[arg-type]
                angle=None if angle is None else str(angle),
                angle_coeff=coeff if angle is not None else 0,
            )
        )
    return TermSet(tuple(terms), scale, reference_angle)


def frequency_basis(terms: TermSet) -> tuple[Fraction, tuple[int, ...], np.ndarray]:
    """Fundamental frequency and the harmonic number of every distinct non-zero |q| of ``terms``.

    Returns
    -------
    q0 : Fraction
        Fundamental = gcd of the |q| (as fractions of the input speed); the common period is
        ``1/q0`` input revolutions (24 for 12/36/84).
    harmonics : tuple of int
        Sorted distinct harmonic numbers n_g = |q_g| / q0.
    group : ndarray of int
        Per term, the index into ``harmonics`` (-1 for q = 0).
    """
    if terms._basis is not None:  # computed once per term set
        return terms._basis[0], terms._basis[1], terms._basis[2].copy()
    qs = [abs(t.frequency) for t in terms.terms if t.frequency != 0]
    if not qs:
        return Fraction(1), (), np.full(len(terms.terms), -1, dtype=np.int64)
    num = 0
    den = 1
    for q in qs:
        num = math.gcd(num, q.numerator)
        den = den * q.denominator // math.gcd(den, q.denominator)
    q0 = Fraction(num, den)
    harm = sorted({int(q / q0) for q in qs})
    idx = {h: i for i, h in enumerate(harm)}
    group = np.array(
        [idx[int(abs(t.frequency) / q0)] if t.frequency != 0 else -1 for t in terms.terms],
        dtype=np.int64,
    )
    object.__setattr__(terms, "_basis", (q0, tuple(harm), group.copy()))
    return q0, tuple(harm), group


def _term_arrays(terms: TermSet) -> dict[str, np.ndarray]:
    """Flat arrays describing the terms, for the vectorised / compiled evaluation; computed once
    per :class:`TermSet` (the fraction arithmetic of :func:`frequency_basis` is slow) and kept on
    it (callers must not write to them)."""
    if terms._arrays is not None:
        return terms._arrays
    _, harm, group = frequency_basis(terms)
    mag_idx = np.array([terms.magnitudes.index(t.magnitude) for t in terms.terms], dtype=np.int64)
    ang_idx = np.array(
        [terms.angles.index(t.angle) if t.angle is not None else -1 for t in terms.terms],
        dtype=np.int64,
    )
    coeff = np.array([t.angle_coeff for t in terms.terms], dtype=np.float64)
    gain = np.array([t.gain for t in terms.terms], dtype=np.float64)
    phase = np.array([t.phase for t in terms.terms], dtype=np.float64)
    fsign = np.array([np.sign(float(t.frequency)) for t in terms.terms], dtype=np.float64)
    arr = {
        "harmonics": np.asarray(harm, dtype=np.int64),
        "group": group,
        "mag_idx": mag_idx,
        "ang_idx": ang_idx,
        "coeff": coeff,
        "gain": gain,
        "phase": phase,
        "fsign": fsign,
    }
    object.__setattr__(terms, "_arrays", arr)
    return arr


def group_phasors(
    terms: TermSet, magnitudes: np.ndarray, angles: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Exact phasor sums of the same-frequency terms (complex arithmetic, no arctan).

    Parameters
    ----------
    terms : TermSet
    magnitudes : ndarray, shape (..., len(terms.magnitudes))
        Error magnitudes [mm] in the order of ``terms.magnitudes``.
    angles : ndarray, shape (..., len(terms.angles))
        Error angles [rad] in the order of ``terms.angles``.

    Returns
    -------
    c : ndarray, shape (...)
        The zero-frequency (constant) part [mm].
    Z : ndarray of complex, shape (..., G)
        Per harmonic ``n_g`` the phasor with ``Σ_g e_g(u) = Im(Z_g exp(i n_g u))`` [mm], where
        ``u = q0 w_in t``.

    Notes
    -----
    ``A sin(q w t + phi)`` is ``Im(A e^{i phi} e^{i q w t})`` for q > 0 and
    ``Im(-A e^{-i phi} e^{i |q| w t})`` for q < 0; Wang 2013 eqs 2-5 are the same sums written with
    arctan, which loses the quadrant (their footnote to eq 3 patches the case of a zero
    denominator only).

    References
    ----------
    Wang C., Chen X., Li Y., Chen H. (2013). Trans. CSAM 44(8), 287-292.
    doi:10.6041/j.issn.1000-1298.2013.08.049
    """
    arr = _term_arrays(terms)
    m = np.asarray(magnitudes, dtype=float)
    th = np.asarray(angles, dtype=float)
    if th.shape[-1] == 0:  # no angle keys at all
        th = np.zeros(th.shape[:-1] + (1,))
    lead = np.broadcast_shapes(m.shape[:-1], th.shape[:-1])
    amp = arr["gain"] * m[..., arr["mag_idx"]]
    ang = np.where(arr["ang_idx"] >= 0, th[..., np.maximum(arr["ang_idx"], 0)], 0.0)
    phi = arr["phase"] + arr["coeff"] * ang
    G = len(arr["harmonics"])
    c = np.zeros(lead)
    Z = np.zeros(lead + (G,), dtype=complex)
    for k in range(len(terms.terms)):
        gidx = arr["group"][k]
        if gidx < 0:
            c = c + amp[..., k] * np.sin(phi[..., k])
        elif arr["fsign"][k] > 0:
            Z[..., gidx] += amp[..., k] * np.exp(1j * phi[..., k])
        else:
            Z[..., gidx] += -amp[..., k] * np.exp(-1j * phi[..., k])
    return c, Z


# --------------------------------------------------------------------------- sample kernel
@njit(cache=True, nogil=True, inline="always")
def _row_phasors(mags, i, sa, ca, gain, mag_idx, ang_idx, coeff, c0, s0, fsign, group, zr, zi):
    """Constant part c (returned) and group phasors (zr, zi, filled) of sample i, from the
    sines/cosines ``sa[v], ca[v]`` of its angles and the terms' phase tables c0, s0."""
    c = 0.0
    for g in range(zr.shape[0]):
        zr[g] = 0.0
        zi[g] = 0.0
    for k in range(gain.shape[0]):
        a = gain[k] * mags[i, mag_idx[k]]
        v = ang_idx[k]
        if v >= 0:  # phase + coeff * theta, coeff = ±1
            cp = c0[k] * ca[v] - coeff[k] * s0[k] * sa[v]
            sp = s0[k] * ca[v] + coeff[k] * c0[k] * sa[v]
        else:
            cp = c0[k]
            sp = s0[k]
        gi = group[k]
        if gi < 0:
            c += a * sp
        elif fsign[k] > 0:
            zr[gi] += a * cp
            zi[gi] += a * sp
        else:
            zr[gi] -= a * cp
            zi[gi] += a * sp
    return c


MODE_SAMPLES = 0
""":func:`_te_kernel` mode: extremes per row of magnitudes and angles."""
MODE_MINIMIZE = 1
""":func:`_te_kernel` mode: Nelder–Mead on the amplitude over the free angles."""
MODE_PHASORS = 2
""":func:`_te_kernel` mode: extremes per row of given constant parts and phasors."""


@kernel
def _te_kernel(mode, mags, angs, cz, pos, tf, ti, nh, M, fx, fn, sim, fsim, vec, ist, tol):
    """The planetary's one compiled entry point: exact extremes of Σe for many assemblies, or
    the assembly that minimises the amplitude max|Σe| (compiled Nelder–Mead).

    ``mode`` :data:`MODE_SAMPLES`: row i of ``mags`` [mm] (n, n_mag) and ``angs`` [rad] (n, V)
    → ``fx[i]``, ``fn[i]`` = max, min of Σe [mm]. :data:`MODE_PHASORS`: row i of ``cz`` (n,
    1 + 2 G) = constant part, Re Z_g, Im Z_g [mm] → ``fx[i]``, ``fn[i]``. :data:`MODE_MINIMIZE`:
    ``angs[0]`` all angles [rad], of which ``pos`` are free; Nelder–Mead (state ``sim, fsim,
    vec, ist`` of :mod:`gearte.solvers.nelder_mead`, started by the caller; tolerances ``tol`` =
    xatol [rad], fatol [mm]) on the amplitude [mm] (inf where an angle leaves the exact range of
    sincos) with ``mags[0]``; the best vertex stays in ``sim[0]``.

    Per term, ``tf`` rows gain, coeff, cos phase, sin phase, sign of the frequency, phase [rad]
    (in :data:`MODE_SAMPLES` the cosines and sines are computed here from the phases) and ``ti``
    rows magnitude index, angle index, group; ``nh`` the harmonics, ``M`` the grid's nodes.

    One kernel with a single call site of :func:`~gearte.solvers.trig_extremes.extremes_kernel`
    and of :func:`_row_phasors`: numba compiles a copy of what a kernel calls into every kernel
    that calls it, and the three uses compiled three copies (issue 12: first-run compile).
    """
    G = nh.shape[0]
    V = angs.shape[1]
    N = pos.shape[0]
    n = fx.shape[0] if mode != MODE_MINIMIZE else 1
    if n == 0:
        return
    if mode == MODE_SAMPLES:
        for k in range(tf.shape[1]):
            tf[2, k] = math.cos(tf[5, k])
            tf[3, k] = math.sin(tf[5, k])
    tab = node_tables(nh, M)
    buf = np.empty(M)
    zr = np.empty(G)
    zi = np.empty(G)
    wr = np.empty(G)
    wi = np.empty(G)
    th = np.empty(V)
    sa = np.empty(V)
    ca = np.empty(V)
    xt = vec[2]
    i = 0
    while True:
        ok = True
        c = 0.0
        if mode == MODE_PHASORS:
            c = cz[i, 0]
            for g in range(G):
                zr[g] = cz[i, 1 + g]
                zi[g] = cz[i, 1 + G + g]
        else:
            # row i of the samples, or the one row of the optimisation (i stays 0 there: a literal
            # 0 in the call would compile _row_phasors a second time, for Literal[int](0))
            for v in range(V):
                th[v] = angs[i, v]
            if mode == MODE_MINIMIZE:
                for j in range(N):
                    th[pos[j]] = xt[j]
                for v in range(V):
                    if not abs(th[v]) <= SINCOS_MAX_ARG:
                        ok = False
            if ok:
                sincos_into(th, sa, ca)
                c = _row_phasors(
                    mags, i, sa, ca, tf[0], ti[0], ti[1], tf[1], tf[2], tf[3], tf[4], ti[2], zr, zi
                )
        fmax = np.inf
        fmin = -np.inf
        if ok:
            if G == 0:
                fmax = c
                fmin = c
            else:
                fmax, fmin = extremes_kernel(c, zr, zi, nh, tab, buf, wr, wi)
        if mode != MODE_MINIMIZE:
            fx[i] = fmax
            fn[i] = fmin
            i += 1
            if i >= n:
                return
        else:
            f = (abs(c) if G == 0 else max(fmax, -fmin)) if ok else np.inf
            if nm_tell(f, tol[0], tol[1], sim, fsim, vec, ist):
                return


def _term_tables(terms: TermSet) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """``tf`` (cos and sin of the phases from numpy), ``ti``, harmonics and nodes ``M`` of
    :func:`_te_kernel` for ``terms`` (16 nodes when there is no group)."""
    arr = _term_arrays(terms)
    ph = arr["phase"]
    tf = np.array([arr["gain"], arr["coeff"], np.cos(ph), np.sin(ph), arr["fsign"], ph])
    ti = np.array([arr["mag_idx"], arr["ang_idx"], arr["group"]], dtype=np.int64)
    nh = arr["harmonics"]
    return tf, ti, nh, grid_points(nh) if nh.size else 16


_NO_F2 = np.zeros((0, 0))
_NO_F1 = np.zeros(0)
_NO_I1 = np.zeros(0, dtype=np.int64)


def _phasor_extremes(
    c: np.ndarray, Z: np.ndarray, harmonics: Sequence[int]
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~gearte.solvers.trig_extremes.exact_extremes` through :func:`_te_kernel` (the same
    kernel, the same values): max, min [mm] per row of ``c`` (n,) and ``Z`` (n, G) [mm]."""
    nh = np.ascontiguousarray(np.asarray(harmonics, dtype=np.int64))
    c = np.atleast_1d(np.asarray(c, dtype=float))
    Z = np.atleast_2d(np.asarray(Z, dtype=complex))
    if nh.size == 0:
        return c.copy(), c.copy()
    if np.any(nh < 1):
        raise ParameterError("harmonics", harmonics, "must be integers >= 1")
    cz = np.ascontiguousarray(np.concatenate([c[:, None], Z.real, Z.imag], axis=1))
    n = c.shape[0]
    fx = np.empty(n)
    fn = np.empty(n)
    _te_kernel(
        MODE_PHASORS, _NO_F2, np.zeros((0, 1)), cz, _NO_I1, _NO_F2, np.zeros((0, 0), np.int64),
        nh, grid_points(nh), fx, fn, _NO_F2, _NO_F1, _NO_F2, _NO_I1, _NO_F1,
    )  # fmt: skip
    return fx, fn


def minimize_amplitude(
    terms: TermSet,
    magnitudes: np.ndarray,
    base: np.ndarray,
    pos: Sequence[int],
    starts: Sequence[np.ndarray],
    xatol: float,
    fatol: float,
    maxiter: int,
    restarts: int = 1,
) -> tuple[np.ndarray, np.ndarray]:
    """Compiled Nelder–Mead (SciPy's adaptive method, :mod:`gearte.solvers.nelder_mead`) on the
    exact amplitude max|Σe| [mm] over the free angles ``pos`` (indices into ``terms.angles``),
    from each of ``starts`` [rad], restarted ``restarts`` times from its own result (a minimax
    can stall a simplex on a kink).

    ``magnitudes`` [mm] per key of ``terms.magnitudes``; ``base`` [rad] every angle (the free
    ones are overwritten); ``xatol`` [rad], ``fatol`` [mm] and ``maxiter`` [-] as SciPy's.
    Returns (x [rad] per start, amplitude [mm] per start). The amplitude is inf where an angle
    leaves ±:data:`~gearte.solvers.trig_extremes.SINCOS_MAX_ARG`.
    """
    tf, ti, nh, M = _term_tables(terms)
    mags = np.ascontiguousarray(np.asarray(magnitudes, dtype=float).reshape(1, -1))
    angs = np.ascontiguousarray(np.asarray(base, dtype=float).reshape(1, -1))
    p = np.asarray(pos, dtype=np.int64)
    N = p.size
    sim = np.empty((N + 1, N))
    fsim = np.empty(N + 2)
    vec = np.empty((4, N))
    ist = np.zeros(4, dtype=np.int64)
    tol = np.array([xatol, fatol], dtype=float)
    xs, fs = [], []
    for x0 in starts:
        x = np.ascontiguousarray(x0, dtype=float)
        for _ in range(1 + restarts):
            nm_start(x, maxiter, sim, fsim, vec, ist)
            _te_kernel(
                MODE_MINIMIZE, mags, angs, _NO_F2, p, tf, ti, nh, M, _NO_F1, _NO_F1, sim, fsim,
                vec, ist, tol,
            )  # fmt: skip
            x = sim[0].copy()
        xs.append(x)
        fs.append(nm_best(fsim, N))
    return np.array(xs), np.array(fs)


def sample_extremes(
    terms: TermSet, magnitudes: np.ndarray, angles: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Exact max and min of Σe(t) [mm] for each row of ``magnitudes`` [mm] and ``angles`` [rad]
    (shapes (n, len(terms.magnitudes)) and (n, len(terms.angles))), in one compiled pass.

    The extremes come from :func:`gearte.solvers.trig_extremes.exact_extremes`' kernel; the
    angles' sines and cosines from its vectorised :func:`~gearte.solvers.trig_extremes.sincos`
    (|angle| <= 1e5 rad).
    """
    # C-contiguous and writeable: a read-only view (np.broadcast_to) is another compile
    m = np.require(np.atleast_2d(np.asarray(magnitudes, dtype=float)), requirements=["C", "W"])
    th = np.require(np.atleast_2d(np.asarray(angles, dtype=float)), requirements=["C", "W"])
    if th.shape[1] == 0:
        th = np.zeros((m.shape[0], 1))
    if th.size and not np.all(np.abs(th) <= SINCOS_MAX_ARG):
        raise ParameterError(
            "angles", float(np.max(np.abs(th))), f"|angle| must be <= {SINCOS_MAX_ARG} rad"
        )
    tf, ti, nh, M = _term_tables(terms)  # cos and sin of the phases computed in the kernel
    n = m.shape[0]
    fx = np.empty(n)
    fn = np.empty(n)
    _te_kernel(
        MODE_SAMPLES, m, th, _NO_F2, _NO_I1, tf, ti, nh, M, fx, fn, _NO_F2, _NO_F1, _NO_F2,
        _NO_I1, _NO_F1,
    )  # fmt: skip
    return fx, fn


# --------------------------------------------------------------------------- coupled TE
def coupled_te(
    terms: TermSet, magnitudes: Mapping[str, float], angles: Mapping[str, float]
) -> CoupledTE:
    """Coupled output TE of one assembly.

    Parameters
    ----------
    terms : TermSet
    magnitudes : mapping
        Magnitude per key of ``terms.magnitudes`` [mm]; missing keys raise.
    angles : mapping
        Angle per key of ``terms.angles`` [rad]; missing keys count as 0.

    Returns
    -------
    CoupledTE
        With the exact amplitude ``max |Σe(t)|`` and peak-to-peak over the common period.
    """
    mags = keyed_vector(terms.magnitudes, magnitudes, "magnitudes", required=True)
    angs = keyed_vector(terms.angles, angles, "angles", required=False)
    q0, harm, _ = frequency_basis(terms)
    c, Z = group_phasors(terms, mags, angs)
    fmax, fmin = _phasor_extremes(np.array([c]), Z[None, :], harm)
    return CoupledTE(
        constant=float(c),
        harmonics=harm,
        frequencies=tuple(q0 * h for h in harm),
        phasors=np.asarray(Z),
        fmax=float(fmax[0]),
        fmin=float(fmin[0]),
        scale=terms.scale,
        q0=q0,
    )


def keyed_vector(
    keys: Sequence[str], values: Mapping[str, float], what: str, required: bool
) -> np.ndarray:
    """Values of a name → value mapping in the order of ``keys``, checked.

    Parameters
    ----------
    keys : sequence of str
        Term names, in the order of the returned vector.
    values : mapping
        Name → magnitude [mm] (``what="magnitudes"``, must be ≥ 0) or angle [rad].
    what : str
        Field name used in error messages.
    required : bool
        Missing names are an error (else 0).
    """
    out = np.zeros(len(keys))
    for i, k in enumerate(keys):
        if k in values:
            v = float(values[k])
            if not np.isfinite(v):
                raise ParameterError(f"{what}.{k}", v, "must be finite")
            if what == "magnitudes" and v < 0:
                raise ParameterError(f"{what}.{k}", v, "must be >= 0 [mm]")
            out[i] = v
        elif required:
            raise ParameterError(f"{what}.{k}", None, f"missing; needed keys: {list(keys)}")
    return out
