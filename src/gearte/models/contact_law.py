"""Pin–disc contact laws: normal approach δ(F), its inverse, stiffness and Hertz pressure.

The one place where gearte computes how far a pin and a cycloid flank approach under a force.
Every user of a pin-contact law — the cycloid-stage tooth contact
(:mod:`gearte.models.cycloid_contact`), the RV load-sharing solver
(:mod:`gearte.solvers.rv_equilibrium`, through the coefficients returned here) and the Li 2023
loaded contact (:mod:`gearte.models.cycloid_loaded_contact`) — calls this module. A law is chosen
by name:

``"line_contact"`` (default)
    The textbook approach of two elastic cylinders in line contact (Johnson 1985, §5.6; the same
    law as Li et al. 2023 eq 2)::

        δ = (2 F (1 − ν²) / (π E b)) · (ln(4 |ρ| / a) + ln(4 r / a) − 1)
        a = (4 F R* / (π b E*))^½,   1/R* = 1/r − 1/ρ,   1/E* = 2 (1 − ν²)/E

    a the Hertz half-width of the contact strip, ρ the signed flank curvature radius
    (ρ < 0 convex, ρ > 0 concave, as :func:`gearte.geometry.cycloid.curvature_radius`), r the
    pin radius, b the face width; disc and pin of the same material.
``"hu2020"``
    Hu et al. 2020 eq 38–39 as printed, constant 4.99e-3 in the "half-width"::

        δ = (2 F (1 − μ²) / (π E b)) · (2/3 + ln(16 r |ρ| / c²))
        c = 4.99e-3 · (4 (1 − μ²) F |ρ| r / (E b (|ρ| + r)))^½

    It is the shape of Roark's two-cylinder formula (c the full band width, constant 1.60) with
    1.60 replaced by 4.99e-3 — a factor 320.6 in c, i.e. ln(320.6²) = 11.54 more in the bracket:
    on the Hu 2020 stage the pin approach is 1.95× the textbook value. Kept because it is what
    reproduces Hu 2020's Tables 4–5 and 7–8. See docs/contact-law.md.

``"palmgren"``
    Palmgren's empirical line-contact law of a steel roller on a steel raceway (Palmgren 1959;
    Harris & Kotzalas 2007, eq 7.4), the law Han et al. 2023 name for their springs::

        δ = 3.84e-5 · F^0.9 / l^0.8        (δ in mm, F in N, l in mm)

    l the contact length (here the face width b). It does not depend on the curvatures, nor on
    E and ν: it is a fit to steel, and is refused for a material whose E is not a steel's
    (:data:`PALMGREN_STEEL_E_RANGE_MPA`).

Both logarithmic laws have the form ``δ(F) = F (a0 − a1 ln F)`` with
``a1 = 2 (1 − ν²)/(π E b)`` (F in N, δ in mm); :func:`log_law_coefficients` returns ``(a0, a1)``.
Every law, Palmgren's included, has the form ``δ(F) = F (a0 − a1 ln F) + a2 F^a3``
(:func:`law_coefficients` returns ``(a0, a1, a2, a3)``; Palmgren: ``a0 = a1 = 0``,
``a2 = 3.84e-5 / l^0.8``, ``a3 = 0.9``), so that solvers can evaluate any law without knowing
which one it is; a linear series compliance adds to ``a0``.

Units: mm, N, MPa. Every function checks its material (:func:`check_material`): E from the
plausibility floor of a Young's modulus (1 000 MPa, ``gearte.limits.FLOORS``) to
:data:`MAX_YOUNGS_MODULUS_MPA`, ν in [0, 0.5), each error naming the argument.

References
----------
Johnson K.L. (1985). Contact Mechanics. Cambridge University Press, §4.2 (eq 4.45) and §5.6.
doi:10.1017/CBO9781139171731
Young W.C., Budynas R.G. (2002). Roark's Formulas for Stress and Strain, 7th ed., Table 14.1
case 2. McGraw-Hill. ISBN 0-07-072542-X
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Machines 11(6), 626.
doi:10.3390/machines11060626
Palmgren A. (1959). Ball and Roller Bearing Engineering, 3rd ed. SKF Industries, Philadelphia.
Harris T.A., Kotzalas M.N. (2007). Rolling Bearing Analysis, 5th ed., Essential Concepts of
Bearing Technology, ch. 7 (roller–raceway line contact, δ = 3.84e-5 Q^0.9 / l^0.8).
doi:10.1201/9781420006612
Han L., Xu W., Wang Y., Zhang Y. (2023). JERR 25(8). doi:10.9734/JERR/2023/v25i8970
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from gearte._jit import inner_kernel, kernel
from gearte.errors import ParameterError
from gearte.geometry.cycloid import CycloidStage
from gearte.limits import MAX_CONTACT_PRESSURE_MPA, check_floor
from gearte.solvers.contact import log_law_force

__all__ = [
    "LAWS",
    "DEFAULT_LAW",
    "HU2020_HALF_WIDTH_FACTOR",
    "ROARK_BAND_WIDTH_FACTOR",
    "MAX_YOUNGS_MODULUS_MPA",
    "check_law",
    "check_material",
    "contact_modulus",
    "relative_radius",
    "hertz_half_width",
    "max_contact_pressure",
    "pin_pressure_estimate",
    "implausible_pin_pressure",
    "check_pin_pressure",
    "check_palmgren_modulus",
    "log_law_coefficients",
    "law_coefficients",
    "palmgren_approach",
    "PALMGREN_COEFFICIENT",
    "PALMGREN_FORCE_EXPONENT",
    "PALMGREN_LENGTH_EXPONENT",
    "PALMGREN_STEEL_E_RANGE_MPA",
    "LOG_LAWS",
    "approach",
    "force",
    "force_from_coefficients",
    "secant_stiffness",
    "tangent_stiffness",
    "line_contact_a0_scalar",
    "max_contact_pressure_scalar",
]

#: Names of the contact laws; the first is the default of the Python functions (case files
#: must name theirs).
LAWS = ("line_contact", "hu2020", "palmgren")
#: The laws of the form δ = F (a0 − a1 ln F) (:func:`log_law_coefficients`).
LOG_LAWS = ("line_contact", "hu2020")
DEFAULT_LAW = "line_contact"
#: Palmgren's constant of δ = C F^0.9 / l^0.8 [mm^1.7 N^-0.9] (δ mm, F N, l mm; Palmgren 1959,
#: Harris & Kotzalas 2007 ch. 7).
PALMGREN_COEFFICIENT = 3.84e-5
#: Exponent of the force in Palmgren's law [-].
PALMGREN_FORCE_EXPONENT = 0.9
#: Exponent of the contact length in Palmgren's law [-].
PALMGREN_LENGTH_EXPONENT = 0.8
#: Young's moduli [MPa] for which Palmgren's steel-on-steel fit is accepted (bearing and tool
#: steels: about 1.9e5 to 2.2e5 MPa).
PALMGREN_STEEL_E_RANGE_MPA = (1.9e5, 2.2e5)
#: The constant of Hu 2020 eq 39 as printed.
HU2020_HALF_WIDTH_FACTOR = 4.99e-3
#: Roark's constant of the contact band width of two cylinders, b = 1.60 (p K_D C_E)^½
#: (= 2 (2/π)^½ = 1.596, the full width 2a of Hertz's strip).
ROARK_BAND_WIDTH_FACTOR = 1.60
#: Largest Young's modulus the contact laws accept [MPa]: ten times diamond's (about 1.05e6 MPa),
#: the case files' upper bound of ``youngs_modulus_MPa`` (``cycloid_stage``). No material is that
#: stiff, and far above it the law's products leave the range of a double (at E = 1e300 the
#: compiled tooth contact divided by zero and the Hertz pressures overflowed to inf).
MAX_YOUNGS_MODULUS_MPA = 1.0e7


def check_law(law: str, field: str = "contact_law") -> str:
    """Return ``law`` if it names a contact law; else a :class:`ParameterError` naming ``field``.

    Parameters
    ----------
    law : str
        ``"line_contact"``, ``"hu2020"`` or ``"palmgren"``.
    field : str
        Name of the input that carried the law (for the error message).

    References
    ----------
    See the module docstring.
    """
    if not isinstance(law, str) or law not in LAWS:
        raise ParameterError(field, law, f"must be one of {', '.join(repr(x) for x in LAWS)}")
    return law


def check_palmgren_modulus(E: float, field: str = "youngs_modulus_MPa") -> None:
    """A :class:`ParameterError` naming ``field`` unless ``E`` [MPa] lies in
    :data:`PALMGREN_STEEL_E_RANGE_MPA`: Palmgren's law is a fit for steel on steel.

    References
    ----------
    Palmgren (1959); Harris & Kotzalas (2007) ch. 7, doi:10.1201/9781420006612.
    """
    lo, hi = PALMGREN_STEEL_E_RANGE_MPA
    if not lo <= E <= hi:
        raise ParameterError(
            field,
            E,
            f"contact_law 'palmgren' is Palmgren's fit for steel on steel (E in [{lo:g}, "
            f"{hi:g}] MPa); select 'line_contact' for another material",
        )


def check_material(E: float, nu: float, *, fields: tuple[str, str] = ("E", "nu")) -> None:
    """Raise :class:`ParameterError` unless E and ν are those of an engineering material.

    E must be finite, at least the plausibility floor of a Young's modulus
    (``gearte.limits.FLOORS["youngs_modulus"]``, 1 000 MPa) and at most
    :data:`MAX_YOUNGS_MODULUS_MPA`; ν must lie in [0, 0.5).

    Parameters
    ----------
    E : float
        Young's modulus [MPa].
    nu : float
        Poisson's ratio [-].
    fields : (str, str)
        The caller's names of E and ν (named in the error: ``("E", "mu")``,
        ``("youngs_modulus_MPa", "poisson_ratio")``).

    Raises
    ------
    ParameterError
        Naming the first value out of its range, with the range and the reason.

    References
    ----------
    See the module docstring.
    """
    e_name, nu_name = fields
    if not (math.isfinite(E) and E > 0.0):
        raise ParameterError(e_name, E, "must be finite and > 0 [MPa]")
    check_floor(e_name, E, "youngs_modulus")
    if E > MAX_YOUNGS_MODULUS_MPA:
        raise ParameterError(
            e_name,
            E,
            f"must be <= {MAX_YOUNGS_MODULUS_MPA:g} MPa: stiffer than any material "
            "(diamond has about 1.05e6 MPa)",
        )
    if not (math.isfinite(nu) and 0.0 <= nu < 0.5):
        raise ParameterError(nu_name, nu, "Poisson's ratio must be in [0, 0.5)")


def _check_material(E: float, nu: float, b: float) -> None:
    check_material(E, nu)
    if not (math.isfinite(b) and b > 0.0):
        raise ParameterError("b", b, "must be finite and > 0 [mm]")


def contact_modulus(E: float, nu: float) -> float:
    """Contact modulus E* = E / (2 (1 − ν²)) [MPa] of two bodies of the same material.

    Parameters
    ----------
    E : float
        Young's modulus [MPa].
    nu : float
        Poisson's ratio [-].

    Raises
    ------
    ParameterError
        E or ν out of range (:func:`check_material`).

    References
    ----------
    Johnson (1985), eq 4.22 (1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2). doi:10.1017/CBO9781139171731
    """
    check_material(E, nu)
    return E / (2.0 * (1.0 - nu * nu))


def relative_radius(rho: ArrayLike, r: ArrayLike) -> np.ndarray:
    """Relative radius of curvature R* of a pin on a flank [mm], 1/R* = 1/r − 1/ρ.

    Parameters
    ----------
    rho : array_like
        Signed curvature radius of the flank [mm]: < 0 convex, > 0 concave, ±inf flat.
    r : array_like
        Pin radius [mm].

    Returns
    -------
    numpy.ndarray
        R* [mm]; ``r |ρ| / (|ρ| + r)`` on a convex flank, ``r ρ / (ρ − r)`` on a concave one.

    References
    ----------
    Johnson (1985), eq 4.45 context (R = R1 R2/(R1 + R2), concave radius negative).
    doi:10.1017/CBO9781139171731
    """
    rho = np.asarray(rho, dtype=float)
    with np.errstate(divide="ignore"):
        curv = 1.0 / np.asarray(r, dtype=float) - np.where(np.isfinite(rho), 1.0 / rho, 0.0)
    return 1.0 / curv


def hertz_half_width(
    F: ArrayLike, rho: ArrayLike, r: float, E: float, nu: float, b: float
) -> np.ndarray:
    """Hertz half-width a of the contact strip of a pin on a flank [mm].

    ``a = (4 F R* / (π b E*))^½`` (Johnson 1985, eq 4.45 with P = F/b).

    Parameters
    ----------
    F : array_like
        Contact force [N] (≥ 0).
    rho : array_like
        Signed flank curvature radius [mm] (see :func:`relative_radius`).
    r : float
        Pin radius [mm].
    E, nu : float
        Young's modulus [MPa] and Poisson's ratio [-] of disc and pin.
    b : float
        Face width [mm].

    References
    ----------
    Johnson (1985), eq 4.45. doi:10.1017/CBO9781139171731
    """
    _check_material(E, nu, b)
    F = np.asarray(F, dtype=float)
    rs = relative_radius(rho, r)
    return np.sqrt(4.0 * F * rs / (math.pi * b * contact_modulus(E, nu)))


def max_contact_pressure(
    F: ArrayLike, rho: ArrayLike, r: float, E: float, nu: float, b: float
) -> np.ndarray:
    """Largest Hertz pressure p0 of a pin on a flank [MPa] (line contact).

    ``p0 = 2 F / (π a b) = (F E* / (π b R*))^½`` (Johnson 1985, eq 4.45), with each pin's own
    flank curvature ρ. It does not depend on the approach law (the pressure is Hertz's in both).

    Parameters
    ----------
    F : array_like
        Contact force [N] (0 gives 0).
    rho : array_like
        Signed flank curvature radius where the pin touches [mm].
    r : float
        Pin radius [mm].
    E, nu : float
        Young's modulus [MPa] and Poisson's ratio [-].
    b : float
        Face width [mm].

    Returns
    -------
    numpy.ndarray
        p0 [MPa].

    Examples
    --------
    >>> round(float(max_contact_pressure(1810.0, -43.598, 2.978, 2.06e5, 0.3, 11.0)), 0)
    1458.0

    References
    ----------
    Johnson (1985), eq 4.45. doi:10.1017/CBO9781139171731
    """
    _check_material(E, nu, b)
    f = np.maximum(np.asarray(F, dtype=float), 0.0)
    rs = relative_radius(rho, r)
    return np.sqrt(f * contact_modulus(E, nu) / (math.pi * b * rs))


def pin_pressure_estimate(
    stage: CycloidStage, torque_Nmm: float, share: float, E: float, nu: float
) -> float:
    """Hertz pressure of the most loaded pin under an ideal load share [MPa].

    Parameters
    ----------
    stage : CycloidStage
        The cycloid–pin stage (its K1, z_c, r_p, pin radius, face width and ρ(φ0)).
    torque_Nmm : float
        Output torque of the stage [N·mm] (a negative torque gives 0: see ``max_contact_pressure``).
    share : float
        Share of the torque carried by one disc [-].
    E : float
        Young's modulus [MPa].
    nu : float
        Poisson's ratio [-].

    Returns
    -------
    float
        p0 [MPa] of the force F = 4 share T / (K1 z_c r_p) (Hu 2020 eq 30) at the flank curvature
        ρ(φ0) (eq 40).

    Notes
    -----
    Eq 30 lets all z_p/2 pins of the loaded flank share the disc's torque, so F is a lower bound
    of the real largest pin force and p0 a lower bound of its pressure (Johnson eq 4.45,
    :func:`max_contact_pressure`). Used by the case files' plausibility check
    (``gearte.io.plausibility``, which re-exports it) and by :func:`check_pin_pressure`.

    Examples
    --------
    >>> from gearte.geometry.cycloid import CycloidStage
    >>> st = CycloidStage(z_p=40, r_p=82.0, r_rp=3.5, a=1.5, b=13.0)  # han2023_rv110e's pins
    >>> round(pin_pressure_estimate(st, 1.078e6, 0.5, 2.06e5, 0.3))  # rated torque, two discs
    882

    References
    ----------
    Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
    Johnson K. L. (1985). Contact Mechanics, eq 4.45. doi:10.1017/CBO9781139171731
    """
    force = 4.0 * share * torque_Nmm / (stage.K1 * stage.z_c * stage.r_p)
    return float(max_contact_pressure(force, stage.rho0, stage.r, E, nu, stage.b))


def implausible_pin_pressure(
    stage: CycloidStage, torque_Nmm: float, share: float, E: float, nu: float
) -> str | None:
    """Why ``torque_Nmm`` is impossible for ``stage``, or ``None`` when it is not.

    A torque is impossible when its :func:`pin_pressure_estimate` exceeds
    :data:`gearte.limits.MAX_CONTACT_PRESSURE_MPA`: no steel carries the load even once.

    Parameters
    ----------
    stage : CycloidStage
        The cycloid–pin stage.
    torque_Nmm : float
        Output torque of the stage [N·mm] (its magnitude counts).
    share : float
        Share of the torque carried by one disc [-].
    E, nu : float
        Young's modulus [MPa] and Poisson's ratio [-].

    Returns
    -------
    str or None
        ``"is implausible for this stage: it gives a pin–disc contact pressure of about <p> MPa
        (ideal load share, Hu 2020 eq 30), above the 10,000 MPa no steel carries"`` (the case
        files' wording, which adds a hint on units), or ``None``.
    References
    ----------
    Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
    Johnson K. L. (1985). Contact Mechanics, eq 4.45. doi:10.1017/CBO9781139171731
    """
    p = pin_pressure_estimate(stage, abs(torque_Nmm), share, E, nu)
    if p <= MAX_CONTACT_PRESSURE_MPA:
        return None
    return (
        f"is implausible for this stage: it gives a pin–disc contact pressure "
        f"of about {p:,.0f} MPa (ideal load share, Hu 2020 eq 30), above the "
        f"{MAX_CONTACT_PRESSURE_MPA:,.0f} MPa no steel carries"
    )


def check_pin_pressure(
    field: str, torque_Nmm: float, stage: CycloidStage, share: float, E: float, nu: float
) -> None:
    """Raise :class:`ParameterError` naming ``field`` when ``torque_Nmm`` is impossible for
    ``stage`` (:func:`implausible_pin_pressure`).

    Parameters
    ----------
    field : str
        The argument that carried the torque (named in the error).
    torque_Nmm : float
        Output torque of the stage [N·mm] (its magnitude counts).
    stage : CycloidStage
        The cycloid–pin stage.
    share : float
        Share of the torque carried by one disc [-].
    E, nu : float
        Young's modulus [MPa] and Poisson's ratio [-].

    Raises
    ------
    ParameterError
        ``"<field> = <value>: is implausible for this stage: it gives a pin–disc contact
        pressure of about <p> MPa (ideal load share, Hu 2020 eq 30), above the 10,000 MPa no
        steel carries (<value> N·mm = <value / 1000> N·m)"``.
    References
    ----------
    Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
    Johnson K. L. (1985). Contact Mechanics, eq 4.45. doi:10.1017/CBO9781139171731
    """
    reason = implausible_pin_pressure(stage, torque_Nmm, share, E, nu)
    if reason is not None:
        raise ParameterError(
            field,
            torque_Nmm,
            f"{reason} ({torque_Nmm:g} N·mm = {torque_Nmm / 1000:g} N·m)",
        )


def log_law_coefficients(
    law: str,
    rho: ArrayLike,
    r: float,
    E: float,
    nu: float,
    b: float,
    *,
    rho_cap: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients (a0 [mm/N], a1 [mm/N]) of ``δ(F) = F (a0 − a1 ln F)`` for a named law.

    Parameters
    ----------
    law : {"line_contact", "hu2020"}
        The contact law (module docstring).
    rho : array_like
        Signed curvature radius of the flank where the pin touches [mm]. ``"hu2020"`` uses |ρ|
        (as printed, convex–convex); ``"line_contact"`` uses the sign in R*.
    r : float
        Pin radius [mm] (the grinding pin radius r_rp + Δr_rp in gearte's stages).
    E, nu : float
        Young's modulus [MPa], Poisson's ratio [-] of disc and pin.
    b : float
        Face width [mm].
    rho_cap : float, optional
        Upper bound of |ρ| in the logarithm of ``"line_contact"`` [mm]. The flank curvature radius
        passes through infinity at the profile's inflection; ln(4|ρ|/a) would then send the pin
        stiffness to zero although the deforming body is finite. ``None``: no cap (|ρ| must be
        finite).

    Returns
    -------
    a0, a1 : numpy.ndarray
        Broadcast to the shape of ``rho``; ``a1 = 2 (1 − ν²)/(π E b)`` for both laws.

    Notes
    -----
    line contact: ln(4|ρ|/a) + ln(4r/a) = ln(16 |ρ| r) − ln q − ln F with a² = q F,
    q = 4 R*/(π b E*), so a0 = a1 (ln(16 |ρ| r) − ln q − 1).
    hu2020: δ = A F (2/3 + ln(B/F)), A = a1, B = 16 r |ρ| F / c², so a0 = a1 (2/3 + ln B).

    References
    ----------
    Johnson (1985) §5.6; Hu et al. (2020) eq 38–39, doi:10.3390/app10020481.
    """
    check_law(law)
    if law not in LOG_LAWS:
        raise ParameterError(
            "contact_law",
            law,
            "is not of the form δ = F (a0 − a1 ln F) (a power law): use law_coefficients",
        )
    _check_material(E, nu, b)
    if not (math.isfinite(r) and r > 0.0):
        raise ParameterError("pin_radius", r, "must be finite and > 0")
    rho = np.asarray(rho, dtype=float)
    mu2 = 1.0 - nu * nu
    a1 = 2.0 * mu2 / (math.pi * E * b)
    rho_abs = np.abs(rho)
    if law == "hu2020":
        c2_per_F = HU2020_HALF_WIDTH_FACTOR**2 * 4.0 * mu2 * rho_abs * r / (E * b * (rho_abs + r))
        a0 = a1 * (2.0 / 3.0 + np.log(16.0 * r * rho_abs / c2_per_F))
    else:
        if rho_cap is not None:
            if not (math.isfinite(rho_cap) and rho_cap > 0.0):
                raise ParameterError("rho_cap", rho_cap, "must be finite and > 0 [mm]")
            rho_abs = np.minimum(rho_abs, rho_cap)
        rs = relative_radius(rho, r)
        q = 4.0 * rs / (math.pi * b * contact_modulus(E, nu))
        a0 = a1 * (np.log(16.0 * rho_abs * r) - np.log(q) - 1.0)
    return a0, np.broadcast_to(a1, np.shape(a0)).copy()


def palmgren_approach(F: ArrayLike, length: float) -> np.ndarray:
    """Palmgren's approach of a steel roller and a steel raceway in line contact [mm].

    ``δ = 3.84e-5 F^0.9 / l^0.8`` (δ mm, F N, l mm).

    Parameters
    ----------
    F : array_like
        Contact force [N] (≤ 0 gives 0).
    length : float
        Contact length l [mm] (the face width of a pin on a disc), > 0.

    Returns
    -------
    numpy.ndarray
        δ [mm].

    Examples
    --------
    >>> round(1e3 * float(palmgren_approach(1000.0, 13.0)), 3)
    2.473

    References
    ----------
    Palmgren A. (1959). Ball and Roller Bearing Engineering, 3rd ed., SKF Industries.
    Harris T.A., Kotzalas M.N. (2007). Rolling Bearing Analysis, 5th ed., ch. 7.
    doi:10.1201/9781420006612
    """
    if not (math.isfinite(length) and length > 0.0):
        raise ParameterError("length", length, "must be finite and > 0 [mm]")
    f = np.maximum(np.asarray(F, dtype=float), 0.0)
    return PALMGREN_COEFFICIENT * f**PALMGREN_FORCE_EXPONENT / length**PALMGREN_LENGTH_EXPONENT


def law_coefficients(
    law: str,
    rho: ArrayLike,
    r: float,
    E: float,
    nu: float,
    b: float,
    *,
    rho_cap: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Coefficients of ``δ(F) = F (a0 − a1 ln F) + a2 F^a3`` for a named law (every law).

    Parameters
    ----------
    law : {"line_contact", "hu2020", "palmgren"}
        The contact law (module docstring).
    rho, r, E, nu, b, rho_cap
        As in :func:`log_law_coefficients` ([mm], [mm], [MPa], [-], [mm], [mm]).
        ``"palmgren"`` reads only b (the contact length) and checks that E is a steel's
        (:data:`PALMGREN_STEEL_E_RANGE_MPA`).

    Returns
    -------
    a0, a1 : numpy.ndarray
        [mm/N]: those of :func:`log_law_coefficients`; 0 for ``"palmgren"``.
    a2 : numpy.ndarray
        [mm/N^0.9]: ``3.84e-5 / b^0.8`` for ``"palmgren"``; 0 for the logarithmic laws.
    a3 : numpy.ndarray
        [-]: 0.9 for ``"palmgren"``; 1 for the logarithmic laws.

    Raises
    ------
    ParameterError
        An unknown law, a material out of range, or ``"palmgren"`` with E outside a steel's.

    References
    ----------
    Johnson (1985) §5.6; Hu et al. (2020) eq 38–39; Palmgren (1959); Harris & Kotzalas (2007)
    ch. 7, doi:10.1201/9781420006612.
    """
    check_law(law)
    if law in LOG_LAWS:
        a0, a1 = log_law_coefficients(law, rho, r, E, nu, b, rho_cap=rho_cap)
        return a0, a1, np.zeros_like(a0), np.ones_like(a0)
    _check_material(E, nu, b)
    check_palmgren_modulus(E)
    shape = np.shape(np.asarray(rho, dtype=float))
    a2 = PALMGREN_COEFFICIENT / b**PALMGREN_LENGTH_EXPONENT
    return (np.zeros(shape), np.zeros(shape), np.full(shape, a2),
            np.full(shape, PALMGREN_FORCE_EXPONENT))  # fmt: skip


def _approach_from(F: np.ndarray, coef) -> np.ndarray:
    a0, a1, a2, a3 = coef
    return F * (a0 - a1 * np.log(F)) + a2 * F**a3


def approach(
    F: ArrayLike,
    law: str,
    rho: ArrayLike,
    r: float,
    E: float,
    nu: float,
    b: float,
    *,
    rho_cap: float | None = None,
) -> np.ndarray:
    """Normal approach δ [mm] of a pin and a flank under the contact force F [N].

    Parameters
    ----------
    F : array_like
        Contact force [N], > 0.
    law, rho, r, E, nu, b, rho_cap
        As in :func:`log_law_coefficients` ([-], [mm], [mm], [MPa], [-], [mm], [mm]).

    Returns
    -------
    numpy.ndarray
        δ(F) [mm].

    Examples
    --------
    On the Hu 2020 Table 3 stage at φ0 (ρ = −43.598 mm, r = 2.978 mm, b = 11 mm, steel):

    >>> kw = dict(rho=-43.598, r=2.978, E=2.06e5, nu=0.3, b=11.0)
    >>> round(1e3 * float(approach(1810.0, "line_contact", **kw)), 2)
    5.51
    >>> round(1e3 * float(approach(1810.0, "hu2020", **kw)), 2)
    10.98
    >>> round(1e3 * float(approach(1810.0, "palmgren", **kw)), 2)
    4.82

    References
    ----------
    Johnson (1985) §5.6, doi:10.1017/CBO9781139171731; Hu et al. (2020) eq 38–39,
    doi:10.3390/app10020481; Palmgren (1959), Harris & Kotzalas (2007) ch. 7.
    """
    F = np.asarray(F, dtype=float)
    return _approach_from(F, law_coefficients(law, rho, r, E, nu, b, rho_cap=rho_cap))


def secant_stiffness(
    F: ArrayLike,
    law: str,
    rho: ArrayLike,
    r: float,
    E: float,
    nu: float,
    b: float,
    *,
    rho_cap: float | None = None,
) -> np.ndarray:
    """Secant contact stiffness k = F / δ(F) [N/mm].

    Parameters
    ----------
    F : array_like
        Contact force [N], > 0.
    law : {"line_contact", "hu2020", "palmgren"}
        The contact law (:data:`LAWS`).
    rho : array_like
        Curvature radius of the flank at the contact [mm] (ρ < 0 convex).
    r : float
        Pin radius [mm].
    E : float
        Young's modulus of pin and disc [MPa].
    nu : float
        Poisson's ratio [-].
    b : float
        Face width [mm].
    rho_cap : float, optional
        Cap on |ρ| in the logarithm [mm] (as in :func:`log_law_coefficients`).

    Returns
    -------
    numpy.ndarray
        k [N/mm].

    References
    ----------
    See :func:`approach`.
    """
    F = np.asarray(F, dtype=float)
    a0, a1, a2, a3 = law_coefficients(law, rho, r, E, nu, b, rho_cap=rho_cap)
    return 1.0 / (a0 - a1 * np.log(F) + a2 * F ** (a3 - 1.0))


def tangent_stiffness(
    F: ArrayLike,
    law: str,
    rho: ArrayLike,
    r: float,
    E: float,
    nu: float,
    b: float,
    *,
    rho_cap: float | None = None,
) -> np.ndarray:
    """Tangent contact stiffness k_t = dF/dδ = 1 / (a0 − a1 ln F − a1 + a3 a2 F^(a3−1)) [N/mm].

    Parameters
    ----------
    F : array_like
        Contact force [N], > 0.
    law : {"line_contact", "hu2020", "palmgren"}
        The contact law (:data:`LAWS`).
    rho : array_like
        Curvature radius of the flank at the contact [mm] (ρ < 0 convex).
    r : float
        Pin radius [mm].
    E : float
        Young's modulus of pin and disc [MPa].
    nu : float
        Poisson's ratio [-].
    b : float
        Face width [mm].
    rho_cap : float, optional
        Cap on |ρ| in the logarithm [mm] (as in :func:`log_law_coefficients`).

    Returns
    -------
    numpy.ndarray
        k_t [N/mm].

    References
    ----------
    See :func:`approach`.
    """
    F = np.asarray(F, dtype=float)
    a0, a1, a2, a3 = law_coefficients(law, rho, r, E, nu, b, rho_cap=rho_cap)
    return 1.0 / (a0 - a1 * np.log(F) - a1 + a3 * a2 * F ** (a3 - 1.0))


def force_from_coefficients(
    delta: ArrayLike, a0: ArrayLike, a1: ArrayLike, *, rtol: float = 1e-12
) -> np.ndarray:
    """Inverse of ``δ = F (a0 − a1 ln F)``: the force F [N] for an approach δ [mm]; δ ≤ 0 → 0.

    δ(F) increases up to F* = exp(a0/a1 − 1), where it reaches δ* = a1 F* (far beyond any
    elastic load: the half-width is then comparable to the radii). Below δ* the inverse is found by
    a safeguarded Newton iteration on u = ln F inside the bracket (ln δ − 60, ln F*); at or beyond
    δ* the law has no inverse and ``inf`` is returned (callers report the load as out of range).
    The iteration is the solver :func:`gearte.solvers.contact.log_law_force`, here its numpy
    implementation (no compile for the few callers outside the compiled contact kernels, which
    call its compiled twin pin by pin).

    Parameters
    ----------
    delta : array_like
        Approach [mm].
    a0, a1 : array_like
        Law coefficients from :func:`log_law_coefficients` [mm/N].
    rtol : float
        Relative tolerance on F [-].

    Raises
    ------
    ConvergenceError
        Newton did not converge in 100 iterations.

    References
    ----------
    See :func:`approach`.
    """
    return log_law_force(
        np.asarray(delta), np.asarray(a0), np.asarray(a1), rtol=rtol, implementation="plain"
    )


def force(
    delta: ArrayLike,
    law: str,
    rho: ArrayLike,
    r: float,
    E: float,
    nu: float,
    b: float,
    *,
    rho_cap: float | None = None,
    rtol: float = 1e-12,
) -> np.ndarray:
    """Contact force F [N] for a normal approach δ [mm] (inverse of :func:`approach`).

    Parameters
    ----------
    delta : array_like
        Approach [mm]; δ ≤ 0 gives F = 0 (no contact).
    law, rho, r, E, nu, b, rho_cap
        As in :func:`approach`.
    rtol : float
        Relative tolerance on F [-].

    References
    ----------
    See :func:`approach`.
    """
    if law not in LOG_LAWS:
        check_law(law)
        a0, a1, a2, a3 = law_coefficients(law, rho, r, E, nu, b, rho_cap=rho_cap)
        d = np.maximum(np.asarray(delta, dtype=float), 0.0)
        return (d / a2) ** (1.0 / a3)  # the power law inverted in closed form (a0 = a1 = 0)
    a0, a1 = log_law_coefficients(law, rho, r, E, nu, b, rho_cap=rho_cap)
    return force_from_coefficients(delta, a0, a1, rtol=rtol)


# --- compiled twins (numba, one pin at a time) for the compiled tooth contact ----------------
# The numpy functions above are the reference; tests/test_contact_compiled.py checks these
# against them to 1e-12.


@inner_kernel
def _relative_radius_scalar(rho, r):  # pragma: no cover - compiled
    """Twin of :func:`relative_radius` for one pin [mm]."""
    curv = 1.0 / r
    if math.isfinite(rho) and rho != 0.0:
        curv -= 1.0 / rho
    elif rho == 0.0:
        return -0.0  # numpy: 1/r − inf → −inf, 1/−inf = −0
    return 1.0 / curv if curv != 0.0 else math.inf


@kernel
def line_contact_a0_scalar(rho, r, E_star, b, a1, rho_cap):  # pragma: no cover - compiled
    """Coefficient a0 [mm/N] of the ``"line_contact"`` law for one pin (compiled twin).

    Twin of :func:`log_law_coefficients` with ``law="line_contact"``: ``a0 = a1 (ln(16 |ρ| r) −
    ln q − 1)``, ``q = 4 R* / (π b E*)``, |ρ| capped at ``rho_cap`` (``inf``: no cap).

    Parameters
    ----------
    rho : float
        Signed flank curvature radius where the pin touches [mm].
    r : float
        Pin radius [mm].
    E_star : float
        Contact modulus E* [MPa] (:func:`contact_modulus`).
    b : float
        Face width [mm].
    a1 : float
        Coefficient a1 = 2 (1 − ν²)/(π E b) [mm/N].
    rho_cap : float
        Upper bound of |ρ| in the logarithm [mm] (``inf`` for none).

    Returns
    -------
    float
        a0 [mm/N].

    References
    ----------
    Johnson (1985) §5.6, doi:10.1017/CBO9781139171731.
    """
    rho_abs = min(abs(rho), rho_cap)
    q = 4.0 * _relative_radius_scalar(rho, r) / (math.pi * b * E_star)
    return a1 * (math.log(16.0 * rho_abs * r / q) - 1.0)  # one log: ln(16|ρ|r) − ln q


@kernel
def max_contact_pressure_scalar(F, rho, r, E_star, b):  # pragma: no cover - compiled
    """Hertz pressure p0 [MPa] of one pin (compiled twin of :func:`max_contact_pressure`).

    Parameters
    ----------
    F : float
        Contact force [N] (≤ 0 gives 0).
    rho : float
        Signed flank curvature radius where the pin touches [mm].
    r : float
        Pin radius [mm].
    E_star : float
        Contact modulus E* [MPa].
    b : float
        Face width [mm].

    Returns
    -------
    float
        p0 = (F E* / (π b R*))^½ [MPa].

    References
    ----------
    Johnson (1985), eq 4.45. doi:10.1017/CBO9781139171731
    """
    f = max(F, 0.0)
    if f == 0.0:
        return 0.0
    return math.sqrt(f * E_star / (math.pi * b * _relative_radius_scalar(rho, r)))
