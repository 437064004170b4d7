"""Record of a loaded tooth contact analysis (``tooth_contact`` of
:mod:`gearte.models.cycloid_contact`).

Kept apart from the solver's module, which compiles kernels: a result of the cycloid-stage kind
unpickles, and its figures draw, without numba (the report process of ``gearte run`` imports
none of the parent's kernel modules for it: ``NUMBA_FREE_RESULTS`` in
:mod:`gearte.plotting.cycloid_stage`).

References
----------
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ToothContact"]


@dataclass(frozen=True)
class ToothContact:
    """Loaded tooth contact at one or more mesh positions (arrays over positions × pins).

    Attributes
    ----------
    mesh_angle : ndarray (n,)
        Mesh position: phase of pin 1 [rad].
    phase : ndarray (n, z_p)
        Meshing phase φ_i of every pin [rad].
    clearance : ndarray (n, z_p)
        Initial clearance Δ_i (eq 32) [mm]; NaN on the unloaded flank (sin φ ≤ 0).
    approach : ndarray (n, z_p)
        Normal deformation/approach δ_i = (l_i/r_c) δ_max (eq 37) [mm].
    force : ndarray (n, z_p)
        Contact force F_i (eq 41) [N].
    in_mesh : ndarray (n, z_p) of bool
        δ_i > Δ_i on the loaded flank.
    F_max : ndarray (n,)
        Maximum contact force (eq 44) [N].
    delta_max : ndarray (n,)
        Maximum normal deformation (eq 38) [mm].
    n_eval : ndarray (n,)
        Residual evaluations of the solver.
    T_c : float
        Torque on the disc [N·mm].
    rho : float
        Curvature radius at φ0 [mm].
    curvature : ndarray (n, z_p)
        Signed flank curvature radius where each pin touches (eq 40 at φ_i) [mm].
    pressure : ndarray (n, z_p)
        Hertz pressure of each pin with its own curvature [MPa] (0 out of mesh).
    contact_law : str
        Name of the contact law (:mod:`gearte.models.contact_law`).
    """

    mesh_angle: np.ndarray
    phase: np.ndarray
    clearance: np.ndarray
    approach: np.ndarray
    force: np.ndarray
    in_mesh: np.ndarray
    F_max: np.ndarray
    delta_max: np.ndarray
    n_eval: np.ndarray
    T_c: float
    rho: float
    curvature: np.ndarray
    pressure: np.ndarray
    contact_law: str

    @property
    def pins_in_mesh(self) -> np.ndarray:
        """Number of loaded pins at each position [-]."""
        return self.in_mesh.sum(axis=-1)

    @property
    def max_pin_force(self) -> np.ndarray:
        """Largest force carried by a pin at each position [N] (≤ F_max)."""
        return self.force.max(axis=-1)

    @property
    def max_contact_pressure(self) -> np.ndarray:
        """Largest Hertz pin pressure at each position [MPa]."""
        return self.pressure.max(axis=-1)
