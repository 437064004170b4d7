"""Records of the loaded cycloid–pin contact after Li et al. (2023) (``loaded_contact`` and
``mesh_period_contact`` of :mod:`gearte.models.cycloid_loaded_contact`).

Kept apart from the solver's module, which imports the compiled rotation solver: a result of the
RV kinds holding the contact over a mesh period unpickles, and its figures draw, without numba
(``NUMBA_FREE_RESULTS`` in :mod:`gearte.plotting.rv_reducer`). Both records are still importable
from :mod:`gearte.models.cycloid_loaded_contact`.

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["LoadedContact", "MeshPeriodContact"]


@dataclass(frozen=True)
class LoadedContact:
    """Loaded contact at one or more mesh positions (arrays over positions × pins).

    Attributes (units in brackets)
    ----------------------------------
    phi : meshing phase of each pin [rad], shape (n_pos, z_p)
    arm : l_i [mm]; clearance : Δ_i [mm]; backlash : φ_bl,i [rad]
    force : F_i [N] (0 out of contact); in_contact : bool mask
    rotation : Δφ_c, elastic rotation from first contact [rad], shape (n_pos,)
    tangential_force, radial_force : F_t, F_r [N] (eq 5, F_r summed without sign as printed)
    radial_force_signed : Σ F_i (K1 − cos φ_i)/S_i [N], the physical resultant's radial part
    pressure_angle : β = atan(F_r/F_t) [rad] (eq 7)
    mesh_stiffness : k_cr = F_cr / (r_c Δφ_c cos β) [N/mm] (eq 7, reading A)
    torsional_stiffness : T / Δφ_c [N·mm/rad]
    pressure : Hertz pressure of each pin with its own flank curvature [MPa] (0 out of contact)
    """

    phi: np.ndarray
    arm: np.ndarray
    clearance: np.ndarray
    backlash: np.ndarray
    force: np.ndarray
    in_contact: np.ndarray
    rotation: np.ndarray
    tangential_force: np.ndarray
    radial_force: np.ndarray
    radial_force_signed: np.ndarray
    pressure_angle: np.ndarray
    mesh_stiffness: np.ndarray
    torsional_stiffness: np.ndarray
    pins_in_contact: np.ndarray = field(default=None)  # type: ignore[arg-type]  # set in __post_init__
    pressure: np.ndarray = field(default=None)  # type: ignore[arg-type]  # set by loaded_contact


@dataclass(frozen=True)
class MeshPeriodContact:
    """Equivalent pressure angle and mesh stiffness over one mesh period (paper 004 Fig 9)."""

    mesh_position: np.ndarray  # [rad], over [0, 2π/z_p)
    pressure_angle: np.ndarray  # β [rad]
    mesh_stiffness: np.ndarray  # k_cr [N/mm]
    pins_in_contact: np.ndarray
    max_force: np.ndarray  # [N]
    contact: LoadedContact

    @property
    def max_contact_pressure(self) -> float:
        """Largest Hertz pin pressure over the mesh period [MPa]."""
        return float(np.max(self.contact.pressure))

    @property
    def pressure_angle_mean(self) -> float:
        """Mean β over the mesh period [rad]."""
        return float(np.mean(self.pressure_angle))

    @property
    def mesh_stiffness_mean(self) -> float:
        """Mean k_cr over the mesh period [N/mm]."""
        return float(np.mean(self.mesh_stiffness))
