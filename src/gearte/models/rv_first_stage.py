"""Backlash of an RV reducer's first stage (sun–planet meshes) seen at the output.

The quasi-static RV model (:mod:`gearte.models.rv_load_sharing`) has no clearance in the
sun–planet meshes. This module adds it outside the model, as a dead zone of the output torsion
angle (docs/tolerance_grades.md, "First-stage backlash at the output", has the derivation):

* mesh ``k``'s circumferential backlash ``j_t,k = j_k − (E_sun + E_planet,k) + 2 A_a,k tan α_w``
  [mm] (DIN 3967: tooth-thickness deviations ``E`` and centre-distance deviation ``A_a``;
  ``j_k`` a backlash given directly);
* input locked, the cranks turn together (they carry the same discs), so the relative
  pitch-line displacement of every mesh is the same ``s = r_sun · i · θ_out``; with the gaps
  centred on the model's no-clearance contact the output turns freely while
  ``|s| < min_k j_t,k / 2``: a free angle ``Δθ = max(min_k j_t,k, 0) / (r_sun · i)`` [rad];
* the torsion curve becomes ``θ(T) + sign(T) Δθ/2`` (the side the output comes from at
  ``T = 0``), so lost motion, backlash and hysteresis loss each grow by ``Δθ``; the rigidity
  (read between 50 % and 100 % rated torque on one branch) and a one-directional TE do not.

References
----------
DIN 3967:1978-08 (allowances, ``j_t``). Han et al. (2023) for the RV kinematics (ratio
``i = 1 + z_p z_2 / z_1``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["mesh_backlash", "output_free_angle", "with_dead_zone", "catalogue_with_free_angle"]


def mesh_backlash(
    given: ArrayLike,
    sun_thickness: ArrayLike,
    planet_thickness: ArrayLike,
    centre_distance: ArrayLike,
    working_pressure_angle: float,
) -> np.ndarray:
    """Circumferential backlash of each sun–planet mesh [mm].

    Parameters
    ----------
    given : array_like, shape (..., N)
        Backlash given directly per mesh [mm] (0 where the classes describe it).
    sun_thickness : array_like, shape (...)
        Tooth-thickness deviation ``E_sn`` of the sun [mm] (negative: thinner).
    planet_thickness : array_like, shape (..., N)
        Tooth-thickness deviation of each planet [mm].
    centre_distance : array_like, shape (..., N)
        Centre-distance deviation ``A_a`` of each sun–planet pair [mm].
    working_pressure_angle : float
        ``α_w`` [rad].

    Returns
    -------
    numpy.ndarray, shape (..., N)
        ``j_t,k = j_k − (E_sun + E_planet,k) + 2 A_a,k tan α_w`` [mm].

    References
    ----------
    DIN 3967:1978-08; gearte.tolerance.din3967.pair_backlash_limits (the same law at the limits).
    """
    sun = np.asarray(sun_thickness, dtype=float)[..., None]
    return (
        np.asarray(given, dtype=float)
        - (sun + np.asarray(planet_thickness, dtype=float))
        + 2.0 * np.asarray(centre_distance, dtype=float) * np.tan(working_pressure_angle)
    )


def output_free_angle(backlash: ArrayLike, sun_pitch_radius: float, ratio: float) -> np.ndarray:
    """Free angle of the output (input locked) from the meshes' backlash [rad].

    Parameters
    ----------
    backlash : array_like, shape (..., N)
        Circumferential backlash ``j_t,k`` of each sun–planet mesh [mm].
    sun_pitch_radius : float
        ``r_sun = m z_1 / 2`` [mm].
    ratio : float
        Reduction ratio ``i`` of the reducer, input to output [-].

    Returns
    -------
    numpy.ndarray, shape (...)
        ``max(min_k j_t,k, 0) / (r_sun · i)`` [rad]: the smallest gap stops the cranks (they
        turn together); a negative backlash (interference) leaves no free play.

    Examples
    --------
    >>> float(output_free_angle([0.05, 0.03, 0.04], 15.0, 81.0)) * 15.0 * 81.0
    0.03
    """
    j = np.min(np.asarray(backlash, dtype=float), axis=-1)
    return np.maximum(j, 0.0) / (float(sun_pitch_radius) * float(ratio))


def with_dead_zone(
    torque: ArrayLike, angle: ArrayLike, direction: ArrayLike, free_angle: float
) -> np.ndarray:
    """A torsion curve with a dead zone of ``free_angle`` at zero torque [rad].

    Parameters
    ----------
    torque : array_like, shape (K,)
        Output torque in recording order [N·mm].
    angle : array_like, shape (K,)
        Output torsion angle without the dead zone [rad].
    direction : array_like, shape (K,)
        +1 rising / −1 falling torque per sample [-] (at zero torque the output stays on the
        side it comes from).
    free_angle : float
        Width of the dead zone [rad].

    Returns
    -------
    numpy.ndarray, shape (K,)
        ``angle + sign(T) · free_angle / 2`` (``−direction`` at ``T = 0``) [rad].
    """
    t = np.asarray(torque, dtype=float)
    side = np.where(t == 0.0, -np.sign(np.asarray(direction, dtype=float)), np.sign(t))
    return np.asarray(angle, dtype=float) + side * (0.5 * float(free_angle))


def catalogue_with_free_angle(cat, free_angle: float, rated_torque: float, fraction: float):
    """Catalogue values with a dead zone ``free_angle`` [rad] in the virtual loop and curve.

    Parameters
    ----------
    cat : gearte.models.rv_catalogue.CatalogueValues
        The virtual test without the first stage's free play.
    free_angle : float
        Output free angle [rad] (:func:`output_free_angle`).
    rated_torque : float
        Rated torque [N·mm].
    fraction : float
        Lost-motion torque, fraction of rated torque [-].

    Returns
    -------
    CatalogueValues
        The loop and curve with the dead zone (:func:`with_dead_zone`), read again by the shared
        definitions (:func:`gearte.models.catalogue.hysteresis_values`): lost motion, backlash and
        hysteresis loss grow by ``free_angle``, the rigidity is unchanged.
    """
    from gearte.models.rv_catalogue import TorsionTest, read_catalogue

    t = np.asarray(cat.curve.torque, dtype=float)
    rising = np.sign(np.diff(t, prepend=t[0]))
    rising[rising == 0] = -1.0  # the first point: approached from above (as torsion_test)
    curve = TorsionTest(t, with_dead_zone(t, cat.curve.angle, rising, free_angle))
    loop = TorsionTest(
        cat.loop.torque,
        with_dead_zone(cat.loop.torque, cat.loop.angle, cat.loop_direction, free_angle),
    )
    return read_catalogue(curve, loop, cat.loop_direction, rated_torque, fraction)
