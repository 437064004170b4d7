"""Closed-form stiffness of each element of an RV reducer's load path.

Every function is a pure, vectorised function of arrays (mm, N, N·mm, MPa, rad). They are the
elements of the RV stiffness chain (``docs/rv-stiffness-chain.md``):

=====================  ============================================  ==========================
element                closed form                                   reference
=====================  ============================================  ==========================
roller–race contact    ``δ = 3.84e-5 Q^0.9 / l^0.8``                 Palmgren 1959; Harris &
                                                                     Kotzalas 2007, ch. 6
roller bearing         Stribeck ``Q_max = 4.08 F_r / (Z cos α)``,    Harris & Kotzalas 2007
(crank needle, main)   ``δ_r = 2 δ(Q_max) / cos α``
pin–housing seat       Palmgren line contact of the pin in its       Harris & Kotzalas 2007
                       semicircular groove, tangent at the pin load  (outer race = conformal)
pin / crank bending    simply supported beam, point load, bending    Roark (Young & Budynas
                       ``a² b² / (3 E I L)`` + shear                 2002) Table 8.1 case 1e,
                       ``F_s a b / (G A L)``                         section 8.10
crank torsion          ``k_t = G π d⁴ / (32 L)``                     Shigley eq 4-5
first-stage mesh       ``c_γ b``                                     ISO 6336-1:2019, 9.3
series / shares        ``C = Σ C_i``, share ``C_i / C``              —
=====================  ============================================  ==========================

Domain (checked where it can be): Palmgren's formula is an empirical fit for hardened steel
rollers on steel races (E ≈ 206 GPa) and holds for the convex inner race and the concave
(conformal) outer race alike, because the approach of a line contact depends only weakly
(logarithmically) on the radii; it is used here for the pin in its housing groove, which is such
a concave seat. The beam formulas hold for small deflections of a slender-to-stubby round bar
(shear is included, so ``L/d`` down to about 1 is acceptable).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.units import um_to_mm

__all__ = [
    "PALMGREN_LINE_COEFFICIENT",
    "STRIBECK_LINE_CONTACT",
    "ROARK_SHEAR_FORM_FACTOR_ROUND",
    "palmgren_line_deflection",
    "palmgren_line_stiffness",
    "stribeck_max_roller_load",
    "roller_bearing_radial_stiffness",
    "pin_seat_stiffness",
    "ideal_peak_pin_force",
    "shear_modulus",
    "beam_point_compliance",
    "disc_load_positions",
    "shaft_torsional_stiffness",
    "iso6336_mesh_stiffness",
    "series_compliance",
    "compliance_shares",
]

#: Palmgren's line-contact constant for steel on steel [mm^1.7 / N^0.9]: ``δ = c Q^0.9 / l^0.8``
#: with δ [mm], Q [N], l [mm] (Harris & Kotzalas 2007, eq. for line contact; Palmgren 1959).
PALMGREN_LINE_COEFFICIENT = 3.84e-5
#: Stribeck's factor of the most loaded roller of a zero-clearance line-contact bearing
#: ``Q_max = 4.08 F_r / (Z cos α)`` (Harris & Kotzalas 2007, ch. 7; 4.37 for point contact).
STRIBECK_LINE_CONTACT = 4.08
#: Roark's form factor ``F_s`` of the shear deflection of a solid round section (10/9).
ROARK_SHEAR_FORM_FACTOR_ROUND = 10.0 / 9.0


def _positive(name: str, value: ArrayLike) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
        raise ParameterError(name, value, "must be finite and > 0")
    return arr


def palmgren_line_deflection(load: ArrayLike, length: ArrayLike) -> np.ndarray:
    """Approach of one steel line contact [mm] from Palmgren's formula.

    Parameters
    ----------
    load : array_like
        Contact force ``Q`` [N], ``>= 0``.
    length : array_like
        Effective contact length ``l`` [mm].

    Returns
    -------
    numpy.ndarray
        ``δ = 3.84e-5 Q^0.9 / l^0.8`` [mm].

    References
    ----------
    Palmgren A. (1959) *Ball and Roller Bearing Engineering*, 3rd ed., Burbank, Philadelphia.
    Harris T.A., Kotzalas M.N. (2007) *Rolling Bearing Analysis*, 5th ed., vol. 1, ch. 6
    (approximate load–deflection of a line contact). doi:10.1201/9781420006582

    Examples
    --------
    >>> round(float(palmgren_line_deflection(1000.0, 10.0)) * 1e3, 3)  # µm
    3.05
    """
    q = np.asarray(load, dtype=float)
    if not np.all(np.isfinite(q)) or np.any(q < 0.0):
        raise ParameterError("load", load, "must be finite and >= 0 N")
    ll = _positive("length", length)
    return PALMGREN_LINE_COEFFICIENT * q**0.9 / ll**0.8


def palmgren_line_stiffness(
    load: ArrayLike, length: ArrayLike, linearisation: str = "tangent"
) -> np.ndarray:
    """Stiffness of one steel line contact [N/mm], Palmgren's law linearised at ``load``.

    Parameters
    ----------
    load : array_like
        Contact force ``Q`` [N] at which the law is linearised, ``> 0``.
    length : array_like
        Contact length ``l`` [mm].
    linearisation : {"tangent", "secant"}
        ``"tangent"``: ``dQ/dδ = Q / (0.9 δ(Q))``; ``"secant"``: ``Q / δ(Q)``.

    Returns
    -------
    numpy.ndarray
        Stiffness [N/mm].

    Notes
    -----
    ``δ = c Q^0.9 / l^0.8`` gives ``dδ/dQ = 0.9 c Q^-0.1 / l^0.8 = 0.9 δ / Q``.

    References
    ----------
    Harris T.A., Kotzalas M.N. (2007) *Rolling Bearing Analysis*, 5th ed., ch. 6.
    doi:10.1201/9781420006582
    """
    q = _positive("load", load)
    delta = palmgren_line_deflection(q, length)
    if linearisation == "tangent":
        return q / (0.9 * delta)
    if linearisation == "secant":
        return q / delta
    raise ParameterError("linearisation", linearisation, "must be 'tangent' or 'secant'")


def stribeck_max_roller_load(
    radial_load: ArrayLike, rollers: ArrayLike, contact_angle: ArrayLike = 0.0
) -> np.ndarray:
    """Load of the most loaded roller of a zero-clearance roller bearing [N] (Stribeck).

    Parameters
    ----------
    radial_load : array_like
        Bearing radial load ``F_r`` [N].
    rollers : array_like
        Number of rollers of one row ``Z`` [-], ``>= 3``.
    contact_angle : array_like
        Contact angle ``α`` [rad] in ``[0, π/2)``.

    Returns
    -------
    numpy.ndarray
        ``Q_max = 4.08 F_r / (Z cos α)`` [N].

    References
    ----------
    Stribeck R. (1901); Harris T.A., Kotzalas M.N. (2007) *Rolling Bearing Analysis*, 5th ed.,
    ch. 7 (radially loaded bearings). doi:10.1201/9781420006582
    """
    z = np.asarray(rollers, dtype=float)
    if np.any(z < 3) or np.any(z != np.round(z)):
        raise ParameterError("rollers", rollers, "must be an integer >= 3")
    ca = np.asarray(contact_angle, dtype=float)
    if not np.all(np.isfinite(ca)) or np.any(ca < 0.0) or np.any(ca >= np.pi / 2):
        raise ParameterError("contact_angle", contact_angle, "must be in [0, 90) deg")
    fr = _positive("radial_load", radial_load)
    return STRIBECK_LINE_CONTACT * fr / (z * np.cos(ca))


def roller_bearing_radial_stiffness(
    rollers: ArrayLike,
    roller_length: ArrayLike,
    radial_load: ArrayLike,
    contact_angle: ArrayLike = 0.0,
    rows: ArrayLike = 1,
    linearisation: str = "secant",
) -> np.ndarray:
    """Radial stiffness [N/mm] of a roller (needle) bearing from its roller data.

    Parameters
    ----------
    rollers : array_like
        Rollers per row ``Z`` [-].
    roller_length : array_like
        Effective roller length ``l`` [mm].
    radial_load : array_like
        Radial load ``F_r`` on the whole bearing at which it is linearised [N].
    contact_angle : array_like
        Contact angle ``α`` [rad] (0 for a radial needle bearing; the angle of a tapered or
        angular-contact roller row).
    rows : array_like
        Number of identical rows sharing ``F_r`` (a pair of main bearings: 2) [-].
    linearisation : {"secant", "tangent"}
        ``F_r / δ_r`` (secant, the stiffness of a load applied from zero) or ``dF_r / dδ_r``.

    Returns
    -------
    numpy.ndarray
        Radial stiffness [N/mm].

    Notes
    -----
    The most loaded roller carries ``Q_max = 4.08 (F_r / rows) / (Z cos α)`` (Stribeck); inner
    and outer race contacts each approach ``δ(Q_max) = 3.84e-5 Q_max^0.9 / l^0.8`` (Palmgren),
    the ring's radial deflection is ``δ_r = 2 δ(Q_max) / cos α``. ``δ_r ∝ F_r^0.9``, so the
    tangent stiffness is the secant / 0.9.

    References
    ----------
    Palmgren A. (1959) *Ball and Roller Bearing Engineering*, 3rd ed.; Harris T.A., Kotzalas
    M.N. (2007) *Rolling Bearing Analysis*, 5th ed., ch. 6–7. doi:10.1201/9781420006582

    Examples
    --------
    >>> round(float(roller_bearing_radial_stiffness(16, 14.0, 5000.0)) / 1e5, 2)
    8.62
    """
    nrow = np.asarray(rows, dtype=float)
    if np.any(nrow < 1) or np.any(nrow != np.round(nrow)):
        raise ParameterError("rows", rows, "must be an integer >= 1")
    fr = _positive("radial_load", radial_load)
    ca = np.asarray(contact_angle, dtype=float)
    q_max = stribeck_max_roller_load(fr / nrow, rollers, ca)
    delta_r = 2.0 * palmgren_line_deflection(q_max, roller_length) / np.cos(ca)
    k = fr / delta_r
    if linearisation == "secant":
        return k
    if linearisation == "tangent":
        return k / 0.9
    raise ParameterError("linearisation", linearisation, "must be 'secant' or 'tangent'")


def pin_seat_stiffness(pin_load: ArrayLike, seat_length: ArrayLike) -> np.ndarray:
    """Stiffness [N/mm] of a pin pressed into its semicircular housing groove (pin seat).

    The pin and its groove are a concave (conformal) steel line contact: Palmgren's line-contact
    law, which bearing practice applies to the roller on the concave outer race, linearised
    (tangent) at the pin load.

    Parameters
    ----------
    pin_load : array_like
        Pin force at which the seat is linearised [N] (the largest pin force at rated torque).
    seat_length : array_like
        Length over which the pin bears on its groove [mm].

    Returns
    -------
    numpy.ndarray
        ``dF/dδ = F / (0.9 · 3.84e-5 F^0.9 / l^0.8)`` [N/mm].

    Notes
    -----
    Hertz's line-contact formula does not apply to a pin in a groove of nearly its own radius:
    the half width ``b = sqrt(4 F R / (π l E*))`` with ``R = r R_g / (R_g − r)`` grows without
    bound as the clearance ``R_g − r`` vanishes, beyond the ``b << R`` the theory needs. The
    approach of a line contact depends on the radii only through a logarithm, and Palmgren's
    empirical formula (fitted on roller bearings, whose outer-race contact is concave) carries
    none; it is the closed form used here.

    References
    ----------
    Harris T.A., Kotzalas M.N. (2007) *Rolling Bearing Analysis*, 5th ed., ch. 6.
    doi:10.1201/9781420006582. Johnson K.L. (1985) *Contact Mechanics*, §4.3, §5.3 (conforming
    pin in a hole). doi:10.1017/CBO9781139171731

    Examples
    --------
    >>> round(float(pin_seat_stiffness(3000.0, 26.0)) / 1e5, 2)
    8.73
    """
    return palmgren_line_stiffness(pin_load, seat_length, "tangent")


def ideal_peak_pin_force(
    torque: ArrayLike, share: ArrayLike, K1: float, z_c: int, r_p: float
) -> np.ndarray:
    """Largest pin force of an ideal (error-free, zero-clearance) load share [N].

    Parameters
    ----------
    torque : array_like
        Output torque of the cycloid stage [N·mm].
    share : array_like
        Share of the torque on one disc [-].
    K1 : float
        Short-width coefficient ``a z_p / r_p`` [-].
    z_c : int
        Disc teeth [-].
    r_p : float
        Pin-circle radius [mm].

    Returns
    -------
    numpy.ndarray
        ``F_max = 4 share T / (K1 z_c r_p)`` (Hu 2020 eq 30) [N].

    References
    ----------
    Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481, eq 30.
    doi:10.3390/app10020481
    """
    if not 0.0 < K1 < 1.0:
        raise ParameterError("K1", K1, "must be in (0, 1)")
    t = np.asarray(torque, dtype=float)
    return 4.0 * np.asarray(share, dtype=float) * t / (K1 * z_c * r_p)


def shear_modulus(youngs_modulus: ArrayLike, poisson_ratio: ArrayLike) -> np.ndarray:
    """``G = E / (2 (1 + ν))`` [MPa] of an isotropic material.

    Parameters
    ----------
    youngs_modulus : array_like
        ``E`` [MPa].
    poisson_ratio : array_like
        ``ν`` [-], in ``[0, 0.5)``.

    Returns
    -------
    numpy.ndarray
        ``G`` [MPa].
    """
    e = _positive("youngs_modulus", youngs_modulus)
    nu = np.asarray(poisson_ratio, dtype=float)
    if np.any(nu < 0.0) or np.any(nu >= 0.5):
        raise ParameterError("poisson_ratio", poisson_ratio, "must be in [0, 0.5)")
    return e / (2.0 * (1.0 + nu))


def beam_point_compliance(
    span: ArrayLike,
    position: ArrayLike,
    diameter: ArrayLike,
    youngs_modulus: ArrayLike,
    poisson_ratio: ArrayLike,
    shear: bool = True,
) -> np.ndarray:
    """Deflection per unit load under a point load on a simply supported round bar [mm/N].

    Parameters
    ----------
    span : array_like
        Distance between the supports ``L`` [mm].
    position : array_like
        Distance of the load from one support ``a`` [mm], ``0 < a < L``.
    diameter : array_like
        Bar diameter ``d`` [mm].
    youngs_modulus : array_like
        ``E`` [MPa].
    poisson_ratio : array_like
        ``ν`` [-] (shear modulus ``G = E / (2 (1 + ν))``).
    shear : bool
        Add the shear deflection (Timoshenko; matters for stubby pins, ``L/d < 10``).

    Returns
    -------
    numpy.ndarray
        ``y / W = a² b² / (3 E I L) + F_s a b / (G A L)`` [mm/N], ``b = L − a``,
        ``I = π d⁴ / 64``, ``A = π d² / 4``, ``F_s = 10/9``.

    References
    ----------
    Young W.C., Budynas R.G. (2002) *Roark's Formulas for Stress and Strain*, 7th ed.,
    Table 8.1 case 1e (simply supported, intermediate load: ``y_a = −W a² b² / (3 E I l)``)
    and section 8.10 (shear deflection, form factor ``F = 10/9`` for a solid circle).

    Examples
    --------
    >>> round(float(beam_point_compliance(40.0, 20.0, 10.0, 2.06e5, 0.3, shear=False)) * 1e6, 3)
    13.186
    """
    L = _positive("span", span)
    a = _positive("position", position)
    if np.any(a >= L):
        raise ParameterError("position", position, "must lie strictly between the supports")
    d = _positive("diameter", diameter)
    E = _positive("youngs_modulus", youngs_modulus)
    b = L - a
    inertia = np.pi * d**4 / 64.0
    c = a * a * b * b / (3.0 * E * inertia * L)
    if shear:
        area = np.pi * d * d / 4.0
        c = c + ROARK_SHEAR_FORM_FACTOR_ROUND * a * b / (shear_modulus(E, poisson_ratio) * area * L)
    return c


def disc_load_positions(span: float, discs: int, face_width: float) -> np.ndarray:
    """Where the ``discs`` adjacent discs (centred in ``span``) load a pin or crank [mm].

    Parameters
    ----------
    span : float
        Distance between the supports [mm].
    discs : int
        Number of discs ``N`` [-].
    face_width : float
        Disc width ``b`` [mm].

    Returns
    -------
    numpy.ndarray
        ``(N,)`` distance of disc ``j``'s mid-plane from the first support [mm]:
        ``L/2 + (j − (N − 1)/2) b``.

    Raises
    ------
    ParameterError
        ``span`` shorter than the discs' total width ``N b``.
    """
    if not np.isfinite(span) or span <= discs * face_width:
        raise ParameterError(
            "span", span, f"must exceed the discs' total width {discs} × {face_width} mm"
        )
    return span / 2.0 + (np.arange(discs) - (discs - 1) / 2.0) * face_width


def shaft_torsional_stiffness(
    diameter: ArrayLike, length: ArrayLike, youngs_modulus: ArrayLike, poisson_ratio: ArrayLike
) -> np.ndarray:
    """Torsional stiffness of a solid round shaft [N·mm/rad].

    Parameters
    ----------
    diameter : array_like
        ``d`` [mm].
    length : array_like
        Twisted length ``L`` [mm] (for a crank: planet gear to the cams).
    youngs_modulus, poisson_ratio : array_like
        ``E`` [MPa], ``ν`` [-].

    Returns
    -------
    numpy.ndarray
        ``k_t = G J / L``, ``J = π d⁴ / 32`` [N·mm/rad].

    References
    ----------
    Budynas R.G., Nisbett J.K. (2011) *Shigley's Mechanical Engineering Design*, 9th ed.,
    eq. 4-5 (``θ = T l / (G J)``).

    Examples
    --------
    >>> round(float(shaft_torsional_stiffness(20.0, 50.0, 2.06e5, 0.3)) / 1e7, 4)
    2.4891
    """
    d = _positive("diameter", diameter)
    L = _positive("length", length)
    return shear_modulus(youngs_modulus, poisson_ratio) * np.pi * d**4 / 32.0 / L


def iso6336_mesh_stiffness(face_width: ArrayLike, c_gamma: ArrayLike = 20.0) -> np.ndarray:
    """Mean involute mesh stiffness [N/mm] = ``c_gamma`` [N/(mm·µm)] × face width [mm].

    ISO 6336-1:2019, 9.3 gives ``c_gamma ≈ 20 N/(mm·µm)`` for solid steel spur gears.

    Parameters
    ----------
    face_width : array_like
        Face width of the mesh [mm].
    c_gamma : array_like
        Mesh stiffness per face width [N/(mm·µm)].

    Returns
    -------
    numpy.ndarray
        Mean mesh stiffness along the line of action [N/mm].

    References
    ----------
    ISO 6336-1:2019, clause 9.3.

    Examples
    --------
    >>> float(iso6336_mesh_stiffness(10.0))
    200000.0
    """
    b = _positive("face_width", face_width)
    cg = _positive("c_gamma", c_gamma)
    return cg * b / um_to_mm(1.0)  # N/µm -> N/mm


def series_compliance(*compliances: ArrayLike) -> np.ndarray:
    """Compliance of elements in series [any unit of compliance]: ``C = Σ C_i``.

    ``None`` entries (elements left out) are skipped.
    """
    total = np.asarray(0.0)
    for c in compliances:
        if c is None:
            continue
        arr = np.asarray(c, dtype=float)
        if not np.all(np.isfinite(arr)) or np.any(arr < 0.0):
            raise ParameterError("compliance", c, "must be finite and >= 0")
        total = total + arr
    return total


def compliance_shares(compliances: dict[str, float]) -> dict[str, float]:
    """Share of the total of each element's compliance [-], summing to 1.

    Parameters
    ----------
    compliances : dict
        Element name → its contribution to a total compliance [any one unit of compliance,
        e.g. rad/(N·mm)], ``>= 0``.

    Returns
    -------
    dict
        Element name → ``C_i / Σ C``.
    """
    vals = {k: float(v) for k, v in compliances.items()}
    if any(not np.isfinite(v) or v < 0.0 for v in vals.values()):
        raise ParameterError("compliances", compliances, "must be finite and >= 0")
    total = float(np.sum(list(vals.values())))
    if total <= 0.0:
        raise ParameterError("compliances", compliances, "sum to zero: nothing is compliant")
    return {k: v / total for k, v in vals.items()}
