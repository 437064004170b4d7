"""Involute spur-gear basics and the bevel pair's equivalent cylindrical pair on the back cone.

Pure vectorised functions; lengths in mm, angles in rad.

References
----------
Jiang J., Zhong X., Lv L., Lai J., Jin D. (2024) Gear backlash modeling and tolerance simulation
of fully gear-coupled robot. J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542 (§3.1, Fig. 5).
doi:10.3785/j.issn.1008-973X.2024.08.001
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "pitch_diameter",
    "base_diameter",
    "centre_distance",
    "gear_ratio",
    "bevel_pitch_cone_angles",
    "bevel_mean_diameter",
    "bevel_cone_distance",
    "virtual_spur_diameter",
    "virtual_spur_teeth",
]


def pitch_diameter(z: ArrayLike, module: ArrayLike) -> np.ndarray | float:
    """Reference (pitch) diameter ``d = z·m`` [mm] of a spur gear (``z`` teeth, module [mm]).

    >>> float(pitch_diameter(110, 2.5))
    275.0
    """
    return np.multiply(z, module) * 1.0


def base_diameter(d: ArrayLike, alpha: ArrayLike) -> np.ndarray | float:
    """Base-circle diameter ``d_b = d·cos α`` [mm] (``d`` [mm], pressure angle ``α`` [rad])."""
    return np.multiply(d, np.cos(alpha))


def centre_distance(z1: ArrayLike, z2: ArrayLike, module: ArrayLike) -> np.ndarray | float:
    """Nominal centre distance ``a = m (z₁ + z₂)/2`` [mm] of an external spur pair.

    Teeth ``z1``, ``z2`` [-], ``module`` m [mm].

    >>> float(centre_distance(28, 110, 2.5))   # Jiang et al. (2024) Table 2: 172.5 mm
    172.5

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    return np.multiply(module, np.add(z1, z2)) / 2.0


def gear_ratio(z_driving: ArrayLike, z_driven: ArrayLike) -> np.ndarray | float:
    """Reduction ratio ``i = z_driven / z_driving`` [-] (> 1 for a reduction).

    ``z_driving``, ``z_driven``: teeth of the driving and the driven gear [-].

    >>> round(float(gear_ratio(28, 110)), 3)   # Table 2: 3.929
    3.929
    """
    return np.divide(z_driven, z_driving) * 1.0


def bevel_pitch_cone_angles(
    z1: ArrayLike, z2: ArrayLike, shaft_angle: ArrayLike = np.pi / 2
) -> tuple[np.ndarray | float, np.ndarray | float]:
    """Pitch-cone angles ``(δ₁, δ₂)`` [rad] of a bevel pair with ``shaft_angle`` Σ [rad].

    Teeth ``z1``, ``z2`` [-].

    ``tan δ₁ = sin Σ / (z₂/z₁ + cos Σ)``, ``δ₂ = Σ − δ₁``. For ``z₁ = z₂`` and ``Σ = 90°``,
    ``δ₁ = δ₂ = 45°`` (the paper's pair).
    """
    u = np.divide(z2, z1)
    d1 = np.arctan2(np.sin(shaft_angle), u + np.cos(shaft_angle))
    return d1, np.subtract(shaft_angle, d1)


def bevel_mean_diameter(
    d: ArrayLike, face_width: ArrayLike, delta: ArrayLike
) -> np.ndarray | float:
    """Mean (mid-face) diameter ``d_m = d − b·sin δ`` [mm].

    ``d`` outer pitch diameter [mm], ``face_width`` b [mm], ``δ`` pitch-cone angle [rad].
    Jiang et al. (2024) Table 5: ``108.5 − 9·sin 45° = 102.1`` mm.

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    return np.subtract(d, np.multiply(face_width, np.sin(delta)))


def bevel_cone_distance(d: ArrayLike, delta: ArrayLike) -> np.ndarray | float:
    """Outer cone distance ``R = d / (2 sin δ)`` [mm] (``d`` [mm], pitch-cone angle δ [rad])."""
    return np.divide(d, 2.0 * np.sin(delta))


def virtual_spur_diameter(d: ArrayLike, delta: ArrayLike) -> np.ndarray | float:
    """Diameter ``d_v = d / cos δ`` [mm] of the equivalent spur gear on the back cone (Tredgold).

    The bevel pair is replaced by a cylindrical pair whose pitch circles are the developed back
    cones; Jiang et al. (2024) §3.1 (Fig. 5) compute the bevel backlash on that pair.
    ``d`` pitch diameter [mm], δ pitch-cone angle [rad].

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    return np.divide(d, np.cos(delta))


def virtual_spur_teeth(z: ArrayLike, delta: ArrayLike) -> np.ndarray | float:
    """Virtual number of teeth ``z_v = z / cos δ`` [-] of the back-cone equivalent spur gear.

    ``z`` teeth [-], δ pitch-cone angle [rad].
    """
    return np.divide(z, np.cos(delta))
