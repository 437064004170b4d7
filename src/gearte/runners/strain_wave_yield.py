"""A strain-wave gear as a yield model: its lost motion and transmission error from drawn errors.

Each sample is one gear of a production lot: its hysteresis loss H and torsion at T1, θ1 [arcmin]
(normal about the catalogue's values), its wave-generator eccentricity and spline ovalities [µm]
(Rayleigh magnitudes, each with a uniform direction ``<key>_phase_rad``) and its lobe-height
difference [µm] → ``"lost_motion [arcmin]"`` (H + 2 φ(T_L), Harmonic Drive eq. 68.2–68.4) and
``"te_peak_to_peak [arcsec]"`` over one output revolution (:func:`te_peak_to_peak`).

References
----------
Harmonic Drive AG (2015) CHA manual 1018854, eq. 68.1–68.4; gearte's two-zone TE reading
(docs/strain-wave.md) of Jia et al. (2021), doi:10.1016/j.mechmachtheory.2020.104122.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from gearte.units import arcmin_to_rad, rad_to_arcmin, rad_to_arcsec, um_to_mm

__all__ = ["ERROR_KEYS", "StrainWaveYield", "te_peak_to_peak"]

#: The drawn errors: key → (unit, gear field it sets).
ERROR_KEYS: dict[str, str] = {
    "hysteresis_loss": "arcmin",
    "torsion_at_T1": "arcmin",
    "wave_generator_eccentricity": "um",
    "lobe_height_difference": "um",
    "flexspline_ovality": "um",
    "circular_spline_ovality": "um",
}


def te_peak_to_peak(
    ratio: float,
    pitch_radius: float,
    pressure_angle: float,
    engagement_depth: float,
    eccentricity: np.ndarray,
    eccentricity_angle: np.ndarray,
    lobe_difference: np.ndarray,
    fs_ovality: np.ndarray,
    cs_ovality: np.ndarray,
    cs_ovality_angle: np.ndarray,
) -> np.ndarray:
    """Peak-to-peak of the TE (eq. te) over one output revolution [rad], per sample.

    Over an output revolution the WG turns i times and the FS-ovality term drifts through every
    phase relative to the others, so ``ptp = (tan α / r) (max g − min g + 2|ε_f|)`` with
    ``g(θ) = (d/2 + e cos(θ − ψ_e))²/h + ε_c cos 2(θ − ψ_c)``, a trigonometric polynomial of
    degree 2 whose exact extremes come from :func:`gearte.solvers.trig_extremes.exact_extremes`
    (the drift covering every phase is exact as i → ∞; the report's sampled trace, 32 positions
    per WG revolution at i = 100, gave 0.7 % less for the bundled CSF-32-100-like case).

    Parameters
    ----------
    ratio : float
        i [-] (the period; the bound does not depend on it).
    pitch_radius : float
        r [mm].
    pressure_angle : float
        α [rad].
    engagement_depth : float
        h [mm].
    eccentricity, eccentricity_angle : ndarray
        e [mm], ψ_e [rad].
    lobe_difference : ndarray
        d [mm].
    fs_ovality : ndarray
        ε_f [mm].
    cs_ovality, cs_ovality_angle : ndarray
        ε_c [mm], ψ_c [rad].

    Returns
    -------
    numpy.ndarray
        [rad].

    References
    ----------
    gearte's reading (docs/strain-wave.md) of Jia et al. (2021),
    doi:10.1016/j.mechmachtheory.2020.104122.
    """
    from gearte.solvers.trig_extremes import exact_extremes

    e, pe, d = (
        np.atleast_1d(np.asarray(x, dtype=float))
        for x in (eccentricity, eccentricity_angle, lobe_difference)
    )
    ec, pc = (np.atleast_1d(np.asarray(x, dtype=float)) for x in (cs_ovality, cs_ovality_angle))
    n = max(e.size, pe.size, d.size, ec.size, pc.size, np.size(fs_ovality))
    e, pe, d, ec, pc = (np.broadcast_to(x, (n,)) for x in (e, pe, d, ec, pc))
    h = float(engagement_depth)
    c = (0.25 * d * d + 0.5 * e * e) / h
    z1 = (d * e / h) * 1j * np.exp(-1j * pe)
    z2 = (0.5 * e * e / h) * 1j * np.exp(-2j * pe) + ec * 1j * np.exp(-2j * pc)
    gmax, gmin = exact_extremes(c, np.column_stack([z1, z2]), (1, 2))
    k = math.tan(pressure_angle) / pitch_radius
    return k * (gmax - gmin + 2.0 * np.abs(np.broadcast_to(fs_ovality, (n,))))


class StrainWaveYield:
    """Lost motion and TE peak-to-peak of a strain-wave gear from its drawn errors (picklable).

    Parameters
    ----------
    gear : StrainWaveGear
        The nominal gear (its values stand in for errors a batch does not draw).
    prefix : str
        Key prefix (``"<stage slug>."`` inside a chain, ``""`` for the gear's own yield).

    Notes
    -----
    Keys and units: :data:`ERROR_KEYS`; a magnitude's direction is ``<key>_phase_rad``.
    Outputs ``"lost_motion [arcmin]"`` and ``"te_peak_to_peak [arcsec]"``.
    """

    quantities: tuple[str, ...] = ("lost_motion [arcmin]", "te_peak_to_peak [arcsec]")

    def __init__(self, gear, prefix: str = "") -> None:
        self.gear = gear
        self.prefix = prefix

    def nominal(self) -> dict[str, float]:
        """Each error key's nominal value, in its unit."""
        from gearte.units import mm_to_um

        g, e = self.gear, self.gear.errors
        return {
            "hysteresis_loss": float(rad_to_arcmin(g.hysteresis_loss)),
            "torsion_at_T1": float(rad_to_arcmin(g.T1 / g.K1)),
            "wave_generator_eccentricity": float(mm_to_um(e.wave_generator_eccentricity)),
            "lobe_height_difference": float(mm_to_um(e.lobe_height_difference)),
            "flexspline_ovality": float(mm_to_um(e.flexspline_ovality)),
            "circular_spline_ovality": float(mm_to_um(e.circular_spline_ovality)),
        }

    def _values(self, errors: Mapping[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
        nom = self.nominal()
        out = {}
        for k in ERROR_KEYS:
            key = self.prefix + k
            out[k] = np.asarray(errors[key], dtype=float) if key in errors else np.full(n, nom[k])
        return out

    def _phase(self, errors: Mapping[str, np.ndarray], k: str, default: float, n: int):
        key = f"{self.prefix}{k}_phase_rad"
        return np.asarray(errors[key], dtype=float) if key in errors else np.full(n, default)

    def lost_motion(self, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
        """Lost motion [rad] of each sample."""
        from gearte.models.strain_wave import lost_motion

        g = self.gear
        v = self._values(errors, n)
        theta1 = arcmin_to_rad(v["torsion_at_T1"])
        k1 = g.T1 / np.where(theta1 > 0, theta1, np.nan)
        lm = lost_motion(
            arcmin_to_rad(v["hysteresis_loss"]), g.lost_motion_torque, g.T1, g.T2, k1, g.K2, g.K3
        )
        return np.nan_to_num(np.asarray(lm, dtype=float), nan=0.0)

    def te_peak_to_peak(self, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
        """TE peak-to-peak over one output revolution [rad] of each sample."""
        g, e = self.gear, self.gear.errors
        v = self._values(errors, n)
        return te_peak_to_peak(
            g.ratio,
            g.pitch_radius,
            g.pressure_angle,
            g.engagement_depth,
            np.abs(um_to_mm(v["wave_generator_eccentricity"])),
            self._phase(
                errors, "wave_generator_eccentricity", e.wave_generator_eccentricity_angle, n
            ),
            um_to_mm(v["lobe_height_difference"]),
            um_to_mm(v["flexspline_ovality"]),
            np.abs(um_to_mm(v["circular_spline_ovality"])),
            self._phase(errors, "circular_spline_ovality", e.circular_spline_ovality_angle, n),
        )

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        n = next((int(np.shape(v)[0]) for v in errors.values()), 1)
        return {
            self.quantities[0]: np.asarray(rad_to_arcmin(self.lost_motion(errors, n)), dtype=float),
            self.quantities[1]: np.asarray(
                rad_to_arcsec(self.te_peak_to_peak(errors, n)), dtype=float
            ),
        }
