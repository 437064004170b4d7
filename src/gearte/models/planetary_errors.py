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
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
from numba import njit

from gearte.errors import ParameterError
from gearte.geometry.planetary import PlanetarySet

__all__ = [
    "ErrorTerm",
    "TermSet",
    "CoupledTE",
    "derive_terms",
    "terms_from_table",
    "frequency_basis",
    "group_phasors",
    "coupled_te",
    "exact_extremes",
    "exact_extremes_numpy",
    "grid_extremes_numpy",
    "sample_extremes",
]


@dataclass(frozen=True)
class ErrorTerm:
    """One equivalent mesh error term ``e(t) = gain * M * sin(q w_in t + phase + k * theta)``.

    Attributes
    ----------
    name : str
        Label, e.g. ``"E_s/external"``.
    magnitude : str
        Key of the error magnitude M [mm] (``"E_s"``, ``"A_c"``, ``"E_p1"``...).
    gain : float
        Dimensionless factor on M (1 for a plain projection; 1/N in the planet-mean model).
    frequency : Fraction
        Angular frequency as a signed multiple q of the input speed [-].
    phase : float
        Constant phase phi0 [rad].
    angle : str or None
        Key of the error angle theta [rad] (``"beta_s"``, ``"gamma_c"``...), None for none.
    angle_coeff : int
        k, the multiple of theta in the phase (+1 or -1; 0 when ``angle`` is None).
    line : str
        ``"external"``, ``"internal"`` or ``"given"``.
    """

    name: str
    magnitude: str
    gain: float
    frequency: Fraction
    phase: float
    angle: str | None
    angle_coeff: int
    line: str = "given"


@dataclass(frozen=True)
class TermSet:
    """The terms of a set and the output scale that turns Σe [mm] into output rotation [rad]."""

    terms: tuple[ErrorTerm, ...]
    scale: float  # [rad/mm]
    reference_angle: str | None = None  # an angle held at 0: the assembly datum
    magnitudes: tuple[str, ...] = field(init=False)
    angles: tuple[str, ...] = field(init=False)

    def __post_init__(self) -> None:
        if not self.terms:
            raise ParameterError("terms", [], "at least one term is needed")
        mags: list[str] = []
        angs: list[str] = []
        for t in self.terms:
            if (t.angle is None and t.angle_coeff != 0) or (
                t.angle is not None and t.angle_coeff not in (-1, 1)
            ):
                raise ParameterError(
                    f"terms.{t.name}.angle_coeff", t.angle_coeff, "must be ±1 (0 without angle)"
                )
            if t.magnitude not in mags:
                mags.append(t.magnitude)
            if t.angle is not None and t.angle not in angs:
                angs.append(t.angle)
        object.__setattr__(self, "magnitudes", tuple(mags))
        object.__setattr__(self, "angles", tuple(angs))
        if self.reference_angle is not None and self.reference_angle not in angs:
            raise ParameterError(
                "reference_angle", self.reference_angle, f"must be one of the angles {angs}"
            )

    @property
    def free_angles(self) -> tuple[str, ...]:
        """Angles the assembler can choose (all but the reference)."""
        return tuple(a for a in self.angles if a != self.reference_angle)


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
    """
    terms = []
    for k, r in enumerate(rows):
        angle = r.get("angle")
        coeff = int(r.get("angle_coeff", 1 if angle else 0))  # type: ignore[arg-type]
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
    """Fundamental frequency and the harmonic number of every distinct non-zero |q|.

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
    return q0, tuple(harm), group


def _term_arrays(terms: TermSet) -> dict[str, np.ndarray]:
    """Flat arrays describing the terms, for the vectorised / compiled evaluation."""
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
    return {
        "harmonics": np.asarray(harm, dtype=np.int64),
        "group": group,
        "mag_idx": mag_idx,
        "ang_idx": ang_idx,
        "coeff": coeff,
        "gain": gain,
        "phase": phase,
        "fsign": fsign,
    }


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


# --------------------------------------------------------------------------- exact extremes
def _grid_points(harmonics: Sequence[int]) -> int:
    """Grid size of the dense stage: 8 points per period of the highest harmonic (>= 16; always
    a multiple of 4, which :func:`_argmax_argmin` relies on)."""
    return max(16, 8 * int(max(harmonics)) if len(harmonics) else 16)


@njit(cache=True, nogil=True)
def _f_d1_d2(u, c, zr, zi, nh):
    f = c
    d1 = 0.0
    d2 = 0.0
    for g in range(nh.shape[0]):
        n = nh[g]
        s = math.sin(n * u)
        co = math.cos(n * u)
        v = zr[g] * s + zi[g] * co
        f += v
        d1 += n * (zr[g] * co - zi[g] * s)
        d2 -= n * n * v
    return f, d1, d2


@njit(cache=True, nogil=True)
def _f_d123(u, c, zr, zi, nh):
    """f and its first three derivatives at u.

    One sine/cosine of u; e^{i n_g u} for the sorted harmonics by complex multiplication
    (w^{n_g} = w^{n_{g-1}} w^{n_g - n_{g-1}}, binary powering), relative error ~ 1e-15.
    """
    cu = math.cos(u)
    su = math.sin(u)
    pr = 1.0  # running power w^{n_{g-1}}
    pi_ = 0.0
    last = 0
    f = c
    d1 = 0.0
    d2 = 0.0
    d3 = 0.0
    for g in range(nh.shape[0]):
        n = nh[g]
        k = n - last
        last = n
        # w^k by binary powering
        br = cu
        bi = su
        qr = 1.0
        qi = 0.0
        while k > 0:
            if k & 1:
                t = qr * br - qi * bi
                qi = qr * bi + qi * br
                qr = t
            k >>= 1
            if k:
                t = br * br - bi * bi
                bi = 2.0 * br * bi
                br = t
        t = pr * qr - pi_ * qi
        pi_ = pr * qi + pi_ * qr
        pr = t
        co = pr
        s_ = pi_
        v = zr[g] * s_ + zi[g] * co
        w = n * (zr[g] * co - zi[g] * s_)
        f += v
        d1 += w
        d2 -= n * n * v
        d3 -= n * n * w
    return f, d1, d2, d3


@njit(cache=True, nogil=True)
def _golden(u0, lo, hi, sgn, c, zr, zi, nh):
    """Golden-section search for a local maximum of sgn*f on [lo, hi] (fallback, rarely used)."""
    gr = 0.6180339887498949
    a = lo
    b = hi
    x1 = b - gr * (b - a)
    x2 = a + gr * (b - a)
    f1 = sgn * _f_d1_d2(x1, c, zr, zi, nh)[0]
    f2 = sgn * _f_d1_d2(x2, c, zr, zi, nh)[0]
    for _ in range(200):
        if b - a <= 1e-12:
            break
        if f1 < f2:
            a = x1
            x1 = x2
            f1 = f2
            x2 = a + gr * (b - a)
            f2 = sgn * _f_d1_d2(x2, c, zr, zi, nh)[0]
        else:
            b = x2
            x2 = x1
            f2 = f1
            x1 = b - gr * (b - a)
            f1 = sgn * _f_d1_d2(x1, c, zr, zi, nh)[0]
    best = max(f1, f2)
    fu = sgn * _f_d1_d2(u0, c, zr, zi, nh)[0]
    return max(best, fu)


@njit(cache=True, nogil=True)
def _refine(u0, du, lo, hi, sgn, c, zr, zi, nh, stol):
    """Local maximum of sgn*f in [lo, hi], Halley iteration on f' from u0 + du.

    ``du`` is the parabolic-interpolation guess from the grid. Stops when the step is below
    ``stol`` and returns the third-order Taylor value at the stepped point, whose error is below
    Σ|Z| n⁴ stol⁴ / 24; the caller sets stol so that this is 1e-13 Σ|Z| (1e-13 relative to the
    largest possible |f|). Falls back to golden-section search if the iteration leaves
    [lo, hi] or meets f'' of the wrong sign.
    """
    u = u0 + du
    for _ in range(30):
        f, d1, d2, d3 = _f_d123(u, c, zr, zi, nh)
        d1 *= sgn
        d2 *= sgn
        d3 *= sgn
        if d2 >= 0.0:
            break
        den = 2.0 * d2 * d2 - d1 * d3
        step = -2.0 * d1 * d2 / den if den > 0.0 else -d1 / d2  # Halley, else Newton
        if abs(step) <= stol:
            return sgn * f + step * (d1 + step * (0.5 * d2 + step * d3 / 6.0))
        u = u + step
        if u < lo or u > hi:
            break
    return _golden(u0, lo, hi, sgn, c, zr, zi, nh)


@njit(cache=True, nogil=True)
def _nb(buf, j, sgn):
    """sgn * (previous, this, next node value), periodic; no integer modulo (slow)."""
    M = buf.shape[0]
    jp = j - 1 if j > 0 else M - 1
    jn = j + 1 if j < M - 1 else 0
    return sgn * buf[jp], sgn * buf[j], sgn * buf[jn]


@njit(cache=True, nogil=True)
def _parabolic(buf, j, sgn, h):
    """Offset of the vertex of the parabola through the nodes j-1, j, j+1 [rad]."""
    vp, v, vn = _nb(buf, j, sgn)
    den = vp - 2.0 * v + vn
    return 0.5 * h * (vp - vn) / den if den < 0.0 else 0.0


@njit(cache=True, nogil=True)
def _refine_node(buf, j, sgn, h, c, zr, zi, nh, stol):
    return _refine(
        j * h, _parabolic(buf, j, sgn, h), (j - 1) * h, (j + 1) * h, sgn, c, zr, zi, nh, stol
    )


@njit(cache=True, nogil=True)
def _best_extremum(buf, j0, sgn, h, bound, c, zr, zi, nh, stol):
    """Global max of sgn*f over the period.

    The best node j0 is refined first (value B). A true maximum elsewhere can exceed its nearest
    node by at most ``bound``, so only nodes above B - bound can lead to a higher one: the run of
    such nodes around j0 is searched for further discrete peaks, and the remaining nodes are
    scanned (almost always all below: a predictable branch); every peak found is refined too.
    """
    M = buf.shape[0]
    best = _refine_node(buf, j0, sgn, h, c, zr, zi, nh, stol)
    thr = best - bound
    # the run of nodes above thr around j0: offsets -lo < k < hi
    lo = 1
    j = j0 - 1 if j0 > 0 else M - 1
    while lo < M and sgn * buf[j] > thr:
        lo += 1
        j = j - 1 if j > 0 else M - 1
    hi = 1
    j = j0 + 1 if j0 < M - 1 else 0
    while hi < M - lo + 1 and sgn * buf[j] > thr:
        hi += 1
        j = j + 1 if j < M - 1 else 0
    j = j0 - lo + 1
    if j < 0:
        j += M
    for _k in range(lo + hi - 1):  # inside the run: any other discrete peak
        if j != j0:
            vp, v, vn = _nb(buf, j, sgn)
            if v >= vp and v >= vn:
                r = _refine_node(buf, j, sgn, h, c, zr, zi, nh, stol)
                if r > best:
                    best = r
        j = j + 1 if j < M - 1 else 0
    above = 0
    for k in range(M):  # branchless count of nodes above thr (vectorised)
        above += sgn * buf[k] > thr
    if above <= lo + hi - 1:  # all of them in the run: nothing outside can win
        return sgn * best
    for _k in range(M - lo - hi + 1):  # outside the run: j continues after its right end
        if sgn * buf[j] > thr:
            vp, v, vn = _nb(buf, j, sgn)
            if v >= vp and v >= vn:
                r = _refine_node(buf, j, sgn, h, c, zr, zi, nh, stol)
                if r > best:
                    best = r
        j = j + 1 if j < M - 1 else 0
    return sgn * best


@njit(cache=True, nogil=True)
def _argmax_argmin(buf):
    """Indices of the largest and smallest node; four independent lanes with selects (no
    data-dependent branches), ~2x faster than the plain loop. len(buf) is a multiple of 4."""
    M = buf.shape[0]
    a0 = a1 = a2 = a3 = -np.inf
    b0 = b1 = b2 = b3 = np.inf
    i0 = i1 = i2 = i3 = 0
    k0 = k1 = k2 = k3 = 0
    for j in range(0, M, 4):
        v = buf[j]
        t = v > a0
        a0 = v if t else a0
        i0 = j if t else i0
        t = v < b0
        b0 = v if t else b0
        k0 = j if t else k0
        v = buf[j + 1]
        t = v > a1
        a1 = v if t else a1
        i1 = j + 1 if t else i1
        t = v < b1
        b1 = v if t else b1
        k1 = j + 1 if t else k1
        v = buf[j + 2]
        t = v > a2
        a2 = v if t else a2
        i2 = j + 2 if t else i2
        t = v < b2
        b2 = v if t else b2
        k2 = j + 2 if t else k2
        v = buf[j + 3]
        t = v > a3
        a3 = v if t else a3
        i3 = j + 3 if t else i3
        t = v < b3
        b3 = v if t else b3
        k3 = j + 3 if t else k3
    if a1 > a0:
        a0 = a1
        i0 = i1
    if a3 > a2:
        a2 = a3
        i2 = i3
    if a2 > a0:
        i0 = i2
    if b1 < b0:
        b0 = b1
        k0 = k1
    if b3 < b2:
        b2 = b3
        k2 = k3
    if b2 < b0:
        k0 = k2
    return i0, k0


@njit(cache=True, nogil=True)
def _extremes_one(c, zr, zi, nh, stab, ctab, buf, h, curv):
    """max f and min f over one period, exact (dense grid, pruning bound, Newton refinement)."""
    M = buf.shape[0]
    G = nh.shape[0]
    for j in range(M):
        buf[j] = c
    for g in range(G):  # contiguous inner loop: vectorised
        a = zr[g]
        b = zi[g]
        for j in range(M):
            buf[j] += a * stab[g, j] + b * ctab[g, j]
    jmax, jmin = _argmax_argmin(buf)
    # the most a true extremum can exceed its nearest node (f' = 0 there): h²/8 max|f''|
    bound = 0.0
    s1 = 0.0
    s4 = 0.0
    for g in range(G):
        a = math.sqrt(zr[g] * zr[g] + zi[g] * zi[g])
        n2 = nh[g] * nh[g]
        bound += a * n2
        s1 += a
        s4 += a * n2 * n2
    bound *= curv
    # Taylor-stop step: Σ|Z| n⁴ stol⁴ / 24 <= 1e-13 Σ|Z|, and never above 1e-3 rad
    stol = min(1e-3, (2.4e-12 * s1 / s4) ** 0.25) if s4 > 0.0 else 1e-3
    best_max = _best_extremum(buf, jmax, 1.0, h, bound, c, zr, zi, nh, stol)
    best_min = _best_extremum(buf, jmin, -1.0, h, bound, c, zr, zi, nh, stol)
    return best_max, best_min


@njit(cache=True, nogil=True)
def _tables(nh, M):
    G = nh.shape[0]
    stab = np.empty((G, M))
    ctab = np.empty((G, M))
    h = 2.0 * math.pi / M
    for g in range(G):
        for j in range(M):
            stab[g, j] = math.sin(nh[g] * j * h)
            ctab[g, j] = math.cos(nh[g] * j * h)
    return stab, ctab, h


@njit(cache=True, nogil=True)
def _extremes_batch(c, zr, zi, nh, M):
    n = c.shape[0]
    stab, ctab, h = _tables(nh, M)
    buf = np.empty(M)
    curv = h * h / 8.0
    fmax = np.empty(n)
    fmin = np.empty(n)
    for i in range(n):
        fmax[i], fmin[i] = _extremes_one(c[i], zr[i], zi[i], nh, stab, ctab, buf, h, curv)
    return fmax, fmin


def exact_extremes(
    c: np.ndarray, Z: np.ndarray, harmonics: Sequence[int]
) -> tuple[np.ndarray, np.ndarray]:
    """Exact max and min over one common period of ``f(u) = c + Σ_g Im(Z_g e^{i n_g u})``.

    Parameters
    ----------
    c : ndarray, shape (n,)
        Constant part [mm].
    Z : ndarray of complex, shape (n, G)
        Phasors per harmonic [mm].
    harmonics : sequence of int
        Harmonic numbers n_g (>= 1).

    Returns
    -------
    fmax, fmin : ndarray, shape (n,)
        [mm]. The coupled-TE *amplitude* is ``max(fmax, -fmin)`` (= max |Σe(t)|, Wang 2013's
        amplitude of the coupled error) and the peak-to-peak ``fmax - fmin``.

    Notes
    -----
    Dense stage on ``M = 8 n_max`` nodes (h = 2 pi / M). The best node is refined by Halley
    iteration on f' (parabolic start; stop when the step is below a tolerance chosen so that the
    third-order Taylor value is within 1e-13 Σ|Z| of f there). A true maximum can exceed its
    nearest node by at most ``h²/8 Σ|Z_g| n_g²`` (f' = 0 there), so every other discrete peak
    whose node lies within that bound of the refined value is refined too (golden-section
    fallback if an iteration leaves its bracket). This is exact (to ~1e-13 relative) provided two
    local maxima of f are never closer than two nodes (a quarter period of the highest harmonic);
    measured against a 2^15-point grid refined from every local extremum: < 1e-13 relative.
    Compiled with numba; :func:`exact_extremes_numpy` is the plain twin.
    """
    nh = np.ascontiguousarray(np.asarray(harmonics, dtype=np.int64))
    c = np.ascontiguousarray(np.atleast_1d(np.asarray(c, dtype=float)))
    Z = np.atleast_2d(np.asarray(Z, dtype=complex))
    if nh.size == 0:
        return c.copy(), c.copy()
    if np.any(nh < 1):
        raise ParameterError("harmonics", harmonics, "must be integers >= 1")
    M = _grid_points(nh)
    return _extremes_batch(c, np.ascontiguousarray(Z.real), np.ascontiguousarray(Z.imag), nh, M)


def exact_extremes_numpy(
    c: np.ndarray,
    Z: np.ndarray,
    harmonics: Sequence[int],
    iterations: int = 30,
    points: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Plain-numpy twin of :func:`exact_extremes`: grid of ``points`` (default 8 n_max) nodes,
    Newton from *every* discrete local extremum (no pruning), vectorised; used to test the
    compiled kernel and, with a fine grid, as the reference of the benchmark."""
    nh = np.asarray(harmonics, dtype=np.int64)
    c = np.atleast_1d(np.asarray(c, dtype=float))
    Z = np.atleast_2d(np.asarray(Z, dtype=complex))
    if nh.size == 0:
        return c.copy(), c.copy()
    M = _grid_points(nh) if points is None else int(points)
    h = 2 * np.pi / M
    u = np.arange(M) * h

    def fd(rows: np.ndarray, uu: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        e = np.exp(1j * nh * uu[..., None]) * Z[rows]
        f = c[rows] + e.imag.sum(-1)
        d1 = (nh * e.real).sum(-1)
        d2 = -(nh**2 * e.imag).sum(-1)
        return f, d1, d2

    f = c[:, None] + (Z.real @ np.sin(np.outer(nh, u)) + Z.imag @ np.cos(np.outer(nh, u)))
    out = []
    for sgn in (1.0, -1.0):
        g = sgn * f
        is_ext = (g >= np.roll(g, 1, axis=1)) & (g >= np.roll(g, -1, axis=1))
        rows, cols = np.nonzero(is_ext)  # Newton from every discrete local extremum
        u0 = u[cols]
        uu = u0.copy()
        for _ in range(iterations):
            _, d1, d2 = fd(rows, uu)
            step = np.where(sgn * d2 < 0, -d1 / np.where(d2 == 0, 1.0, d2), 0.0)
            uu = np.clip(uu + step, u0 - h, u0 + h)
        fr, _, _ = fd(rows, uu)
        val = np.maximum(sgn * fr, g[rows, cols])
        best = np.full(len(c), -np.inf)
        np.maximum.at(best, rows, val)
        out.append(sgn * best)
    return out[0], out[1]


def grid_extremes_numpy(
    c: np.ndarray, Z: np.ndarray, harmonics: Sequence[int], points: int = 2048
) -> tuple[np.ndarray, np.ndarray]:
    """Naive fixed-grid max/min over one period (``points`` nodes, no refinement) [mm];
    the baseline of ``benchmarks/bench_planetary_mc.py``."""
    nh = np.asarray(harmonics, dtype=np.int64)
    c = np.atleast_1d(np.asarray(c, dtype=float))
    Z = np.atleast_2d(np.asarray(Z, dtype=complex))
    u = np.arange(points) * (2 * np.pi / points)
    E = np.exp(1j * np.outer(nh, u))  # (G, P)
    f = c[:, None] + (Z.real @ E.imag + Z.imag @ E.real)
    return f.max(axis=1), f.min(axis=1)


# --------------------------------------------------------------------------- sample kernel
@njit(cache=True, nogil=True)
def _sample_kernel(mags, angs, gain, mag_idx, ang_idx, coeff, phase, fsign, group, nh, M):
    """Phasor sums and exact extremes for each sample (row) of magnitudes and angles."""
    n = mags.shape[0]
    G = nh.shape[0]
    K = gain.shape[0]
    V = angs.shape[1]
    stab, ctab, h = _tables(nh, M)
    buf = np.empty(M)
    curv = h * h / 8.0
    zr = np.empty(G)
    zi = np.empty(G)
    ca = np.empty(V)
    sa = np.empty(V)
    c0 = np.empty(K)
    s0 = np.empty(K)
    for k in range(K):
        c0[k] = math.cos(phase[k])
        s0[k] = math.sin(phase[k])
    fmax = np.empty(n)
    fmin = np.empty(n)
    for i in range(n):
        for v in range(V):  # one sine/cosine per angle, shared by its terms
            ca[v] = math.cos(angs[i, v])
            sa[v] = math.sin(angs[i, v])
        c = 0.0
        for g in range(G):
            zr[g] = 0.0
            zi[g] = 0.0
        for k in range(K):
            a = gain[k] * mags[i, mag_idx[k]]
            if ang_idx[k] >= 0:  # phase + coeff * theta, coeff = ±1
                cp = c0[k] * ca[ang_idx[k]] - coeff[k] * s0[k] * sa[ang_idx[k]]
                sp = s0[k] * ca[ang_idx[k]] + coeff[k] * c0[k] * sa[ang_idx[k]]
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
        if G == 0:
            fmax[i] = c
            fmin[i] = c
        else:
            fmax[i], fmin[i] = _extremes_one(c, zr, zi, nh, stab, ctab, buf, h, curv)
    return fmax, fmin


def sample_extremes(
    terms: TermSet, magnitudes: np.ndarray, angles: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Exact max and min of Σe(t) [mm] for each row of ``magnitudes`` [mm] and ``angles`` [rad]
    (shapes (n, len(terms.magnitudes)) and (n, len(terms.angles))), in one compiled pass."""
    arr = _term_arrays(terms)
    m = np.ascontiguousarray(np.atleast_2d(np.asarray(magnitudes, dtype=float)))
    th = np.ascontiguousarray(np.atleast_2d(np.asarray(angles, dtype=float)))
    if th.shape[1] == 0:
        th = np.zeros((m.shape[0], 1))
    nh = arr["harmonics"]
    M = _grid_points(nh) if nh.size else 16
    return _sample_kernel(
        m,
        th,
        arr["gain"],
        arr["mag_idx"],
        arr["ang_idx"],
        arr["coeff"],
        arr["phase"],
        arr["fsign"],
        arr["group"],
        nh,
        M,
    )


# --------------------------------------------------------------------------- coupled TE
@dataclass(frozen=True)
class CoupledTE:
    """Coupled transmission error of one assembly.

    Attributes
    ----------
    constant : float
        Zero-frequency part of Σe [mm].
    harmonics : tuple of int
        Harmonic numbers n_g of the groups (u = q0 w_in t).
    frequencies : tuple of Fraction
        Group frequencies as multiples of the input speed.
    phasors : ndarray of complex
        Group phasors Z_g [mm] (amplitude |Z_g|, initial phase arg Z_g).
    fmax, fmin : float
        Exact max and min of Σe over the common period [mm].
    scale : float
        Output rotation per mm [rad/mm].
    q0 : Fraction
        Fundamental frequency (common period = 1/q0 input revolutions).
    """

    constant: float
    harmonics: tuple[int, ...]
    frequencies: tuple[Fraction, ...]
    phasors: np.ndarray
    fmax: float
    fmin: float
    scale: float
    q0: Fraction

    @property
    def amplitude(self) -> float:
        """max over the common period of |Σe(t)| times |scale| [rad]."""
        return max(self.fmax, -self.fmin) * abs(self.scale)

    @property
    def peak_to_peak(self) -> float:
        """(max - min) of Σe(t) over the common period times |scale| [rad]."""
        return (self.fmax - self.fmin) * abs(self.scale)

    @property
    def amplitude_sum(self) -> float:
        """Wang 2013 §1(3) approximation (lambda_i = 1 across frequencies):
        ``|c| + Σ_g |Z_g|`` times |scale| [rad]; an upper bound of :attr:`amplitude`."""
        return (abs(self.constant) + float(np.abs(self.phasors).sum())) * abs(self.scale)

    def signal(self, u: np.ndarray) -> np.ndarray:
        """Σe(u) [mm] at the phase u = q0 w_in t [rad] of the common period."""
        u = np.asarray(u, dtype=float)
        nh = np.asarray(self.harmonics)
        return self.constant + (self.phasors * np.exp(1j * nh * u[..., None])).imag.sum(-1)


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
    mags = _vector(terms.magnitudes, magnitudes, "magnitudes", required=True)
    angs = _vector(terms.angles, angles, "angles", required=False)
    q0, harm, _ = frequency_basis(terms)
    c, Z = group_phasors(terms, mags, angs)
    fmax, fmin = exact_extremes(np.array([c]), Z[None, :], harm)
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


def _vector(keys: Sequence[str], values: Mapping[str, float], what: str, required: bool):
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
