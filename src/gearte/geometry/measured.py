"""A measured cycloid disc: flank deviation per tooth as a function of the contact position,
and cumulative pitch per tooth (issue 16).

The measured values enter the one RV model as they are (no fitted equidistant/shift pair): at
every contact the pin–flank normal clearance of the design profile is reduced by the measured
normal deviation of the tooth space the pin is in, linearly interpolated along the flank at the
contact's profile parameter, and the tooth's cumulative pitch deviation turns the flank like a
local rotation of the disc (the rule :func:`gearte.models.rv_load_sharing.assemble` uses for the
one-sine pitch error of Hu et al. 2020).

Tooth numbering (derived from the kinematics of :mod:`gearte.geometry.rv`): with fixed pins
``alpha_k = 2 pi k / z_p`` (``k`` 0-based), disc eccentric direction ``psi = -z_c theta``
(+ ``2 pi j / N``) and disc rotation ``theta``, pin ``k`` is at meshing phase
``phi = alpha_k - psi`` and at the disc-frame angle ``beta = (2 pi k - phi) / z_c``. Writing
``phi = 2 pi m + phi0`` with ``phi0 in [-pi, pi)``, the pin sits in tooth space
``t = (k - m) mod z_c`` (0-based; its root at ``beta = 2 pi t / z_c`` from the disc's mark) at
profile parameter ``phi0`` (``0`` at the root, the flank driven forward at ``phi0 > 0``).

Outside the measured range of a tooth the deviation is held at its end value (the contact
positions a gear-measuring machine leaves out, near tip and root, carry no load).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearte.errors import ParameterError

__all__ = [
    "MeasuredDisc",
    "tooth_and_parameter",
    "apply_measurements",
    "measurements_of",
    "bore_errors",
    "cam_errors",
    "runout_errors",
]


def tooth_and_parameter(pin: np.ndarray, phase: np.ndarray, teeth: int):
    """Tooth space (0-based) and profile parameter [rad] of pin contacts.

    Parameters
    ----------
    pin : numpy.ndarray
        0-based pin index ``k`` [-] of each contact.
    phase : numpy.ndarray
        Meshing phase ``phi = alpha_k - psi`` [rad] (any range).
    teeth : int
        Tooth count ``z_c`` [-].

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Tooth space ``t`` in ``0..z_c-1`` and profile parameter ``phi0`` in ``[-pi, pi)`` [rad].
    """
    phase = np.asarray(phase, dtype=float)
    m = np.floor((phase + np.pi) / (2.0 * np.pi))
    phi0 = phase - 2.0 * np.pi * m
    tooth = np.mod(np.asarray(pin) - m.astype(np.int64), teeth)
    return tooth, phi0


@dataclass(frozen=True, eq=False)  # holds arrays
class MeasuredDisc:
    """Measured flanks and pitch of one cycloid disc.

    Attributes
    ----------
    teeth : int
        ``z_c`` [-].
    profile_phase, profile_deviation : tuple of numpy.ndarray or None
        Per tooth space, the strictly increasing profile parameters [rad] within
        ``[-pi, pi]`` and the normal deviations [mm] (positive = more material, less
        clearance); None: the design flank.
    cumulative_pitch : numpy.ndarray or None
        ``(z_c,)`` cumulative pitch deviation of each tooth space along the pitch circle [mm]
        (positive counter-clockwise); None: none.
    serial : str
        The disc's serial number (reports).
    """

    teeth: int
    profile_phase: tuple[np.ndarray, ...] | None = None
    profile_deviation: tuple[np.ndarray, ...] | None = None
    cumulative_pitch: np.ndarray | None = None
    serial: str = ""

    def __post_init__(self) -> None:
        if (self.profile_phase is None) != (self.profile_deviation is None):
            raise ParameterError("profile", None, "give both phases and deviations, or neither")
        if self.profile_phase is not None and self.profile_deviation is not None:
            if len(self.profile_phase) != self.teeth or len(self.profile_deviation) != self.teeth:
                raise ParameterError(
                    "profile", len(self.profile_phase), f"needs one trace per tooth ({self.teeth})"
                )
            xs, ys = [], []
            for t, (ph, dv) in enumerate(
                zip(self.profile_phase, self.profile_deviation, strict=True)
            ):
                ph, dv = np.asarray(ph, float), np.asarray(dv, float)
                if ph.ndim != 1 or ph.shape != dv.shape or ph.size < 2:
                    raise ParameterError(f"profile[{t}]", ph.shape, "needs >= 2 points")
                if np.any(np.diff(ph) <= 0) or ph[0] < -np.pi - 1e-9 or ph[-1] > np.pi + 1e-9:
                    raise ParameterError(
                        f"profile[{t}]", ph, "must increase strictly within [-pi, pi] rad"
                    )
                if not np.all(np.isfinite(dv)) or np.any(np.abs(dv) > 0.5):
                    raise ParameterError(f"profile[{t}]", dv, "deviations must be within 0.5 mm")
                # pad to [-pi, pi] with the end values, then lay the teeth side by side
                ph = np.concatenate([[-np.pi - 1e-6], ph, [np.pi + 1e-6]])
                dv = np.concatenate([[dv[0]], dv, [dv[-1]]])
                xs.append(ph + 4.0 * np.pi * t)
                ys.append(dv)
            object.__setattr__(self, "_x", np.concatenate(xs))
            object.__setattr__(self, "_y", np.concatenate(ys))
        if self.cumulative_pitch is not None:
            cp = np.asarray(self.cumulative_pitch, dtype=float)
            if cp.shape != (self.teeth,) or not np.all(np.isfinite(cp)) or np.any(abs(cp) > 0.5):
                raise ParameterError(
                    "cumulative_pitch", cp.shape, f"needs {self.teeth} finite values within 0.5 mm"
                )
            object.__setattr__(self, "cumulative_pitch", cp)

    def deviation(self, tooth: np.ndarray, parameter: np.ndarray) -> np.ndarray:
        """Measured normal deviation [mm] at ``(tooth, parameter)`` (0 where not measured).

        Parameters
        ----------
        tooth : numpy.ndarray
            0-based tooth space [-].
        parameter : numpy.ndarray
            Profile parameter in ``[-pi, pi)`` [rad].
        """
        if self.profile_phase is None:
            return np.zeros(np.broadcast(tooth, parameter).shape)
        x = np.asarray(parameter, float) + 4.0 * np.pi * np.asarray(tooth)
        return np.interp(x, self._x, self._y)  # type: ignore[attr-defined]  # set in post_init

    def pitch(self, tooth: np.ndarray) -> np.ndarray:
        """Cumulative pitch deviation [mm] of tooth spaces ``tooth`` (0-based)."""
        if self.cumulative_pitch is None:
            return np.zeros(np.shape(tooth))
        return self.cumulative_pitch[np.asarray(tooth)]

    def gap_change(
        self, pin: np.ndarray, phase: np.ndarray, rotation_arm: np.ndarray, pitch_radius: float
    ) -> np.ndarray:
        """Change of the pin–flank normal clearance [mm] the measurement causes.

        Parameters
        ----------
        pin : numpy.ndarray
            0-based pin index of each contact [-].
        phase : numpy.ndarray
            Meshing phase of each contact [rad].
        rotation_arm : numpy.ndarray
            Approach of the contact per unit disc rotation [mm/rad] (the rotation column of the
            contact row).
        pitch_radius : float
            Disc pitch radius ``a z_c`` [mm].

        Returns
        -------
        numpy.ndarray
            ``-(deviation + arm * pitch / r_c)`` [mm], to add to the design clearance.
        """
        tooth, phi0 = tooth_and_parameter(pin, phase, self.teeth)
        out = -self.deviation(tooth, phi0)
        if self.cumulative_pitch is not None:
            out = out - rotation_arm * self.pitch(tooth) / pitch_radius
        return out

    def scaled(self, factor: float) -> MeasuredDisc:
        """The deviations multiplied by ``factor`` [-]."""
        return MeasuredDisc(
            self.teeth,
            self.profile_phase,
            None
            if self.profile_deviation is None
            else tuple(d * factor for d in self.profile_deviation),
            None if self.cumulative_pitch is None else self.cumulative_pitch * factor,
            self.serial,
        )


def _rot2(v: np.ndarray, ang: np.ndarray | float) -> np.ndarray:
    c, s = np.cos(ang), np.sin(ang)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def bore_errors(positions: np.ndarray, circle_radius: float) -> np.ndarray:
    """Crank-bore errors in each bore's radial frame [mm] from measured centres.

    Parameters
    ----------
    positions : numpy.ndarray
        ``(..., M, 2)`` bore centres in the disc frame [mm] (bore ``i`` nominally at angle
        ``2 pi i / M``).
    circle_radius : float
        Crank circle radius ``R_dc`` [mm].
    """
    m = positions.shape[-2]
    ang = 2.0 * np.pi * np.arange(m) / m
    nominal = circle_radius * np.stack([np.cos(ang), np.sin(ang)], -1)
    return _rot2(positions - nominal, -ang)


def cam_errors(eccentricity: np.ndarray, phase: np.ndarray, design: float) -> np.ndarray:
    """Cam error vectors ``e u(phase) - a u(0)`` [mm] in the crank frame.

    Parameters
    ----------
    eccentricity : numpy.ndarray
        Measured eccentricities [mm].
    phase : numpy.ndarray
        Eccentric direction from the nominal one [rad].
    design : float
        Design eccentricity ``a`` [mm].
    """
    return np.stack([eccentricity * np.cos(phase) - design, eccentricity * np.sin(phase)], -1)


def runout_errors(runout: np.ndarray) -> np.ndarray:
    """Eccentricity vectors [mm] (run-out / 2 at the high point) from ``(..., 2)`` rows of
    run-out [mm] and angle [rad].

    Parameters
    ----------
    runout : numpy.ndarray
        ``(..., 2)``: total indicator reading [mm], high-point angle [rad].
    """
    r = np.asarray(runout, dtype=float)
    return 0.5 * r[..., :1] * np.stack([np.cos(r[..., 1]), np.sin(r[..., 1])], -1)


def apply_measurements(
    reducer,
    *,
    discs: list[MeasuredDisc | None] | None = None,
    disc_bores: np.ndarray | None = None,
    cam_eccentricity: np.ndarray | None = None,
    cam_phase: np.ndarray | None = None,
    planet_runout: np.ndarray | None = None,
    sun_runout: np.ndarray | None = None,
    pin_diameters: np.ndarray | None = None,
    slot_radial: np.ndarray | None = None,
    slot_tangential: np.ndarray | None = None,
    cam_clearance: np.ndarray | None = None,
    carrier_clearance: np.ndarray | None = None,
):
    """The reducer with measured part values in place of the design's (None: keep the design's).

    Parameters
    ----------
    reducer : gearte.geometry.rv.RVReducer
        The design (its errors are kept for every family not measured).
    discs : list of MeasuredDisc or None, optional
        Per disc (in assembly order), its measured flanks and pitch.
    disc_bores : numpy.ndarray, optional
        ``(N, M, 2)`` crank-bore centres of each disc in its own frame [mm].
    cam_eccentricity, cam_phase : numpy.ndarray, optional
        ``(M, N)`` measured eccentricity [mm] and eccentric direction from the nominal [rad] of
        cam ``j`` of the crank at carrier position ``i``.
    planet_runout : numpy.ndarray, optional
        ``(M, 2)`` run-out (TIR) [mm] and high-point angle [rad] of each planet.
    sun_runout : numpy.ndarray, optional
        ``(2,)`` run-out [mm] and angle [rad] of the sun.
    pin_diameters : numpy.ndarray, optional
        ``(z_p,)`` pin diameters [mm].
    slot_radial, slot_tangential : numpy.ndarray, optional
        ``(z_p,)`` pin-slot centre deviations [mm].
    cam_clearance, carrier_clearance : numpy.ndarray, optional
        ``(M, N)`` and ``(M,)`` measured bearing clearances [mm].

    Returns
    -------
    gearte.geometry.rv.RVReducer

    Notes
    -----
    Error vectors in the frames of :mod:`gearte.geometry.rv`: bore error = measured − nominal
    centre (nominal ``R_dc u(2 pi i / M)``) turned into the bore's radial frame; cam error =
    ``e u(phase) − a u(0)``; planet and sun eccentricity = run-out / 2 at the high point; pin
    radius error = diameter / 2 − ``r_rp``.
    """
    import dataclasses

    err = reducer.error_set
    m, n = reducer.cranks.count, reducer.discs.count
    ch: dict = {}
    if discs is not None:
        if len(discs) != n:
            raise ParameterError("discs", len(discs), f"needs one entry per disc ({n})")
        for j, d in enumerate(discs):
            if d is not None and d.teeth != reducer.cycloid_teeth:
                raise ParameterError(
                    f"discs[{j}].teeth", d.teeth, f"the design has {reducer.cycloid_teeth} teeth"
                )
        ch["measured_discs"] = tuple(discs)
    if disc_bores is not None:
        xy = np.asarray(disc_bores, dtype=float).reshape(n, m, 2)
        ch["disc_bore"] = bore_errors(xy, reducer.cranks.circle_radius)
    if cam_eccentricity is not None:
        e = np.asarray(cam_eccentricity, dtype=float).reshape(m, n)
        ph = np.zeros((m, n)) if cam_phase is None else np.asarray(cam_phase, float).reshape(m, n)
        ch["cam"] = cam_errors(e, ph, reducer.cranks.eccentricity)
    if planet_runout is not None:
        ch["planet"] = runout_errors(np.asarray(planet_runout, dtype=float).reshape(m, 2))
    if sun_runout is not None:
        rs = np.asarray(sun_runout, dtype=float).reshape(2)
        ch["sun"] = 0.5 * rs[0] * np.array([np.cos(rs[1]), np.sin(rs[1])])
    if cam_clearance is not None:
        ch["cam_clearance"] = np.asarray(cam_clearance, dtype=float).reshape(m, n)
    if carrier_clearance is not None:
        ch["carrier_clearance"] = np.asarray(carrier_clearance, dtype=float).reshape(m)
    pins = reducer.pins
    pch: dict = {}
    if pin_diameters is not None:
        pch["radius_errors"] = 0.5 * np.asarray(pin_diameters, dtype=float) - pins.pin_radius
    if slot_radial is not None:
        pch["radial_position_errors"] = np.asarray(slot_radial, dtype=float)
    if slot_tangential is not None:
        pch["tangential_position_errors"] = np.asarray(slot_tangential, dtype=float)
    out = reducer.with_errors(dataclasses.replace(err, **ch))
    if pch:
        out = out.replace(pins=dataclasses.replace(pins, **pch))
    return out


def measurements_of(reducer) -> dict[str, np.ndarray]:
    """What a metrology lab would measure on ``reducer``'s parts: the inverse of
    :func:`apply_measurements` (keyword → array, same units and shapes).

    Parameters
    ----------
    reducer : gearte.geometry.rv.RVReducer
        A reducer with errors (its disc bore, cam, planet, sun and pin errors are converted).
    """
    err = reducer.error_set
    m = reducer.cranks.count
    ang = 2.0 * np.pi * np.arange(m) / m
    nominal = reducer.cranks.circle_radius * np.stack([np.cos(ang), np.sin(ang)], -1)
    cam = err.cam + np.array([reducer.cranks.eccentricity, 0.0])
    pl, sun = err.planet, err.sun
    return {
        "disc_bores": nominal[None] + _rot2(err.disc_bore, ang[None, :]),
        "cam_eccentricity": np.hypot(cam[..., 0], cam[..., 1]),
        "cam_phase": np.arctan2(cam[..., 1], cam[..., 0]),
        "planet_runout": np.stack(
            [2.0 * np.hypot(pl[:, 0], pl[:, 1]), np.arctan2(pl[:, 1], pl[:, 0])], -1
        ),
        "sun_runout": np.array([2.0 * np.hypot(*sun), np.arctan2(sun[1], sun[0])]),
        "pin_diameters": 2.0 * (reducer.pins.pin_radius + reducer.pins.radius_errors),
        "slot_radial": reducer.pins.radial_position_errors.copy(),
        "slot_tangential": reducer.pins.tangential_position_errors.copy(),
    }
