"""Mesh-stiffness excitation of the lumped RV model (Li et al. 2023, eqs 11 and 13).

The involute sun–planet mesh stiffness is a rectangular wave of the contact ratio expanded in a
Fourier series (eq 11); the cycloid–pin stiffness is the Fourier series (eq 13) of the loaded
contact's mesh stiffness over one mesh period (:mod:`gearte.models.cycloid_loaded_contact`).

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

import numpy as np

from gearte.errors import ParameterError
from gearte.models.cycloid_loaded_contact import fourier_fit

__all__ = [
    "involute_contact_ratio",
    "rectangular_mesh_stiffness_fourier",
    "cycloid_mesh_stiffness_fourier",
]


def involute_contact_ratio(z1: int, z2: int, module_mm: float, alpha_rad: float) -> float:
    """Transverse contact ratio ε_α [-] of a standard external spur pair (addendum = m).

    Teeth ``z1``, ``z2`` [-], module ``module_mm`` [mm], pressure angle ``alpha_rad`` [rad].

    References
    ----------
    ISO 21771:2007, Gears — Cylindrical involute gears and gear pairs — Concepts and geometry.
    """
    r1, r2 = module_mm * z1 / 2, module_mm * z2 / 2
    rb1, rb2 = r1 * np.cos(alpha_rad), r2 * np.cos(alpha_rad)
    ra1, ra2 = r1 + module_mm, r2 + module_mm
    a = r1 + r2
    path = np.sqrt(ra1**2 - rb1**2) + np.sqrt(ra2**2 - rb2**2) - a * np.sin(alpha_rad)
    return float(path / (np.pi * module_mm * np.cos(alpha_rad)))


def _check_stiffness(field: str, k: float) -> None:
    """A :class:`ParameterError` naming ``field`` unless the stiffness ``k`` [N/mm] is finite and
    > 0. (Not the plausibility floor of a linear stiffness: these are derived values, e.g. the
    single-pair stiffness of a mesh whose floored stiffness is 1 N/mm is 1/ε_α of it.)"""
    if not (np.isfinite(k) and k > 0):
        raise ParameterError(field, k, "must be finite and > 0 [N/mm]")


def rectangular_mesh_stiffness_fourier(
    single_pair_stiffness: float, contact_ratio: float, n_harmonics: int, n_samples: int = 4096
) -> tuple[float, np.ndarray, np.ndarray]:
    """Fourier series (eq 11) of the rectangular-wave involute mesh stiffness.

    Two pairs in mesh (2 k_1) over the fraction ε_α − 1 of a mesh period, one pair (k_1) over the
    rest: mean k_1 ε_α. ``single_pair_stiffness`` k_1 [N/mm] (finite, > 0), ``contact_ratio``
    ε_α [-] in (1, 2), ``n_harmonics`` kept [-], ``n_samples`` [-] points of the wave over one
    period. Returns (mean, a_l, b_l) in the units of ``single_pair_stiffness``.

    References
    ----------
    Li X., Huang J., Ding C., Guo R., Niu W. (2023). Machines 11(6), 626.
    doi:10.3390/machines11060626
    """
    _check_stiffness("single_pair_stiffness", single_pair_stiffness)
    if not 1.0 < contact_ratio < 2.0:
        raise ParameterError("contact_ratio", contact_ratio, "must be in (1, 2)")
    s = 2 * np.pi * np.arange(n_samples) / n_samples
    k = np.where(s < 2 * np.pi * (contact_ratio - 1.0), 2.0, 1.0) * single_pair_stiffness
    return fourier_fit(k, n_harmonics)


def cycloid_mesh_stiffness_fourier(
    mesh_stiffness: np.ndarray,
    n_harmonics: int,
    *,
    mean_only: bool = False,
    mean_N_per_mm: float | None = None,  # noqa: N803 - unit in the name
) -> tuple[float, np.ndarray, np.ndarray]:
    """Fourier series (eq 13) of the cycloid–pin mesh stiffness over one mesh period.

    Parameters
    ----------
    mesh_stiffness : ndarray
        Equivalent cycloid–pin stiffness [N/mm] at equally spaced positions over one mesh period
        (:attr:`gearte.models.cycloid_loaded_contact.MeshPeriodContact.mesh_stiffness`).
    n_harmonics : int
        Harmonics kept.
    mean_only : bool
        Drop the ripple (paper 004 §4.1 feeds only the mean into the model).
    mean_N_per_mm : float, optional
        Replaces the mean [N/mm], finite and > 0; the ripple is scaled with it (e.g. the paper's
        printed k_cr).

    Returns
    -------
    (mean [N/mm], a_l [N/mm], b_l [N/mm])

    References
    ----------
    Li X., Huang J., Ding C., Guo R., Niu W. (2023). Machines 11(6), 626.
    doi:10.3390/machines11060626
    """
    if mean_N_per_mm is not None:
        _check_stiffness("mean_N_per_mm", mean_N_per_mm)
    k_mean, a, b = fourier_fit(mesh_stiffness, n_harmonics)
    if mean_only:
        a, b = np.zeros_like(a), np.zeros_like(b)
    if mean_N_per_mm is not None:
        scale = mean_N_per_mm / k_mean
        k_mean, a, b = k_mean * scale, a * scale, b * scale
    return k_mean, a, b
