"""Drives as yield models: vectorised functions of drawn errors for :func:`run_yield`.

Each class holds one drive's nominal description and maps a batch of drawn errors (keyed as
the drive's case file keys them, in the unit the key names) to the quantities a spec can
bound. They are picklable (module-level classes), so processes and Dask can run them.

* :class:`CycloidGeometricTE` — cycloid–pin stage, the nine component errors of Hu et al.
  (2020) Table 2 [µm] → geometric TE (lost motion of the stage) [arcmin]: the eight linear
  factors through their gains, the eccentricity error through its exact second-order effect
  (:func:`gearte.models.cycloid_te.eccentricity_te`), the design modifications as constants.
  Replaces the RSS-only band of eq. 17 by the distribution.
* :class:`PlanetaryCoupledTE` — 2K-H planetary, eccentricity magnitudes [µm] and directions
  [deg] (Wang et al. 2013) → exact coupled TE amplitude and peak-to-peak [arcsec]
  (:func:`gearte.models.planetary_errors.sample_extremes`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from gearte.units import deg_to_rad, rad_to_arcmin, rad_to_arcsec, um_to_mm

__all__ = ["CycloidGeometricTE", "PlanetaryCoupledTE"]


def _n(errors: Mapping[str, np.ndarray]) -> int:
    for v in errors.values():
        return int(np.shape(v)[0])
    return 1


class CycloidGeometricTE:
    """Geometric TE of a cycloid stage as a function of its nine component errors.

    Parameters
    ----------
    stage : CycloidStage
        The nominal stage (with its modifications).
    nominal_um : mapping
        Error factor → value [µm] used where a batch does not draw the factor (its mean).

    Notes
    -----
    ``TE = Σ_mod Δθ + Σ_j g_j e_j + Δθ_ecc(δa)`` [rad] (Hu et al. 2020 eq 5–16; the
    eccentricity term is gearte's second-order reading, see :mod:`gearte.models.cycloid_te`).
    Output ``"geometric_te [arcmin]"``.

    References
    ----------
    Hu Y. et al. (2020) Applied Sciences 10(2), 481. doi:10.3390/app10020481
    """

    def __init__(self, stage, nominal_um: Mapping[str, float] | None = None) -> None:
        from gearte.models.cycloid_te import ERROR_FACTORS, factor_contributions, te_gradients

        self.stage = stage
        self.factors = ERROR_FACTORS
        self.nominal_um = {k: float((nominal_um or {}).get(k, 0.0)) for k in ERROR_FACTORS}
        contrib = factor_contributions(stage, {})
        self.modifications = float(
            contrib["equidistant_modification"]
            + contrib["shifted_modification"]
            + contrib["rotation_modification"]
        )
        self.gradients = te_gradients(stage)

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        from gearte.models.cycloid_te import eccentricity_te

        n = _n(errors)
        te = np.full(n, self.modifications)
        for k in self.factors:
            e = np.asarray(
                um_to_mm(errors[k] if k in errors else np.full(n, self.nominal_um[k])),
                dtype=float,
            )
            if k == "eccentricity_error":
                nz = e != 0.0
                if np.any(nz):
                    te[nz] += eccentricity_te(self.stage, e[nz])
            else:
                te += self.gradients[k] * e
        return {"geometric_te [arcmin]": np.asarray(rad_to_arcmin(te), dtype=float)}


class PlanetaryCoupledTE:
    """Exact coupled TE of a 2K-H planetary as a function of its errors.

    Parameters
    ----------
    terms : TermSet
        The equivalent mesh-error terms (derived or as given).
    nominal_magnitudes_um : mapping
        Magnitude key → value [µm] where a batch does not draw it.
    nominal_angles_deg : mapping
        Angle key → value [deg] where a batch does not draw it (missing: 0).

    Notes
    -----
    ``amplitude = max_t |Σ e(t)|·|scale|``, ``peak_to_peak = (max − min)·|scale|`` (Wang et al.
    2013 eqs 7–9, exact extremes). Outputs ``"coupled_te_amplitude [arcsec]"`` and
    ``"coupled_te_peak_to_peak [arcsec]"``.

    References
    ----------
    Wang C. et al. (2013) Trans. CSAM 44(8), 287–292. doi:10.6041/j.issn.1000-1298.2013.08.049
    """

    def __init__(
        self,
        terms,
        nominal_magnitudes_um: Mapping[str, float],
        nominal_angles_deg: Mapping[str, float] | None = None,
    ) -> None:
        self.terms = terms
        self.mag_nom = {k: float(nominal_magnitudes_um.get(k, 0.0)) for k in terms.magnitudes}
        self.ang_nom = {k: float((nominal_angles_deg or {}).get(k, 0.0)) for k in terms.angles}

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        from gearte.models.planetary_errors import sample_extremes

        n = _n(errors)
        mags = np.column_stack(
            [
                um_to_mm(np.asarray(errors[k], dtype=float))
                if k in errors
                else np.full(n, float(um_to_mm(self.mag_nom[k])))
                for k in self.terms.magnitudes
            ]
        )
        if self.terms.angles:
            angs = np.column_stack(
                [
                    deg_to_rad(np.asarray(errors[k], dtype=float))
                    if k in errors
                    else np.full(n, float(deg_to_rad(self.ang_nom[k])))
                    for k in self.terms.angles
                ]
            )
        else:
            angs = np.zeros((n, 0))
        fmax, fmin = sample_extremes(self.terms, mags, angs)
        s = abs(self.terms.scale)
        return {
            "coupled_te_amplitude [arcsec]": np.asarray(
                rad_to_arcsec(np.maximum(fmax, -fmin) * s), dtype=float
            ),
            "coupled_te_peak_to_peak [arcsec]": np.asarray(
                rad_to_arcsec((fmax - fmin) * s), dtype=float
            ),
        }
