"""Strain-wave (harmonic) gear: kinematics, catalogue stiffness, hysteresis and lost motion,
transmission error from wave-generator, flexspline and circular-spline errors.

The drive: an elliptical **wave generator** (WG, input) deforms the thin **flexspline** (FS,
``z_f`` external teeth) into mesh with the rigid **circular spline** (CS, ``z_c = z_f + 2``
internal teeth) at the two ends of its major axis. With the CS fixed, the FS turns backwards
once per ``i`` WG turns (Harmonic Drive engineering data; Tuttle 1992 §2.1)::

    i = z_f / (z_c − z_f)                      θ_out = −θ_WG / i                         (kin)

**Torsional stiffness** (the manufacturer's published three-segment model: the torque–torsion
curve linearised between the limit torques T1 and T2; Harmonic Drive AG, eq. 68.1–68.4)::

    φ(T) = T/K1                                   0 ≤ T ≤ T1                          (68.2)
    φ(T) = T1/K1 + (T − T1)/K2                    T1 < T ≤ T2                         (68.3)
    φ(T) = T1/K1 + (T2 − T1)/K2 + (T − T2)/K3     T > T2                              (68.4)

odd in T (the same curve in both directions). **Hysteresis**: the catalogue gives the hysteresis
loss H, the torsion angle left at zero torque after loading to ±rated torque (the width of the
loop at T = 0); gearte draws the loop as the stiffness curve shifted by ∓H/2 on the loading and
unloading branches (a constant-width band: the catalogue gives the width at zero only).
**Lost motion** at a test torque ±T_L (the catalogue's definition: the torsion between +T_L and
−T_L, input locked; no backlash in the mesh)::

    LM = H + 2 φ(T_L)

**Transmission error** (gearte's first-order reading of the two-zone mesh, docs/strain-wave.md):
the FS meshes at the zones A (WG angle θ) and B (θ + π). A radial engagement error δ at a zone
shifts the mesh along the flank, tangentially δ tan α, and turns the output by δ tan α / r
(r = m z_f / 2). The zones share the load in proportion to their engagement depth h ± δ
(h: nominal working depth), so the output follows ``(Σ (h + δ_k) δ_k) / Σ (h + δ_k)``. With

* a WG eccentricity e at ψ_e (WG axis off the CS axis: δ_A = −δ_B = e cos(θ − ψ_e)),
* a lobe-height difference d of the wave (one major-axis end deflected d more than the other,
  from the WG cam or the FS wall: δ_A = −δ_B = d/2),
* a CS ovality ε_c at ψ_c (second harmonic of its tooth ring, fixed in space:
  δ_A = δ_B = ε_c cos 2(θ − ψ_c)) and an FS ovality ε_f at ψ_f (turning with the FS: sampled at
  the FS angle θ(1 + 1/i)),

the output angle error is (to second order in the antisymmetric and first in the symmetric
errors)::

    TE(θ) = −(tan α / r) [ (d/2 + e cos(θ − ψ_e))² / h + ε_c cos 2(θ − ψ_c)
                                                      + ε_f cos 2(θ (1 + 1/i) − ψ_f) ]      (te)

so a WG eccentricity alone averages out to first order (its square gives a twice-per-WG-turn
term e²/(2h)); together with a lobe difference it gives the **once-per-WG-revolution** term
``d e / h``; the ovalities give the **twice-per-WG-revolution** terms. Tuttle (1992) measured a
harmonic drive's kinematic error at frequencies tied to the wave-generator speed; Jia et al.
(2021) attribute its components to the WG's eccentricity and shape and to the splines' errors.
This reading (ours, docs/strain-wave.md) gives those frequencies; its amplitudes are not fitted
to a measurement.

Units: mm, N·mm, rad; stiffness N·mm/rad.

References
----------
Harmonic Drive AG (2015). CHA Servo Actuator manual 1018854 12/2015, §4.2 "Calculation of the
torsion angle", eq. 68.1–68.4 (the torsional-stiffness model of all Harmonic Drive gears).
Harmonic Drive LLC. CSF & CSG Series engineering data: torsional stiffness (tables 41–43),
hysteresis loss, positioning accuracy.
Tuttle T. D. (1992). Understanding and modeling the behavior of a harmonic drive gear
transmission. S.M. thesis, Massachusetts Institute of Technology; MIT Artificial Intelligence
Laboratory technical report, May 1992.
Jia H., Li J., Xiang G., Wang J., Xiao K., Han Y. (2021). Modeling and analysis of pure kinematic
error in harmonic drive. Mechanism and Machine Theory 155, 104122.
doi:10.1016/j.mechmachtheory.2020.104122
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError

__all__ = [
    "StrainWaveGear",
    "StrainWaveErrors",
    "StrainWaveTolerances",
    "strain_wave_ratio",
    "torsion_angle",
    "hysteresis_branches",
    "lost_motion",
    "transmission_error",
    "te_harmonics",
]


def strain_wave_ratio(flexspline_teeth: int, circular_spline_teeth: int) -> float:
    """Reduction i = z_f / (z_c − z_f) [-], circular spline fixed, WG input, FS output (kin).

    Parameters
    ----------
    flexspline_teeth : int
        z_f [-].
    circular_spline_teeth : int
        z_c [-]; ``z_c − z_f`` must be 2 (a two-lobe wave generator).

    Examples
    --------
    >>> strain_wave_ratio(200, 202)
    100.0

    References
    ----------
    Tuttle (1992), MIT AI Laboratory technical report (harmonic-drive operation).
    """
    if not (isinstance(flexspline_teeth, int) and flexspline_teeth >= 2):
        raise ParameterError("flexspline_teeth", flexspline_teeth, "must be an integer >= 2")
    if circular_spline_teeth - flexspline_teeth != 2:
        raise ParameterError(
            "circular_spline_teeth",
            circular_spline_teeth,
            f"must be flexspline_teeth + 2 = {flexspline_teeth + 2} (a two-lobe wave generator "
            "meshes at two zones: the splines differ by two teeth)",
        )
    return flexspline_teeth / (circular_spline_teeth - flexspline_teeth)


def torsion_angle(
    torque: ArrayLike, T1: float, T2: float, K1: float, K2: float, K3: float
) -> np.ndarray:
    """Torsion angle φ(T) of the three-segment stiffness model [rad] (eq. 68.2–68.4), odd in T.

    Parameters
    ----------
    torque : array_like
        Output torque T [N·mm] (input locked).
    T1, T2 : float
        Limit torques [N·mm], 0 < T1 < T2.
    K1, K2, K3 : float
        Stiffness of the three segments [N·mm/rad], > 0.

    Returns
    -------
    numpy.ndarray
        φ [rad], shaped like ``torque``, with the sign of T.

    Examples
    --------
    Harmonic Drive AG's worked example (T = 60 N·m, T1 = 29 N·m, K1 = 6.7e4 N·m/rad,
    K2 = 1.1e5 N·m/rad): φ = 29/6.7e4 + 31/1.1e5 = 7.15e-4 rad (2.5 arcmin):

    >>> float(torsion_angle(60e3, 29e3, 108e3, 6.7e7, 1.1e8, 1.2e8)).__round__(7)
    0.0007146

    References
    ----------
    Harmonic Drive AG (2015), CHA manual 1018854, §4.2 eq. 68.1–68.4.
    """
    if not (0.0 < T1 < T2):
        raise ParameterError("T1", (T1, T2), "limit torques need 0 < T1 < T2")
    for name, k in (("K1", K1), ("K2", K2), ("K3", K3)):
        if not (k > 0 and math.isfinite(k)):
            raise ParameterError(name, k, "stiffness must be > 0")
    t = np.asarray(torque, dtype=float)
    a = np.abs(t)
    phi = np.where(
        a <= T1,
        a / K1,
        np.where(a <= T2, T1 / K1 + (a - T1) / K2, T1 / K1 + (T2 - T1) / K2 + (a - T2) / K3),
    )
    return np.sign(t) * phi


def hysteresis_branches(
    torque: ArrayLike, hysteresis: float, T1: float, T2: float, K1: float, K2: float, K3: float
) -> tuple[np.ndarray, np.ndarray]:
    """Loading and unloading branches of the torsion loop [rad]: ``φ(T) ∓ H/2``.

    Parameters
    ----------
    torque : array_like
        Output torque [N·mm].
    hysteresis : float
        Hysteresis loss H [rad] (the loop's width at T = 0), >= 0.
    T1, T2, K1, K2, K3 : float
        The stiffness model (:func:`torsion_angle`) [N·mm], [N·mm/rad].

    Returns
    -------
    (loading, unloading)
        Torsion on the branch of increasing and of decreasing torque [rad].
    """
    if not hysteresis >= 0:
        raise ParameterError("hysteresis", hysteresis, "must be >= 0")
    phi = torsion_angle(torque, T1, T2, K1, K2, K3)
    return phi - 0.5 * hysteresis, phi + 0.5 * hysteresis


def lost_motion(
    hysteresis: ArrayLike,
    test_torque: float,
    T1: ArrayLike,
    T2: float,
    K1: ArrayLike,
    K2: float,
    K3: float,
) -> np.ndarray:
    """Lost motion at ±T_L [rad]: ``H + 2 φ(T_L)`` (no backlash in the mesh).

    Broadcasts over ``hysteresis``, ``T1`` and ``K1`` (drawn samples).

    Parameters
    ----------
    hysteresis : array_like
        Hysteresis loss H [rad].
    test_torque : float
        T_L [N·mm], >= 0.
    T1 : array_like
        First limit torque [N·mm].
    T2 : float
        Second limit torque [N·mm].
    K1 : array_like
        Low-torque stiffness [N·mm/rad].
    K2, K3 : float
        [N·mm/rad].

    Returns
    -------
    numpy.ndarray
        [rad].

    References
    ----------
    Harmonic Drive LLC, CSF & CSG engineering data (lost motion and hysteresis loss); the
    torsion by Harmonic Drive AG eq. 68.2–68.4.
    """
    if not test_torque >= 0:
        raise ParameterError("test_torque", test_torque, "must be >= 0 N·mm")
    h = np.asarray(hysteresis, dtype=float)
    t1 = np.asarray(T1, dtype=float)
    k1 = np.asarray(K1, dtype=float)
    a = float(test_torque)
    phi = np.where(
        a <= t1,
        a / k1,
        np.where(a <= T2, t1 / k1 + (a - t1) / K2, t1 / k1 + (T2 - t1) / K2 + (a - T2) / K3),
    )
    return h + 2.0 * phi


@dataclass(frozen=True)
class StrainWaveErrors:
    """Errors that make the transmission error [mm, rad] (see the module's eq. te).

    Attributes
    ----------
    wave_generator_eccentricity, wave_generator_eccentricity_angle
        e [mm] and its direction ψ_e [rad].
    lobe_height_difference
        d [mm]: one major-axis end of the wave deflected d more than the other.
    flexspline_ovality, flexspline_ovality_angle
        ε_f [mm] (second harmonic of the FS tooth ring) and ψ_f [rad] (on the FS).
    circular_spline_ovality, circular_spline_ovality_angle
        ε_c [mm] and ψ_c [rad] (on the CS).
    """

    wave_generator_eccentricity: float = 0.0
    wave_generator_eccentricity_angle: float = 0.0
    lobe_height_difference: float = 0.0
    flexspline_ovality: float = 0.0
    flexspline_ovality_angle: float = 0.0
    circular_spline_ovality: float = 0.0
    circular_spline_ovality_angle: float = 0.0


@dataclass(frozen=True)
class StrainWaveTolerances:
    """Production scatter of one strain-wave gear around its nominal description.

    Attributes
    ----------
    hysteresis_loss : float
        ± tolerance (3σ, normal) of the hysteresis loss [rad].
    torsion_at_T1 : float
        ± tolerance (3σ, normal) of the torsion angle at T1, θ1 = T1/K1 [rad].
    errors : mapping
        Error name (a :class:`StrainWaveErrors` magnitude field) → tolerance [mm]: magnitudes
        (eccentricity, ovalities) Rayleigh with 99.73 % below it and a uniform direction; the
        signed lobe-height difference normal (3σ) about its value.
    """

    hysteresis_loss: float = 0.0
    torsion_at_T1: float = 0.0
    errors: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class StrainWaveGear:
    """A strain-wave gear set (CS fixed, WG input, FS output) with its catalogue data.

    Parameters
    ----------
    flexspline_teeth, circular_spline_teeth : int
        z_f, z_c = z_f + 2 [-].
    module : float
        m [mm] (FS pitch radius r = m z_f / 2).
    pressure_angle : float
        α [rad].
    engagement_depth : float
        Nominal working depth h of the mesh [mm].
    T1, T2 : float
        Limit torques of the stiffness model [N·mm].
    K1, K2, K3 : float
        Segment stiffnesses [N·mm/rad].
    hysteresis_loss : float
        H [rad].
    lost_motion_torque : float
        T_L of the lost-motion definition [N·mm].
    errors : StrainWaveErrors
        The TE-making errors.
    tolerances : StrainWaveTolerances
        Production scatter.
    """

    flexspline_teeth: int
    circular_spline_teeth: int
    module: float
    pressure_angle: float
    engagement_depth: float
    T1: float
    T2: float
    K1: float
    K2: float
    K3: float
    hysteresis_loss: float
    lost_motion_torque: float
    errors: StrainWaveErrors = StrainWaveErrors()
    tolerances: StrainWaveTolerances = StrainWaveTolerances()

    def __post_init__(self) -> None:
        strain_wave_ratio(self.flexspline_teeth, self.circular_spline_teeth)
        torsion_angle(0.0, self.T1, self.T2, self.K1, self.K2, self.K3)
        for name in ("module", "engagement_depth"):
            if not getattr(self, name) > 0:
                raise ParameterError(name, getattr(self, name), "must be > 0 mm")
        if not 0 < self.pressure_angle < math.pi / 4:
            raise ParameterError("pressure_angle", self.pressure_angle, "must be in (0, 45°)")
        if not self.hysteresis_loss >= 0:
            raise ParameterError("hysteresis_loss", self.hysteresis_loss, "must be >= 0")
        if not self.lost_motion_torque >= 0:
            raise ParameterError("lost_motion_torque", self.lost_motion_torque, "must be >= 0")

    @property
    def ratio(self) -> float:
        """i = z_f / (z_c − z_f) [-]."""
        return strain_wave_ratio(self.flexspline_teeth, self.circular_spline_teeth)

    @property
    def pitch_radius(self) -> float:
        """FS pitch radius r = m z_f / 2 [mm]."""
        return 0.5 * self.module * self.flexspline_teeth

    def torsion(self, torque: ArrayLike) -> np.ndarray:
        """φ(T) [rad] (:func:`torsion_angle`) at output torques [N·mm]."""
        return torsion_angle(torque, self.T1, self.T2, self.K1, self.K2, self.K3)

    def lost_motion(self) -> float:
        """H + 2 φ(T_L) [rad] (:func:`lost_motion`)."""
        return float(
            lost_motion(
                self.hysteresis_loss,
                self.lost_motion_torque,
                self.T1,
                self.T2,
                self.K1,
                self.K2,
                self.K3,
            )
        )

    def transmission_error(self, wg_angle: ArrayLike) -> np.ndarray:
        """Output angle error at WG angles [rad] (:func:`transmission_error`)."""
        e = self.errors
        return transmission_error(
            wg_angle,
            self.ratio,
            self.pitch_radius,
            self.pressure_angle,
            self.engagement_depth,
            e.wave_generator_eccentricity,
            e.wave_generator_eccentricity_angle,
            e.lobe_height_difference,
            e.flexspline_ovality,
            e.flexspline_ovality_angle,
            e.circular_spline_ovality,
            e.circular_spline_ovality_angle,
        )

    def with_errors(self, **changes: float) -> StrainWaveGear:
        """The same gear with some :class:`StrainWaveErrors` fields changed."""
        return replace(self, errors=replace(self.errors, **changes))


def transmission_error(
    wg_angle: ArrayLike,
    ratio: float,
    pitch_radius: float,
    pressure_angle: float,
    engagement_depth: float,
    eccentricity: ArrayLike = 0.0,
    eccentricity_angle: ArrayLike = 0.0,
    lobe_difference: ArrayLike = 0.0,
    fs_ovality: ArrayLike = 0.0,
    fs_ovality_angle: ArrayLike = 0.0,
    cs_ovality: ArrayLike = 0.0,
    cs_ovality_angle: ArrayLike = 0.0,
) -> np.ndarray:
    """Output angle error of the two-zone mesh [rad] (module eq. te), broadcasting.

    Parameters
    ----------
    wg_angle : array_like
        Wave-generator angle θ [rad].
    ratio : float
        i [-].
    pitch_radius : float
        r [mm].
    pressure_angle : float
        α [rad].
    engagement_depth : float
        h [mm].
    eccentricity, eccentricity_angle : array_like
        WG eccentricity e [mm] and its direction ψ_e [rad].
    lobe_difference : array_like
        d [mm].
    fs_ovality, fs_ovality_angle : array_like
        ε_f [mm], ψ_f [rad].
    cs_ovality, cs_ovality_angle : array_like
        ε_c [mm], ψ_c [rad].

    Returns
    -------
    numpy.ndarray
        TE [rad] (actual − nominal output angle), broadcast of the inputs.

    References
    ----------
    gearte's reading (docs/strain-wave.md) of the error sources of Jia et al. (2021),
    doi:10.1016/j.mechmachtheory.2020.104122; Tuttle (1992) for the WG-speed frequencies.
    """
    th = np.asarray(wg_angle, dtype=float)
    k = math.tan(pressure_angle) / pitch_radius
    anti = 0.5 * np.asarray(lobe_difference) + np.asarray(eccentricity) * np.cos(
        th - np.asarray(eccentricity_angle)
    )
    sym = np.asarray(cs_ovality) * np.cos(2.0 * (th - np.asarray(cs_ovality_angle)))
    sym = sym + np.asarray(fs_ovality) * np.cos(
        2.0 * (th * (1.0 + 1.0 / ratio) - np.asarray(fs_ovality_angle))
    )
    return -k * (anti * anti / engagement_depth + sym)


def te_harmonics(gear: StrainWaveGear) -> dict[str, float]:
    """Amplitudes of the TE's once- and twice-per-WG-revolution terms [rad] (eq. te expanded).

    ``once = (tan α / r) d e / h``; ``twice`` = the modulus of the phasor sum of
    ``e²/(2h)`` (at 2ψ_e) and ε_c (at 2ψ_c); the FS ovality's term runs at 2(1 + 1/i) per WG
    turn (``twice_flexspline = (tan α / r) ε_f``).

    Parameters
    ----------
    gear : StrainWaveGear
        The gear with its errors.

    Returns
    -------
    dict
        ``once``, ``twice``, ``twice_flexspline`` [rad].
    """
    e = gear.errors
    k = math.tan(gear.pressure_angle) / gear.pitch_radius
    h = gear.engagement_depth
    ecc = e.wave_generator_eccentricity
    once = k * abs(e.lobe_height_difference * ecc) / h
    z = (ecc * ecc / (2.0 * h)) * np.exp(2j * e.wave_generator_eccentricity_angle) + (
        e.circular_spline_ovality * np.exp(2j * e.circular_spline_ovality_angle)
    )
    return {
        "once": float(once),
        "twice": float(k * abs(z)),
        "twice_flexspline": float(k * abs(e.flexspline_ovality)),
    }
