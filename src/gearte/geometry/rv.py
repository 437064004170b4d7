"""Description of a whole RV reducer (involute first stage + crank/cycloid/pin second stage).

This module only *describes* a reducer: dimensions, stiffnesses, clearances and measured
manufacturing errors, validated on construction. The quasi-static load-sharing model
(:mod:`gearte.models.rv_load_sharing`) and the RV dynamics model reuse it.

Units: mm, N, N·mm, MPa, rad.

Conventions (stated once, used everywhere)
-----------------------------------------
* Ground frame ``(x, y)`` centred on the pin-ring centre ``O``. The carrier (output) angle is
  ``theta_c``; at ``theta_c = 0`` crank ``i`` (0-based) sits at angle ``2 pi i / M`` on the crank
  circle and the eccentric of disc ``j`` points along ``+x`` rotated by ``psi_j = 2 pi j / N``
  (Han et al. 2023, section 3.1: ``phi_i = 2 pi (i-1)/3``, ``psi_j = (j-1) pi``).
* Kinematics with fixed pins: crank (and planet) absolute angle ``theta_e = -z_c theta_c``;
  input (sun) angle ``theta_s = i theta_c`` with ``i = 1 + z_p z_2 / z_1``.
* Measured eccentricity errors are vectors ``value * (cos(ang), sin(ang))`` in the frame of the
  part that carries them:

  - planet base-circle eccentricity (Han Table 1): planet frame, angle from the eccentric
    direction of disc 1's cam on the same crank (the planet turns with its crank);
  - disc crank-bore eccentricity (Han Table 2, per disc *and* crank): disc frame, angle from the
    radial direction (disc centre → nominal bore centre);
  - cam eccentricity (Han Table 3, per crank *and* disc): crank frame, angle from that cam's
    nominal eccentric direction;
  - carrier crank-bore eccentricity (Han Table 4): carrier frame, angle from the radial direction
    (carrier centre → nominal bore centre).

  Han et al. do not define their angle origins; these are the natural ones and are documented in
  ``docs/validation/han2023.md``.

Stiffness laws
--------------
* Pin–disc contacts: the load-dependent law of Hu et al. 2020, section 4 (eq 33–36): a per-disc
  secant stiffness ``F_max / delta_max(F_max)`` (see :func:`gearte.models.rv_load_sharing`).
* Roller bearings (crank needle bearings, carrier crank bearings): either given, or derived from
  the Palmgren line-contact deflection ``delta = 3.84e-5 Q^0.9 / l^0.8`` per race (Harris &
  Kotzalas, *Rolling Bearing Analysis*, eq. for line contact; Palmgren 1959) with the Stribeck
  load of the most loaded roller ``Q = 4.08 F_r / Z`` — see :func:`palmgren_radial_stiffness`.
* Involute mesh: given, or ``c_gamma * b`` with ``c_gamma`` the ISO 6336-1 mean mesh stiffness
  per unit face width (default 20 N/(mm·µm)).

Reuse
-----
A case file's ``[reducer]`` section becomes an :class:`RVReducer` through
:func:`gearte.studies.rv_reducer.build_reducer`. :func:`gearte.models.rv_load_sharing.assemble`
turns it into spring rows ``w = B q + e`` (stiffness ``k``, bearing clearance ``c``) and
unilateral pin-contact rows at any output angles, over the 3M + 3N + 5 displacement DOF of
:class:`gearte.models.rv_load_sharing.DofLayout`; a dynamic model adds masses and inertias
(not part of this description) to the same DOF.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gearte.errors import ParameterError
from gearte.units import um_to_mm

__all__ = [
    "FirstStage",
    "Cranks",
    "Discs",
    "PinRing",
    "Supports",
    "ErrorEntry",
    "ManufacturingErrors",
    "RVReducer",
    "palmgren_radial_stiffness",
    "iso6336_mesh_stiffness",
]


def palmgren_radial_stiffness(
    rollers: int, roller_length: float, radial_load: float, contact_angle: float = 0.0
) -> float:
    """Secant radial stiffness [N/mm] of a roller (needle) bearing from Palmgren's formula.

    Parameters
    ----------
    rollers : int
        Number of rollers ``Z`` [-].
    roller_length : float
        Effective roller length ``l`` [mm].
    radial_load : float
        Radial load ``F_r`` at which the secant stiffness is taken [N].
    contact_angle : float
        Contact angle ``alpha`` [rad] (0 for radial needle bearings).

    Returns
    -------
    float
        ``F_r / delta_r`` [N/mm].

    Notes
    -----
    Palmgren's empirical line-contact approach per roller–race contact
    ``delta = 3.84e-5 Q^0.9 / l^0.8`` [mm, N, mm]; inner + outer race give twice that. The most
    loaded roller of a zero-clearance bearing carries ``Q_max = 4.08 F_r / (Z cos alpha)``
    (Stribeck), and the bearing's radial deflection is ``delta_r = 2 delta(Q_max) / cos alpha``.

    References
    ----------
    Palmgren A. (1959) *Ball and Roller Bearing Engineering*, 3rd ed.; Harris T.A., Kotzalas M.N.
    (2007) *Rolling Bearing Analysis*, 5th ed., ch. 6.

    Examples
    --------
    >>> round(palmgren_radial_stiffness(16, 14.0, 5000.0) / 1e5, 2)
    8.62
    """
    if rollers < 3:
        raise ParameterError("rollers", rollers, "must be >= 3")
    if roller_length <= 0:
        raise ParameterError("roller_length", roller_length, "must be > 0 mm")
    if radial_load <= 0:
        raise ParameterError("radial_load", radial_load, "must be > 0 N")
    ca = np.cos(contact_angle)
    q_max = 4.08 * radial_load / (rollers * ca)
    delta = 2.0 * 3.84e-5 * q_max**0.9 / roller_length**0.8
    return float(radial_load / (delta / ca))


def iso6336_mesh_stiffness(face_width: float, c_gamma: float = 20.0) -> float:
    """Mean involute mesh stiffness [N/mm] = ``c_gamma`` [N/(mm·µm)] × face width [mm] × 1000.

    ISO 6336-1:2019, 9.3 gives ``c_gamma ≈ 20 N/(mm·µm)`` for solid steel spur gears.
    """
    if face_width <= 0:
        raise ParameterError("face_width", face_width, "must be > 0 mm")
    return float(c_gamma * face_width / um_to_mm(1.0))  # N/µm → N/mm


@dataclass(frozen=True)
class FirstStage:
    """Involute first stage: sun (input) and ``M`` planets, each fixed to a crankshaft.

    Attributes
    ----------
    sun_teeth, planet_teeth : int
        ``z_1``, ``z_2``.
    module : float
        Normal module [mm].
    pressure_angle : float
        Standard pressure angle [rad].
    mesh_stiffness : float
        Sun–planet mesh stiffness along the line of action [N/mm].
    sun_support_stiffness : float
        Radial stiffness of the sun (input shaft) support [N/mm]; small = floating sun.
    """

    sun_teeth: int
    planet_teeth: int
    module: float
    pressure_angle: float
    mesh_stiffness: float
    sun_support_stiffness: float

    def __post_init__(self) -> None:
        _check_int("first_stage.sun_teeth", self.sun_teeth, 6)
        _check_int("first_stage.planet_teeth", self.planet_teeth, 6)
        _check_pos("first_stage.module", self.module)
        if not 0 < self.pressure_angle < np.pi / 4:
            raise ParameterError(
                "first_stage.pressure_angle", self.pressure_angle, "must be in (0, pi/4) rad"
            )
        _check_pos("first_stage.mesh_stiffness", self.mesh_stiffness)
        _check_pos("first_stage.sun_support_stiffness", self.sun_support_stiffness)

    @property
    def base_radii(self) -> tuple[float, float]:
        """Base radii of sun and planet [mm]."""
        c = np.cos(self.pressure_angle) * self.module / 2.0
        return float(self.sun_teeth * c), float(self.planet_teeth * c)


@dataclass(frozen=True)
class Cranks:
    """The ``M`` crankshafts carrying the planets and the eccentric cams.

    Attributes
    ----------
    count : int
        Number of cranks ``M`` (= planets).
    circle_radius : float
        Radius of the crank-axis circle on the carrier ``R_dc`` [mm] (= first-stage centre
        distance).
    eccentricity : float
        Cam eccentricity ``a`` (= ``e``) [mm].
    cam_bearing_stiffness : float
        Radial stiffness of the needle bearing between a cam and its disc bore [N/mm].
    carrier_bearing_stiffness : float
        Radial stiffness of the (two, combined) bearings of one crank in the carrier [N/mm].
    cam_bearing_clearance, carrier_bearing_clearance : float
        Radial clearance of those bearings [mm] (0: none). A bearing with clearance carries
        ``k (|w| - c)`` along its radial deflection ``w`` and nothing while ``|w| <= c``.
    """

    count: int
    circle_radius: float
    eccentricity: float
    cam_bearing_stiffness: float
    carrier_bearing_stiffness: float
    cam_bearing_clearance: float = 0.0
    carrier_bearing_clearance: float = 0.0

    def __post_init__(self) -> None:
        _check_int("cranks.count", self.count, 2, 6)
        _check_pos("cranks.circle_radius", self.circle_radius)
        _check_pos("cranks.eccentricity", self.eccentricity)
        _check_pos("cranks.cam_bearing_stiffness", self.cam_bearing_stiffness)
        _check_pos("cranks.carrier_bearing_stiffness", self.carrier_bearing_stiffness)
        for name in ("cam_bearing_clearance", "carrier_bearing_clearance"):
            v = getattr(self, name)
            if not np.isfinite(v) or not 0.0 <= v <= 0.2:
                raise ParameterError(f"cranks.{name}", v, "must be in [0, 0.2] mm")


@dataclass(frozen=True)
class Discs:
    """The ``N`` cycloid discs (identical profile, eccentrics ``2 pi/N`` apart).

    Attributes
    ----------
    count : int
        ``N`` (usually 2).
    face_width : float
        Disc width ``b`` [mm].
    equidistant_modification, shift_modification : float
        Hu 2020 ``Δr_rp`` and ``Δr_p`` [mm]; a positive ``Δr_rp`` opens the clearance, a negative
        ``Δr_p`` opens it (the convention of Hu et al. 2020, eq 1–3 and 32).
    youngs_modulus : float
        ``E`` [MPa] of disc and pins.
    poisson_ratio : float
        ``mu`` [-].
    contact_law : str
        Name of the pin-contact law (``gearte.models.contact_law``: ``"line_contact"``, the
        textbook default, or ``"hu2020"``); every analysis of the reducer uses it.
    """

    count: int
    face_width: float
    equidistant_modification: float = 0.0
    shift_modification: float = 0.0
    youngs_modulus: float = 2.06e5
    poisson_ratio: float = 0.3
    contact_law: str = "line_contact"

    def __post_init__(self) -> None:
        _check_int("discs.count", self.count, 1, 3)
        _check_pos("discs.face_width", self.face_width)
        for name in ("equidistant_modification", "shift_modification"):
            v = getattr(self, name)
            if not np.isfinite(v) or abs(v) > 0.5:
                raise ParameterError(f"discs.{name}", v, "must be finite with |value| <= 0.5 mm")
        _check_pos("discs.youngs_modulus", self.youngs_modulus)
        if not 0.0 <= self.poisson_ratio < 0.5:
            raise ParameterError("discs.poisson_ratio", self.poisson_ratio, "must be in [0, 0.5)")


@dataclass(frozen=True, eq=False)  # holds arrays: compare fields explicitly
class PinRing:
    """The fixed ring of ``z_p`` pins.

    Attributes
    ----------
    count : int
        ``z_p``; the discs have ``z_c = z_p - 1`` teeth.
    pin_radius : float
        ``r_rp`` [mm].
    circle_radius : float
        Pin-centre circle radius ``r_p`` [mm].
    radius_errors : numpy.ndarray
        Per-pin radius error [mm] (positive = larger pin), shape ``(z_p,)``.
    radial_position_errors, tangential_position_errors : numpy.ndarray
        Per-pin centre position errors [mm] (radially outward, counter-clockwise), ``(z_p,)``.
    """

    count: int
    pin_radius: float
    circle_radius: float
    radius_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    radial_position_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    tangential_position_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        _check_int("pins.count", self.count, 8, 200)
        _check_pos("pins.pin_radius", self.pin_radius)
        _check_pos("pins.circle_radius", self.circle_radius)
        for name in ("radius_errors", "radial_position_errors", "tangential_position_errors"):
            arr = np.asarray(getattr(self, name), dtype=float)
            if arr.size == 0:
                arr = np.zeros(self.count)
            if arr.shape != (self.count,):
                raise ParameterError(
                    f"pins.{name}", arr.shape, f"must have one value per pin ({self.count})"
                )
            if not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > 0.5):
                raise ParameterError(f"pins.{name}", arr, "must be finite, |value| <= 0.5 mm")
            object.__setattr__(self, name, arr)


@dataclass(frozen=True)
class Supports:
    """Carrier (output) main bearings to the housing.

    Attributes
    ----------
    carrier_radial_stiffness : float
        Radial stiffness of the carrier's main bearings [N/mm].
    """

    carrier_radial_stiffness: float

    def __post_init__(self) -> None:
        _check_pos("supports.carrier_radial_stiffness", self.carrier_radial_stiffness)


@dataclass(frozen=True)
class ErrorEntry:
    """One measured eccentricity error.

    Attributes
    ----------
    part : str
        ``"planet_base_circle"``, ``"disc_crank_bore"``, ``"cam"`` or ``"carrier_crank_bore"``.
    crank : int
        Crank (= planet) index, 1-based as in the paper's tables.
    disc : int or None
        Disc index, 1-based; required for ``disc_crank_bore`` and ``cam``.
    value : float
        Magnitude [mm].
    angle : float
        Angle [rad] in the part's frame (module docstring).
    """

    part: str
    crank: int
    disc: int | None
    value: float
    angle: float


_PARTS = ("planet_base_circle", "disc_crank_bore", "cam", "carrier_crank_bore")


@dataclass(frozen=True, eq=False)  # holds arrays: compare fields explicitly
class ManufacturingErrors:
    """Measured eccentricity errors as arrays of error vectors in the parts' frames [mm].

    Attributes
    ----------
    planet : numpy.ndarray
        ``(M, 2)`` planet base-circle eccentricity (magnitude, angle) → stored as (x, y) in the
        planet frame.
    disc_bore : numpy.ndarray
        ``(N, M, 2)`` disc ``j`` crank bore ``i``.
    cam : numpy.ndarray
        ``(M, N, 2)`` crank ``i`` cam for disc ``j``.
    carrier_bore : numpy.ndarray
        ``(M, 2)``.
    """

    planet: np.ndarray
    disc_bore: np.ndarray
    cam: np.ndarray
    carrier_bore: np.ndarray

    @classmethod
    def none(cls, n_cranks: int, n_discs: int) -> ManufacturingErrors:
        """No errors."""
        return cls(
            np.zeros((n_cranks, 2)),
            np.zeros((n_discs, n_cranks, 2)),
            np.zeros((n_cranks, n_discs, 2)),
            np.zeros((n_cranks, 2)),
        )

    @classmethod
    def from_entries(
        cls, entries: list[ErrorEntry], n_cranks: int, n_discs: int, field_name: str = "errors"
    ) -> ManufacturingErrors:
        """Collect error entries, checking every index against the reducer.

        Raises
        ------
        ParameterError
            Naming ``errors[k].crank`` / ``errors[k].disc`` / ``errors[k].part`` when an index
            does not exist or an entry is given twice.
        """
        out = cls.none(n_cranks, n_discs)
        seen: set[tuple] = set()
        for k, e in enumerate(entries):
            f = f"{field_name}[{k}]"
            if e.part not in _PARTS:
                raise ParameterError(f"{f}.part", e.part, f"must be one of {_PARTS}")
            if not 1 <= e.crank <= n_cranks:
                raise ParameterError(
                    f"{f}.crank", e.crank, f"crank index must be in 1..{n_cranks} (cranks.count)"
                )
            needs_disc = e.part in ("disc_crank_bore", "cam")
            if needs_disc:
                if e.disc is None or not 1 <= e.disc <= n_discs:
                    raise ParameterError(
                        f"{f}.disc", e.disc, f"disc index must be in 1..{n_discs} (discs.count)"
                    )
            elif e.disc is not None:
                raise ParameterError(f"{f}.disc", e.disc, f"must be omitted for part {e.part!r}")
            if not np.isfinite(e.value) or not 0.0 <= e.value <= 0.5:
                raise ParameterError(f"{f}.value", e.value, "must be in [0, 0.5] mm")
            key = (e.part, e.crank, e.disc)
            if key in seen:
                raise ParameterError(f, key, "error given twice for the same part and index")
            seen.add(key)
            vec = e.value * np.array([np.cos(e.angle), np.sin(e.angle)])
            i = e.crank - 1
            if e.part == "planet_base_circle":
                out.planet[i] = vec
            elif e.part == "carrier_crank_bore":
                out.carrier_bore[i] = vec
            elif e.part == "disc_crank_bore":
                out.disc_bore[e.disc - 1, i] = vec
            else:
                out.cam[i, e.disc - 1] = vec
        return out

    def scaled(self, factor: float) -> ManufacturingErrors:
        """All errors multiplied by ``factor`` (0 removes them)."""
        return ManufacturingErrors(
            self.planet * factor,
            self.disc_bore * factor,
            self.cam * factor,
            self.carrier_bore * factor,
        )


@dataclass(frozen=True, eq=False)  # holds arrays: compare fields explicitly
class RVReducer:
    """A whole RV reducer.

    Attributes
    ----------
    first_stage, cranks, discs, pins, supports : see the classes above.
    errors : ManufacturingErrors
        Measured errors (default none).
    rated_torque : float
        Rated output torque [N·mm] (catalogue value; used for sweeps and the virtual test).
    planets : int, optional
        Number of planets of the first stage; must equal ``cranks.count`` (default: equal).

    Raises
    ------
    ParameterError
        If the planet count differs from the crank count, if the eccentricity makes the
        short-width coefficient ``K1 = a z_p / r_p >= 1``, if the first-stage base circles do not
        fit the crank circle, or if the error arrays do not match the part counts.
    """

    first_stage: FirstStage
    cranks: Cranks
    discs: Discs
    pins: PinRing
    supports: Supports
    rated_torque: float
    planets: int | None = None
    errors: ManufacturingErrors | None = None

    def __post_init__(self) -> None:
        planets = self.cranks.count if self.planets is None else self.planets
        if planets != self.cranks.count:
            raise ParameterError(
                "first_stage.planets",
                planets,
                f"must equal cranks.count = {self.cranks.count} (each planet drives one crank)",
            )
        _check_pos("rated_torque", self.rated_torque)
        k1 = self.K1
        if not 0 < k1 < 1:
            raise ParameterError(
                "cranks.eccentricity",
                self.cranks.eccentricity,
                f"gives K1 = a z_p / (r_p + Δr_p) = {k1:.4f}; must be < 1",
            )
        rb1, rb2 = self.first_stage.base_radii
        if rb1 + rb2 >= self.cranks.circle_radius:
            raise ParameterError(
                "cranks.circle_radius",
                self.cranks.circle_radius,
                f"must exceed the sum of first-stage base radii {rb1 + rb2:.3f} mm",
            )
        if self.cranks.circle_radius + self.cranks.eccentricity >= self.pins.circle_radius:
            raise ParameterError(
                "cranks.circle_radius",
                self.cranks.circle_radius,
                f"crank circle must lie inside the pin circle r_p = {self.pins.circle_radius} mm",
            )
        m, n = self.cranks.count, self.discs.count
        err = self.errors if self.errors is not None else ManufacturingErrors.none(m, n)
        shapes = {
            "errors.planet": (err.planet.shape, (m, 2)),
            "errors.disc_bore": (err.disc_bore.shape, (n, m, 2)),
            "errors.cam": (err.cam.shape, (m, n, 2)),
            "errors.carrier_bore": (err.carrier_bore.shape, (m, 2)),
        }
        for name, (got, want) in shapes.items():
            if got != want:
                raise ParameterError(name, got, f"shape must be {want} for {m} cranks, {n} discs")
        object.__setattr__(self, "errors", err)
        object.__setattr__(self, "planets", planets)

    # ---- derived quantities -------------------------------------------------------------
    @property
    def cycloid_teeth(self) -> int:
        """``z_c = z_p - 1``."""
        return self.pins.count - 1

    @property
    def K1(self) -> float:  # noqa: N802 - paper symbol
        """Short-width coefficient ``K1 = a z_p / (r_p + Δr_p)`` (Hu 2020 eq 2)."""
        return (
            self.cranks.eccentricity
            * self.pins.count
            / (self.pins.circle_radius + self.discs.shift_modification)
        )

    @property
    def ratio(self) -> float:
        """Reduction ratio with fixed pins, input sun, output carrier: ``1 + z_p z_2 / z_1``."""
        fs = self.first_stage
        return 1.0 + self.pins.count * fs.planet_teeth / fs.sun_teeth

    @property
    def working_pressure_angle(self) -> float:
        """First-stage working pressure angle [rad] from the crank-circle centre distance."""
        rb1, rb2 = self.first_stage.base_radii
        return float(np.arccos((rb1 + rb2) / self.cranks.circle_radius))

    def with_errors(self, errors: ManufacturingErrors) -> RVReducer:
        """Copy with other errors."""
        return RVReducer(
            self.first_stage,
            self.cranks,
            self.discs,
            self.pins,
            self.supports,
            self.rated_torque,
            self.planets,
            errors,
        )

    def replace(self, **changes) -> RVReducer:
        """Copy with some of the sections replaced (``discs=..., pins=...``)."""
        kw = dict(
            first_stage=self.first_stage,
            cranks=self.cranks,
            discs=self.discs,
            pins=self.pins,
            supports=self.supports,
            rated_torque=self.rated_torque,
            planets=self.planets,
            errors=self.errors,
        )
        kw.update(changes)
        return RVReducer(**kw)


def _check_pos(name: str, v: float) -> None:
    if not np.isfinite(v) or v <= 0:
        raise ParameterError(name, v, "must be finite and > 0")


def _check_int(name: str, v: int, lo: int, hi: int | None = None) -> None:
    if int(v) != v or v < lo or (hi is not None and v > hi):
        rng = f">= {lo}" if hi is None else f"in {lo}..{hi}"
        raise ParameterError(name, v, f"must be an integer {rng}")
