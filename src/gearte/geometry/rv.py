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
* Roller bearings (crank needle bearings, carrier crank bearings, main bearings): either given,
  or derived from the Palmgren line-contact deflection ``delta = 3.84e-5 Q^0.9 / l^0.8`` per race
  with the Stribeck load of the most loaded roller ``Q = 4.08 F_r / Z`` —
  :func:`gearte.models.rv_stiffness.roller_bearing_radial_stiffness`.
* Involute mesh: given, or ``c_gamma * b`` with ``c_gamma`` the ISO 6336-1 mean mesh stiffness
  per unit face width (:func:`gearte.models.rv_stiffness.iso6336_mesh_stiffness`).
* The rest of the stiffness chain (``docs/rv-stiffness-chain.md``), each optional here and
  named "left out" by the stiffness-chain analysis when None: the pin seat and pin bending
  (:attr:`PinRing.seat_compliance`, :attr:`PinRing.bending_compliance`, in series with each
  pin contact), crank bending at each cam (:attr:`Cranks.bending_compliance`, in series with
  that cam's bearing), crank torsion between planet and cams (:attr:`Cranks.torsional_stiffness`,
  in series with the sun–planet mesh) and the output flange
  (:attr:`Supports.output_torsional_stiffness`, in series with the output rotation).

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

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from gearte.errors import ParameterError
from gearte.geometry.planetary import EccentricityError, SunPlanetErrors, SunPlanets
from gearte.limits import check_floor

__all__ = [
    "FirstStage",
    "Cranks",
    "Discs",
    "PinRing",
    "Supports",
    "ErrorEntry",
    "ManufacturingErrors",
    "ERROR_PARTS",
    "MassProperties",
    "mass_properties",
    "RVReducer",
    "PinContacts",
    "pin_contacts",
]


@dataclass(frozen=True)
class FirstStage:
    """Involute first stage: sun (input) and ``M`` planets, each fixed to a crankshaft; no ring.

    Its gears are the gear set of the ``planetary`` kind without a ring
    (:class:`gearte.geometry.planetary.SunPlanets`: the same class, the same validation).

    Attributes
    ----------
    gears : SunPlanets
        Sun and planets: tooth numbers ``z_1``, ``z_2``, module [mm], standard pressure angle
        [rad], number of planets (= cranks), planet position angles.
    mesh_stiffness : float
        Sun–planet mesh stiffness along the line of action [N/mm].
    sun_support_stiffness : float
        Radial stiffness of the sun (input shaft) support [N/mm]; small = floating sun.
    face_width : float or None
        Face width of the sun and planets [mm] (needed only to derive their masses).
    """

    gears: SunPlanets
    mesh_stiffness: float
    sun_support_stiffness: float
    face_width: float | None = None

    def __post_init__(self) -> None:
        if self.gears.z_ring is not None:
            raise ParameterError(
                "first_stage.ring", self.gears.z_ring, "an RV first stage has no ring"
            )
        _check_pos("first_stage.mesh_stiffness", self.mesh_stiffness)
        _check_pos("first_stage.sun_support_stiffness", self.sun_support_stiffness)
        if self.face_width is not None:
            _check_pos("first_stage.face_width", self.face_width)

    @property
    def sun_teeth(self) -> int:
        """``z_1`` [-]."""
        return self.gears.z_sun

    @property
    def planet_teeth(self) -> int:
        """``z_2`` [-]."""
        return self.gears.z_planet

    @property
    def module(self) -> float:
        """Module [mm]."""
        return self.gears.module

    @property
    def pressure_angle(self) -> float:
        """Standard pressure angle [rad]."""
        return self.gears.pressure_angle

    @property
    def base_radii(self) -> tuple[float, float]:
        """Base radii of sun and planet [mm]."""
        return self.gears.base_radius("sun"), self.gears.base_radius("planet")


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
    shaft_diameter, shaft_length : float or None
        Crankshaft envelope [mm] (needed only to derive its mass and inertia).
    bending_compliance : tuple of float or None
        Bending compliance of the crank at the cam of each disc [mm/N], one per disc, in series
        with that cam's bearing; None: left out (rigid, named so by the stiffness chain).
    torsional_stiffness : float or None
        Torsional stiffness of one crank between its planet and its cams [N·mm/rad], in series
        with the sun–planet mesh; None: left out.
    """

    count: int
    circle_radius: float
    eccentricity: float
    cam_bearing_stiffness: float
    carrier_bearing_stiffness: float
    cam_bearing_clearance: float = 0.0
    carrier_bearing_clearance: float = 0.0
    shaft_diameter: float | None = None
    shaft_length: float | None = None
    bending_compliance: tuple[float, ...] | None = None
    torsional_stiffness: float | None = None

    def __post_init__(self) -> None:
        _check_int("cranks.count", self.count, 2, 6)
        for name in ("shaft_diameter", "shaft_length"):
            if getattr(self, name) is not None:
                _check_pos(f"cranks.{name}", getattr(self, name))
        _check_pos("cranks.circle_radius", self.circle_radius)
        _check_pos("cranks.eccentricity", self.eccentricity)
        _check_pos("cranks.cam_bearing_stiffness", self.cam_bearing_stiffness)
        _check_pos("cranks.carrier_bearing_stiffness", self.carrier_bearing_stiffness)
        for name in ("cam_bearing_clearance", "carrier_bearing_clearance"):
            v = getattr(self, name)
            if not np.isfinite(v) or not 0.0 <= v <= 0.2:
                raise ParameterError(f"cranks.{name}", v, "must be in [0, 0.2] mm")
        if self.bending_compliance is not None:
            _check_compliances("cranks.bending_compliance", self.bending_compliance)
        if self.torsional_stiffness is not None:
            _check_pos("cranks.torsional_stiffness", self.torsional_stiffness)


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
        ``E`` [MPa] of disc and pins, at least the plausibility floor of a Young's modulus
        (1 000 MPa, ``gearte.limits.FLOORS``).
    poisson_ratio : float
        ``mu`` [-].
    crank_bore_diameter, centre_bore_diameter : float or None
        Diameters of the crank bores and of the central bore [mm] (needed only to derive the
        disc's mass and inertia; no central bore when None).
    contact_law : str
        Name of the pin-contact law (``gearte.models.contact_law``: ``"line_contact"``, the
        textbook default, or ``"hu2020"``); every analysis of the reducer uses it.
    """

    count: int
    face_width: float
    equidistant_modification: float
    shift_modification: float
    youngs_modulus: float
    poisson_ratio: float
    crank_bore_diameter: float | None = None
    centre_bore_diameter: float | None = None
    contact_law: str = "line_contact"

    def __post_init__(self) -> None:
        _check_int("discs.count", self.count, 1, 3)
        for name in ("crank_bore_diameter", "centre_bore_diameter"):
            if getattr(self, name) is not None:
                _check_pos(f"discs.{name}", getattr(self, name))
        _check_pos("discs.face_width", self.face_width)
        for name in ("equidistant_modification", "shift_modification"):
            v = getattr(self, name)
            if not np.isfinite(v) or abs(v) > 0.5:
                raise ParameterError(f"discs.{name}", v, "must be finite with |value| <= 0.5 mm")
        _check_pos("discs.youngs_modulus", self.youngs_modulus)
        check_floor("discs.youngs_modulus", self.youngs_modulus, "youngs_modulus")
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
    seat_compliance : float or None
        Compliance of a pin's seat in its housing groove [mm/N], in series with each pin–disc
        contact; None: left out (rigid, named so by the stiffness chain).
    bending_compliance : tuple of float or None
        Bending compliance of a pin at the mid-plane of each disc [mm/N], one per disc, in
        series with that disc's pin contacts; None: left out.
    """

    count: int
    pin_radius: float
    circle_radius: float
    radius_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    radial_position_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    tangential_position_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    seat_compliance: float | None = None
    bending_compliance: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        _check_int("pins.count", self.count, 8, 200)
        _check_pos("pins.pin_radius", self.pin_radius)
        _check_pos("pins.circle_radius", self.circle_radius)
        if self.seat_compliance is not None:
            _check_compliances("pins.seat_compliance", (self.seat_compliance,))
        if self.bending_compliance is not None:
            _check_compliances("pins.bending_compliance", self.bending_compliance)
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
    main_bearing_clearance : float
        Radial clearance of the main bearings [mm] (Li 2023 ``ε_h``; used by the dynamics).
    carrier_outer_diameter, carrier_length : float or None
        Envelope of the carrier (output flange + end plate) [mm], needed only to derive its mass.
    output_torsional_stiffness : float or None
        Torsional stiffness of the carrier / output flange between the crank bores and the
        output face [N·mm/rad], in series with the output rotation; None: left out.
    """

    carrier_radial_stiffness: float
    main_bearing_clearance: float = 0.0
    carrier_outer_diameter: float | None = None
    carrier_length: float | None = None
    output_torsional_stiffness: float | None = None

    def __post_init__(self) -> None:
        _check_pos("supports.carrier_radial_stiffness", self.carrier_radial_stiffness)
        if self.output_torsional_stiffness is not None:
            _check_pos("supports.output_torsional_stiffness", self.output_torsional_stiffness)
        v = self.main_bearing_clearance
        if not np.isfinite(v) or not 0.0 <= v <= 0.2:
            raise ParameterError("supports.main_bearing_clearance", v, "must be in [0, 0.2] mm")
        for name in ("carrier_outer_diameter", "carrier_length"):
            if getattr(self, name) is not None:
                _check_pos(f"supports.{name}", getattr(self, name))


@dataclass(frozen=True)
class ErrorEntry:
    """One eccentricity (position) error of one part.

    Attributes
    ----------
    part : str
        One of :data:`ERROR_PARTS`: ``"sun_eccentricity"``, ``"sun_assembly"``,
        ``"planet_eccentricity"``, ``"cam"``, ``"disc_crank_bore"``, ``"carrier_crank_bore"``,
        ``"output_assembly"``.
    crank : int or None
        Crank (= planet) index, 1-based as in the papers' tables; required for the per-crank
        parts, omitted for the sun and output parts.
    disc : int or None
        Disc index, 1-based; required for ``disc_crank_bore`` and ``cam``.
    value : float
        Magnitude [mm].
    angle : float
        Angle [rad] in the part's frame (module docstring).
    """

    part: str
    crank: int | None
    disc: int | None
    value: float
    angle: float


ERROR_PARTS = (
    "sun_eccentricity",
    "sun_assembly",
    "planet_eccentricity",
    "cam",
    "disc_crank_bore",
    "disc_radial_runout",
    "disc_cumulative_pitch",
    "carrier_crank_bore",
    "output_assembly",
)
"""Parts that carry an eccentricity error, in the order of the power flow."""

_DISC_ONLY = ("disc_radial_runout", "disc_cumulative_pitch")
_FIRST_STAGE = ("sun_eccentricity", "sun_assembly", "planet_eccentricity")
_NO_CRANK = ("sun_eccentricity", "sun_assembly", "output_assembly", *_DISC_ONLY)
_NEEDS_DISC = ("disc_crank_bore", "cam", *_DISC_ONLY)


def _zeros2() -> np.ndarray:
    return np.zeros(2)


def _empty_per_disc() -> np.ndarray:
    return np.zeros((0, 2))  # replaced by zeros((N, 2)) once N is known


@dataclass(frozen=True, eq=False)  # holds arrays: compare fields explicitly
class ManufacturingErrors:
    """Eccentricity errors as error vectors ``value (cos angle, sin angle)`` [mm].

    Attributes
    ----------
    planet : numpy.ndarray
        ``(M, 2)`` planet eccentricity (Han Table 1 base-circle eccentricity; Li Table 3
        ``E_p``) in the planet frame, from disc 1's eccentric direction.
    disc_bore : numpy.ndarray
        ``(N, M, 2)`` disc ``j`` crank bore ``i`` (Han Table 2; Li ``E^H_c``), radial frame.
    cam : numpy.ndarray
        ``(M, N, 2)`` crank ``i`` cam for disc ``j`` (Han Table 3; Li ``E_d``).
    carrier_bore : numpy.ndarray
        ``(M, 2)`` carrier (output disc) crank bore (Han Table 4; Li ``E^H_o``), radial frame.
    sun : numpy.ndarray
        ``(2,)`` sun eccentricity (Li ``E_s``), rotating with the sun, from its angle 0.
    sun_seat : numpy.ndarray
        ``(2,)`` sun assembly error (Li ``E_sa``): fixed offset of the sun's support seat,
        ground frame.
    output_seat : numpy.ndarray
        ``(2,)`` output assembly error (Li ``E_o``): fixed offset of the carrier's main-bearing
        seat, ground frame.
    disc_runout : numpy.ndarray
        ``(N, 2)`` radial run-out of disc ``j``'s tooth profile (Hu 2020 ``F_r``): offset of the
        profile centre from the crank-bore pattern's centre, disc frame.
    disc_pitch : numpy.ndarray
        ``(N, 2)`` cumulative pitch error of disc ``j`` (Hu 2020 ``ΔF_p``): magnitude = the
        peak-to-peak cumulative pitch deviation along the pitch circle [mm], read as one sine per
        revolution ``s(ψ) = ΔF_p/2 · sin(ψ − angle)`` at the disc-frame angle ``ψ``.
    disc_modification : numpy.ndarray
        ``(N, 2)`` errors of disc ``j``'s equidistant and shifted modifications
        ``(δΔr_rp, δΔr_p)`` [mm] (Hu 2020 Table 2 rows f, g per disc), added to the nominal ones.
    measured_discs : tuple or None
        Per disc, a :class:`gearte.geometry.measured.MeasuredDisc` (measured flank deviation per
        tooth and cumulative pitch per tooth, issue 16) or None; None: no measured disc.
    cam_clearance, carrier_clearance : numpy.ndarray or None
        Measured radial clearances [mm] of each cam bearing ``(M, N)`` and each crank's carrier
        bearing ``(M,)``, replacing the ``Cranks`` values; None: those of ``Cranks``.
    """

    planet: np.ndarray
    disc_bore: np.ndarray
    cam: np.ndarray
    carrier_bore: np.ndarray
    sun: np.ndarray = field(default_factory=_zeros2)
    sun_seat: np.ndarray = field(default_factory=_zeros2)
    output_seat: np.ndarray = field(default_factory=_zeros2)
    disc_runout: np.ndarray = field(default_factory=_empty_per_disc)
    disc_pitch: np.ndarray = field(default_factory=_empty_per_disc)
    disc_modification: np.ndarray = field(default_factory=_empty_per_disc)
    measured_discs: tuple | None = None
    cam_clearance: np.ndarray | None = None
    carrier_clearance: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = self.disc_bore.shape[0]
        for name in ("disc_runout", "disc_pitch", "disc_modification"):
            if getattr(self, name).size == 0:
                object.__setattr__(self, name, np.zeros((n, 2)))

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
            if e.part not in ERROR_PARTS:
                raise ParameterError(f"{f}.part", e.part, f"must be one of {ERROR_PARTS}")
            if e.part in _NO_CRANK:
                if e.crank is not None:
                    raise ParameterError(
                        f"{f}.crank", e.crank, f"must be omitted for part {e.part!r}"
                    )
            elif e.crank is None or not 1 <= e.crank <= n_cranks:
                raise ParameterError(
                    f"{f}.crank", e.crank, f"crank index must be in 1..{n_cranks} (cranks.count)"
                )
            if e.part in _NEEDS_DISC:
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
            if e.part in _FIRST_STAGE:  # the eccentricity object of the planetary kind
                vec = EccentricityError(e.value, e.angle, f"{f}.value").vector
            else:
                vec = e.value * np.array([np.cos(e.angle), np.sin(e.angle)])
            ci = -1 if e.crank is None else e.crank - 1  # checked above where required
            dj = -1 if e.disc is None else e.disc - 1
            if e.part == "sun_eccentricity":
                out.sun[:] = vec
            elif e.part == "sun_assembly":
                out.sun_seat[:] = vec
            elif e.part == "output_assembly":
                out.output_seat[:] = vec
            elif e.part == "disc_radial_runout":
                out.disc_runout[dj] = vec
            elif e.part == "disc_cumulative_pitch":
                out.disc_pitch[dj] = vec
            elif e.part == "planet_eccentricity":
                out.planet[ci] = vec
            elif e.part == "carrier_crank_bore":
                out.carrier_bore[ci] = vec
            elif e.part == "disc_crank_bore":
                out.disc_bore[dj, ci] = vec
            else:
                out.cam[ci, dj] = vec
        return out

    @property
    def first_stage(self) -> SunPlanetErrors:
        """Sun eccentricity, sun assembly error and each planet's eccentricity as the
        eccentricity-error object of the ``planetary`` kind [mm, rad]."""
        return SunPlanetErrors.from_vectors(self.sun, self.sun_seat, self.planet)

    def with_first_stage(self, errors: SunPlanetErrors) -> ManufacturingErrors:
        """Copy with the first-stage errors of ``errors`` (one planet entry per crank).

        Raises
        ------
        ParameterError
            Naming ``planet_eccentricity`` when the planet count differs from the cranks.
        """
        errors.check_planets(self.planet.shape[0])
        sun, seat, planet = errors.vectors()
        return dataclasses.replace(self, sun=sun, sun_seat=seat, planet=planet)

    def scaled(self, factor: float) -> ManufacturingErrors:
        """All errors multiplied by ``factor`` (0 removes them)."""
        return ManufacturingErrors(
            self.planet * factor,
            self.disc_bore * factor,
            self.cam * factor,
            self.carrier_bore * factor,
            self.sun * factor,
            self.sun_seat * factor,
            self.output_seat * factor,
            self.disc_runout * factor,
            self.disc_pitch * factor,
            self.disc_modification * factor,
            None
            if self.measured_discs is None
            else tuple(None if m is None else m.scaled(factor) for m in self.measured_discs),
            self.cam_clearance,
            self.carrier_clearance,
        )

    def with_disc_modification(self, errors: np.ndarray) -> ManufacturingErrors:
        """Copy with per-disc modification errors ``(N, 2)`` = ``(δΔr_rp, δΔr_p)`` [mm]."""
        return dataclasses.replace(self, disc_modification=np.asarray(errors, dtype=float))

    def amplitudes(self) -> dict[str, float]:
        """Largest magnitude of each part's error [mm] (the tolerance of a random batch)."""

        def mx(v: np.ndarray) -> float:
            return float(np.max(np.hypot(v[..., 0], v[..., 1]), initial=0.0))

        return {
            "sun_eccentricity": mx(self.sun),
            "sun_assembly": mx(self.sun_seat),
            "planet_eccentricity": mx(self.planet),
            "cam": mx(self.cam),
            "disc_crank_bore": mx(self.disc_bore),
            "disc_radial_runout": mx(self.disc_runout),
            "disc_cumulative_pitch": mx(self.disc_pitch),
            "carrier_crank_bore": mx(self.carrier_bore),
            "output_assembly": mx(self.output_seat),
        }


@dataclass(frozen=True, eq=False)  # holds arrays: compare fields explicitly
class RVReducer:
    """A whole RV reducer.

    Attributes
    ----------
    first_stage, cranks, discs, pins, supports : see the classes above.
    errors : ManufacturingErrors
        Measured errors (default none).
    rated_torque : float or None
        Rated output torque [N·mm] (catalogue value; needed by the virtual torsion test only).
    planets : int, optional
        Number of planets of the first stage; must equal ``cranks.count`` (default: that of
        ``first_stage.gears``).

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
    rated_torque: float | None
    planets: int | None = None
    errors: ManufacturingErrors | None = None

    def __post_init__(self) -> None:
        planets = self.first_stage.gears.n_planets if self.planets is None else self.planets
        if planets != self.first_stage.gears.n_planets:
            raise ParameterError(
                "first_stage.planets",
                planets,
                f"must equal the gear set's n_planets = {self.first_stage.gears.n_planets}",
            )
        if planets != self.cranks.count:
            raise ParameterError(
                "first_stage.planets",
                planets,
                f"must equal cranks.count = {self.cranks.count} (each planet drives one crank)",
            )
        if self.rated_torque is not None:
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
        for name, per_disc in (
            ("cranks.bending_compliance", self.cranks.bending_compliance),
            ("pins.bending_compliance", self.pins.bending_compliance),
        ):
            if per_disc is not None and len(per_disc) != n:
                raise ParameterError(name, per_disc, f"needs one value per disc ({n})")
        err = self.errors if self.errors is not None else ManufacturingErrors.none(m, n)
        shapes = {
            "errors.planet": (err.planet.shape, (m, 2)),
            "errors.disc_bore": (err.disc_bore.shape, (n, m, 2)),
            "errors.cam": (err.cam.shape, (m, n, 2)),
            "errors.carrier_bore": (err.carrier_bore.shape, (m, 2)),
            "errors.sun": (err.sun.shape, (2,)),
            "errors.sun_seat": (err.sun_seat.shape, (2,)),
            "errors.output_seat": (err.output_seat.shape, (2,)),
            "errors.disc_runout": (err.disc_runout.shape, (n, 2)),
            "errors.disc_pitch": (err.disc_pitch.shape, (n, 2)),
            "errors.disc_modification": (err.disc_modification.shape, (n, 2)),
        }
        for name, (got, want) in shapes.items():
            if got != want:
                raise ParameterError(name, got, f"shape must be {want} for {m} cranks, {n} discs")
        object.__setattr__(self, "errors", err)
        object.__setattr__(self, "planets", planets)

    @property
    def error_set(self) -> ManufacturingErrors:
        """The reducer's errors (never None after construction: none given = no errors)."""
        assert self.errors is not None  # noqa: S101 - set in __post_init__
        return self.errors

    # ---- derived quantities -------------------------------------------------------------
    @property
    def cycloid_teeth(self) -> int:
        """``z_c = z_p - 1``."""
        return self.pins.count - 1

    @property
    def K1(self) -> float:  # noqa: N802 - paper symbol
        """Short-width coefficient ``K1 = a z_p / (r_p + Δr_p)`` (Hu 2020 eq 3): the cycloid
        stage's own (:func:`gearte.geometry.cycloid.short_width_coefficient`, the K1 of
        :class:`~gearte.geometry.cycloid.CycloidStage`)."""
        from gearte.geometry.cycloid import short_width_coefficient

        return short_width_coefficient(
            self.pins.count,
            self.pins.circle_radius,
            self.cranks.eccentricity,
            self.discs.shift_modification,
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
        return dataclasses.replace(self, errors=errors)

    def replace(self, **changes) -> RVReducer:
        """Copy with some of the sections replaced (``discs=..., pins=...``)."""
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True)
class PinContacts:
    """Geometry and initial clearance of every pin contact of every disc at output angles.

    Attributes (shape ``(P, N, z_p)`` over output angles, discs and pins, plus a trailing 2 for
    vectors)
    ----------
    theta : numpy.ndarray
        Output (carrier) angles [rad], ``(P,)``.
    normal : numpy.ndarray
        Unit contact normal ``n`` (towards the pin centre: from the pitch point, or on a shifted
        design profile from the true contact point), ground frame.
    lever : numpy.ndarray
        Contact point − disc centre [mm].
    arm : numpy.ndarray
        ``lever × n`` [mm]: the moment arm of the normal about the disc centre (the rotation
        column of the contact row; negative on the flank that carries the output torque).
    phase : numpy.ndarray
        Meshing phase ``φ = α_k − χ_j`` of pin ``k`` on disc ``j`` [rad].
    gap : numpy.ndarray
        Initial normal clearance [mm] at the nominal positions: the eq-32 clearance of the
        disc's modified profile (nominal modifications + that disc's modification errors),
        minus the pin-radius error, plus the pin-centre error on the normal, minus the disc's
        radial run-out on the normal, minus the arm × the local rotation of the cumulative
        pitch deviation, plus the change a measured disc causes
        (:meth:`gearte.geometry.measured.MeasuredDisc.gap_change`).
    """

    theta: np.ndarray
    normal: np.ndarray
    lever: np.ndarray
    arm: np.ndarray
    phase: np.ndarray
    gap: np.ndarray


def _sum2(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``np.sum`` of ``[x, y]`` stacked on a last axis, bit for bit, without the reduction.

    ``np.add.reduce`` starts from its identity ``+0.0``: ``(0 + x) + y``, which differs from
    ``x + y`` in the sign of a zero sum of two negative zeros.
    """
    return (0.0 + x) + y


def pin_contacts(reducer: RVReducer, theta: np.ndarray) -> PinContacts:
    """Contact normals, arms and initial clearances of all pins of all discs (every error family).

    The one computation of the pin clearances that the quasi-static model
    (:func:`gearte.models.rv_load_sharing.assemble`) and the dynamics
    (:func:`gearte.models.rv_dynamics.disc_rotation_error`) read. All discs are computed at
    once; only the cumulative pitch error and a measured disc are added disc by disc.

    Parameters
    ----------
    reducer : RVReducer
        The description with its errors (per-pin radius and position, disc run-out and
        cumulative pitch, per-disc modification errors).
    theta : numpy.ndarray
        Output angles [rad], ``(P,)``.

    Returns
    -------
    PinContacts

    Notes
    -----
    Disc ``j``'s eccentric points along ``χ_j = −z_c θ + 2π j / N`` (module conventions); its
    pitch point is ``P_j = a z_p ê(χ_j)``; the normal of pin ``k`` (centre ``p_k`` at
    ``α_k = 2π k / z_p``) passes through ``P_j`` and ``p_k`` (Hu 2020 eq 36), the contact point
    lies ``r_rp`` inside the pin centre on it. On a design with a shifted modification
    (Δr_p ≠ 0) the normal is turned to where the real pin touches the design's ground profile
    (:func:`gearte.geometry.cycloid.true_contact`: through the pin's centre, not the pitch
    point; up to a few degrees near the root), and the arm is that normal's. Only the nominal
    Δr_p turns it: the normals and arms are a property of the geometry, the same for every
    sample of a yield; a disc's modification error, like a measured flank, enters the clearance
    only. The clearance of the modified profile is Hu 2020
    eq 32 (:func:`gearte.geometry.cycloid.normal_clearance_unclosed`). Disc errors are in the
    disc frame, which turns with the carrier (angle ``θ``): the run-out ``r`` translates the
    profile (gap ``−n·r``); the cumulative pitch deviation ``s(ψ) = ΔF_p/2 sin(ψ − angle)`` at
    the contact's disc-frame angle ``ψ`` turns the flank locally by ``s / r_c`` (gap
    ``−arm · s / r_c``).

    References
    ----------
    Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481, eq 32, 36.
    doi:10.3390/app10020481
    """
    from gearte.geometry.cycloid import normal_clearance_unclosed, true_contact

    th = np.atleast_1d(np.asarray(theta, dtype=float))
    P = th.size
    N = reducer.discs.count
    pins, err = reducer.pins, reducer.error_set
    zp, zc = pins.count, reducer.cycloid_teeth
    a = reducer.cranks.eccentricity
    alpha_k = 2.0 * np.pi * np.arange(zp) / zp
    pin_dir = np.stack([np.cos(alpha_k), np.sin(alpha_k)], -1)  # (zp, 2)
    pin_pos = pins.circle_radius * pin_dir
    pin_err = pins.radial_position_errors[:, None] * pin_dir + pins.tangential_position_errors[
        :, None
    ] * np.stack([-pin_dir[:, 1], pin_dir[:, 0]], -1)
    ecc = -zc * th[:, None] + 2.0 * np.pi * np.arange(N)[None, :] / N  # (P, N)
    cx, cy = np.cos(ecc)[..., None], np.sin(ecc)[..., None]  # (P, N, 1): eccentric direction
    # components (P, N, zp) of the pin's offset from the pitch point, its normal and lever
    vx = pin_pos[:, 0] - a * zp * cx
    vy = pin_pos[:, 1] - a * zp * cy
    norm = np.sqrt(_sum2(vx * vx, vy * vy))  # numpy.linalg.norm, bit for bit
    nx, ny = vx / norm, vy / norm
    lx = pin_pos[:, 0] - pins.pin_radius * nx - a * cx
    ly = pin_pos[:, 1] - pins.pin_radius * ny - a * cy
    phi = alpha_k[None, None, :] - ecc[:, :, None]
    dr_p = float(reducer.discs.shift_modification)
    if dr_p != 0.0:
        # the design's shifted profile: the real pin touches it where the profile's normal
        # passes through the pin's centre (gearte.geometry.cycloid.true_contact), not the pitch
        # point. The nominal Δr_p only: the rows are a property of the geometry, the same for
        # every sample of a yield; a disc's modification error enters through the gap below.
        turn = true_contact(phi, z_p=zp, r_p=pins.circle_radius, a=a, dr_p=dr_p)[2]
        ct, st = np.cos(turn), np.sin(turn)
        nx, ny = ct * nx - st * ny, st * nx + ct * ny
        lx = pin_pos[:, 0] - pins.pin_radius * nx - a * cx
        ly = pin_pos[:, 1] - pins.pin_radius * ny - a * cy
    n = np.stack([nx, ny], -1)
    lever = np.stack([lx, ly], -1)
    arm = lx * ny - ly * nx
    # each disc's modified profile (nominal modifications + that disc's modification errors)
    mods = np.stack(
        [
            reducer.discs.equidistant_modification + err.disc_modification[:, 0],
            reducer.discs.shift_modification + err.disc_modification[:, 1],
        ],
        -1,
    )  # (N, 2): dr_rp, dr_p
    if np.all(mods.view(np.int64) == mods[:1].view(np.int64)):  # one profile, bit for bit
        gap = normal_clearance_unclosed(
            phi, z_p=zp, r_p=pins.circle_radius, a=a, dr_rp=mods[0, 0], dr_p=mods[0, 1]
        )
    else:
        gap = np.empty((P, N, zp))
        for j in range(N):
            gap[:, j] = normal_clearance_unclosed(
                phi[:, j], z_p=zp, r_p=pins.circle_radius, a=a, dr_rp=mods[j, 0], dr_p=mods[j, 1]
            )
    gap = gap - pins.radius_errors + _sum2(nx * pin_err[:, 0], ny * pin_err[:, 1])
    c, s_ = np.cos(th)[:, None], np.sin(th)[:, None]
    rx, ry = err.disc_runout[:, 0], err.disc_runout[:, 1]
    runout_x = (rx * c - ry * s_)[..., None]  # (P, N, 1): disc frame -> ground
    runout_y = (rx * s_ + ry * c)[..., None]
    gap = gap - _sum2(nx * runout_x, ny * runout_y)
    for j in range(N):
        fp = float(np.hypot(*err.disc_pitch[j]))
        if fp > 0.0:
            psi = np.arctan2(ly[:, j], lx[:, j]) - th[:, None]
            ang = np.arctan2(err.disc_pitch[j, 1], err.disc_pitch[j, 0])
            gap[:, j] = gap[:, j] - arm[:, j] * 0.5 * fp * np.sin(psi - ang) / (a * zc)
        measured = None if err.measured_discs is None else err.measured_discs[j]
        if measured is not None:  # measured flank per tooth and pitch per tooth (issue 16)
            gap[:, j] = gap[:, j] + measured.gap_change(
                np.arange(zp)[None, :], phi[:, j], arm[:, j], a * zc
            )
    return PinContacts(th, n, lever, arm, phi, gap)


@dataclass(frozen=True)
class MassProperties:
    """Masses [kg] and polar moments of inertia [kg·m²] of the RV reducer's bodies.

    Attributes
    ----------
    mass_kg, inertia_kgm2 : dict
        Per body (``"sun"``, ``"planet"``, ``"crank"``, ``"disc"``, ``"output"``): one planet,
        one crank, one disc.
    derived : tuple of str
        The bodies whose values were derived from geometry and density (not given).
    """

    mass_kg: dict[str, float]
    inertia_kgm2: dict[str, float]
    derived: tuple[str, ...]


_MASS_INPUTS = {
    "sun": ("first_stage.face_width_mm",),
    "planet": ("first_stage.face_width_mm",),
    "crank": ("cranks.shaft_diameter_mm", "cranks.shaft_length_mm"),
    "disc": ("discs.crank_bore_diameter_mm",),
    "output": ("supports.carrier_outer_diameter_mm", "supports.carrier_length_mm"),
}


def mass_properties(
    reducer: RVReducer,
    density: float | None,
    given_mass: dict[str, float] | None = None,
    given_inertia: dict[str, float] | None = None,
) -> MassProperties:
    """Masses and inertias of the reducer's bodies: the given ones, the rest from geometry.

    Parameters
    ----------
    reducer : RVReducer
        The description; its optional envelope dimensions are used for derived bodies.
    density : float or None
        Material density [kg/m³]; required when any body is derived.
    given_mass : dict, optional
        Masses [kg] given by the case, per body name.
    given_inertia : dict, optional
        Polar moments of inertia [kg·m²] given by the case, per body name.

    Returns
    -------
    MassProperties

    Raises
    ------
    ParameterError
        Naming the missing key (``density_kg_per_m3`` or the envelope dimension) when a body's
        mass or inertia is neither given nor derivable.

    Notes
    -----
    Solid bodies of revolution (a derivation of gearte, not from a paper): sun and planet are
    cylinders of their pitch diameter ``m z`` and the first-stage face width; the crank is a
    cylinder of its shaft envelope; the disc is a cylinder of radius ``r_p + Δr_p − r_rp − Δr_rp``
    (the radius on which its tooth profile oscillates ±a) and width ``b`` less its ``M`` crank
    bores (on the crank circle) and central bore; the carrier is a cylinder of its envelope.
    ``m = rho V``, ``J = m r² / 2`` per cylinder, bores subtracted with the parallel-axis term.
    Li et al. 2023 Table 2 gives 2.76 kg for its disc; this rule gives 2.0 kg from its
    Table 1 geometry without bores — good for the order of magnitude of the modes, not better.

    References
    ----------
    Li X. et al. (2023), Machines 11(6), 626, Table 2. doi:10.3390/machines11060626
    """
    given_mass = dict(given_mass or {})
    given_inertia = dict(given_inertia or {})
    fs, cr, di, pins, sup = (
        reducer.first_stage,
        reducer.cranks,
        reducer.discs,
        reducer.pins,
        reducer.supports,
    )

    def envelope(body: str, dims: tuple[float, ...], rho: float) -> tuple[float, float]:
        """Mass [kg] and inertia [kg·m²] of ``body`` from its envelope ``dims`` [mm]."""

        def cyl(radius: float, length: float) -> tuple[float, float]:
            v = np.pi * radius**2 * length * 1e-9  # mm^3 -> m^3
            m = rho * v
            return m, 0.5 * m * (radius * 1e-3) ** 2

        if body in ("sun", "planet"):
            z = fs.sun_teeth if body == "sun" else fs.planet_teeth
            return cyl(fs.module * z / 2.0, dims[0])
        if body in ("crank", "output"):
            return cyl(dims[0] / 2.0, dims[1])
        r_out = pins.circle_radius + di.shift_modification - pins.pin_radius
        r_out -= di.equidistant_modification
        m, j = cyl(r_out, di.face_width)
        rb = dims[0] / 2.0
        mb, jb = cyl(rb, di.face_width)
        m -= cr.count * mb
        j -= cr.count * (jb + mb * (cr.circle_radius * 1e-3) ** 2)
        if di.centre_bore_diameter is not None:
            mc, jc = cyl(di.centre_bore_diameter / 2.0, di.face_width)
            m, j = m - mc, j - jc
        return m, j

    values = {
        "sun": (fs.face_width,),
        "planet": (fs.face_width,),
        "crank": (cr.shaft_diameter, cr.shaft_length),
        "disc": (di.crank_bore_diameter,),
        "output": (sup.carrier_outer_diameter, sup.carrier_length),
    }
    mass: dict[str, float] = {}
    inertia: dict[str, float] = {}
    derived: list[str] = []
    for body, keys in _MASS_INPUTS.items():
        if body in given_mass and body in given_inertia:
            mass[body], inertia[body] = float(given_mass[body]), float(given_inertia[body])
            continue
        dims = tuple(v for v in values[body] if v is not None)
        if density is None or len(dims) < len(keys):
            missing = [k for k, v in zip(keys, values[body], strict=True) if v is None]
            if density is None:
                missing.insert(0, "density_kg_per_m3 (or material)")
            what = "mass" if body not in given_mass else "inertia"
            raise ParameterError(
                "reducer." + missing[0].split(" ")[0],
                None,
                f"needed to derive the {body} {what} (or give {body}_mass_kg and "
                f"{body}_inertia_kgm2 in [reducer.dynamics]); missing: {', '.join(missing)}",
            )
        m, j = envelope(body, dims, float(density))
        if m <= 0 or j <= 0:
            raise ParameterError(
                "reducer." + keys[0], values[body][0], f"leaves no material in the {body}"
            )
        mass[body] = float(given_mass.get(body, m))
        inertia[body] = float(given_inertia.get(body, j))
        derived.append(body)
    return MassProperties(mass, inertia, tuple(derived))


def _check_pos(name: str, v: float) -> None:
    if not np.isfinite(v) or v <= 0:
        raise ParameterError(name, v, "must be finite and > 0")


def _check_compliances(name: str, v: tuple[float, ...]) -> None:
    arr = np.asarray(v, dtype=float)
    if arr.ndim != 1 or not np.all(np.isfinite(arr)) or np.any(arr < 0.0):
        raise ParameterError(name, v, "must be finite compliances >= 0 [mm/N]")


def _check_int(name: str, v: int, lo: int, hi: int | None = None) -> None:
    if int(v) != v or v < lo or (hi is not None and v > hi):
        rng = f">= {lo}" if hi is None else f"in {lo}..{hi}"
        raise ParameterError(name, v, f"must be an integer {rng}")
