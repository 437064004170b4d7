"""Records of the RV reducer's analyses, apart from the modules that compute them.

Load sharing and transmission error (:mod:`gearte.models.rv_load_sharing`), the virtual torsion
test and its catalogue values (:mod:`gearte.models.rv_catalogue`), the stiffness chain
(:mod:`gearte.models.rv_stiffness_chain`), the compensation's design points
(:mod:`gearte.models.rv_compensation`) and the modal analysis of the lumped dynamic model
(:mod:`gearte.models.rv_dynamics.modal`).

Kept apart from those modules, which compile kernels or import modules that do (the model's
equilibrium solvers, the dynamic model's right-hand side): a result of the RV kinds unpickles,
and its figures draw, without numba (the report process of ``gearte run`` is then forked before
the parent imports numba and imports none of the parent's kernel modules:
``NUMBA_FREE_RESULTS`` in :mod:`gearte.plotting.rv_reducer`). Each record is still importable
from the module that makes it.

References
----------
Han L., Xu W., Wang Y., Zhang Y. (2023). JERR 25(8). doi:10.9734/JERR/2023/v25i8970
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "LoadSharing",
    "TransmissionError",
    "TorsionTest",
    "CatalogueValues",
    "StiffnessChain",
    "DesignPoint",
    "Compensation",
    "ModalResult",
]


@dataclass(frozen=True)
class LoadSharing:
    """Quasi-static load sharing over output positions.

    Attributes
    ----------
    theta : (P,) output angles [rad].
    torque : float
        Output torque [N·mm].
    pin_force : (P, N, z_p) contact force of every pin on every disc [N].
    pairs_in_mesh : (P, N) loaded pins per disc [-].
    cam_bearing_load : (P, M, N) radial load of each crank's cam bearing in each disc [N].
    carrier_bearing_load : (P, M) radial load of each crank's bearing in the carrier [N].
    mesh_force : (P, M) sun–planet mesh force [N].
    disc_torque : (P, N) moment of the pin forces about each disc centre [N·mm].
    output_error : (P,) output angle error ``theta_actual − theta_nominal`` [rad]
        (negative = output lags).
    contact_stiffness : (P, N) secant pin stiffness per disc [N/mm].
    q : (P, nd) all displacements [mm, rad].
    contact_pressure : (P, N, z_p) Hertz pressure of every pin with its own flank curvature [MPa].
    contact_law : str
        Name of the pin-contact law used.
    pin_phase : (P, N, z_p) meshing phase of every pin [rad]: its angle from the line of
        centres (the disc's eccentric direction), as
        :func:`~gearte.models.rv_load_sharing.contact_phase`.
    """

    theta: np.ndarray
    torque: float
    pin_force: np.ndarray
    pairs_in_mesh: np.ndarray
    cam_bearing_load: np.ndarray
    carrier_bearing_load: np.ndarray
    mesh_force: np.ndarray
    disc_torque: np.ndarray
    output_error: np.ndarray
    contact_stiffness: np.ndarray
    q: np.ndarray
    contact_pressure: np.ndarray
    contact_law: str
    pin_phase: np.ndarray | None = None

    @property
    def peak_pin_load(self) -> float:
        """Largest pin force over the revolution [N]."""
        return float(self.pin_force.max())

    @property
    def max_contact_pressure(self) -> float:
        """Largest Hertz pin pressure over the revolution [MPa]."""
        return float(np.max(self.contact_pressure))


@dataclass(frozen=True)
class TransmissionError:
    """Loaded output angle error over a revolution, split into geometric and elastic parts.

    ``total = geometric + elastic``; geometric is the output angle error at (nearly) zero load
    ``zero_load_torque`` (errors, clearances and the preload they cause), elastic the rest.
    All [rad]. ``theta, total, geometric, elastic`` are on the requested positions (for plots);
    ``*_pp`` are peak-to-peak values over those positions *plus* one finely resolved mesh period
    around each extreme, since the mesh ripple (period
    :func:`~gearte.models.rv_load_sharing.mesh_period`, ``z_p z_c`` cycles per revolution) is
    aliased by any practical uniform sampling.
    """

    theta: np.ndarray
    total: np.ndarray
    geometric: np.ndarray
    elastic: np.ndarray
    loaded: LoadSharing
    unloaded: LoadSharing
    total_pp: float
    geometric_pp: float
    elastic_pp: float

    @staticmethod
    def peak_to_peak(x: np.ndarray) -> float:
        return float(np.max(x) - np.min(x))


@dataclass(frozen=True)
class TorsionTest:
    """Output torsion angle along a torque path (input locked).

    Attributes
    ----------
    torque : (K,) [N·mm]; angle : (K,) output torsion angle [rad] (positive with the torque).
    """

    torque: np.ndarray
    angle: np.ndarray


@dataclass(frozen=True)
class CatalogueValues:
    """Catalogue quantities [N·mm/rad, rad] and the curves they were read from.

    ``loop`` is the virtual hysteresis loop the quantities are read from by the shared
    definitions of :mod:`gearte.models.catalogue` (exactly as from a measured curve); ``curve``
    is the dense sweep for plots.
    """

    torsional_rigidity: float
    lost_motion: float
    backlash: float
    hysteresis_loss: float
    curve: TorsionTest
    loop: TorsionTest | None = None
    loop_direction: np.ndarray | None = None


@dataclass(frozen=True)
class StiffnessChain:
    """Output torsional compliance of an RV reducer and its breakdown per element.

    Attributes
    ----------
    torque : float
        Output torque of the linearisation [N·mm].
    theta : float
        Output angle [rad].
    compliance : dict
        Element → its part of the output torsional compliance [rad/(N·mm)] (elements left out
        are absent).
    left_out : tuple of str
        Elements the reducer does not describe (rigid), named.
    cam_bearing_load, carrier_bearing_load : float
        Largest radial load of a cam bearing and of a crank's carrier bearing at ``torque`` [N]
        (the operating loads to compare with the loads the bearings' stiffness was read at).
    """

    torque: float
    theta: float
    compliance: dict[str, float]
    left_out: tuple[str, ...]
    cam_bearing_load: float = float("nan")
    carrier_bearing_load: float = float("nan")

    @property
    def total_compliance(self) -> float:
        """Tangent output torsional compliance [rad/(N·mm)]."""
        return float(sum(self.compliance.values()))

    @property
    def rigidity(self) -> float:
        """Tangent output torsional rigidity [N·mm/rad]."""
        return 1.0 / self.total_compliance

    @property
    def shares(self) -> dict[str, float]:
        """Element → share of the output torsional compliance [-] (sum 1)."""
        total = self.total_compliance
        return {k: v / total for k, v in self.compliance.items()}


@dataclass(frozen=True)
class DesignPoint:
    """A design and what the model predicts for it (angles [rad], forces [N])."""

    changes: dict[str, float]
    total_te_peak_to_peak: float
    mean_lag: float
    backlash: float
    peak_pin_load: float
    pairs_in_mesh_min: int
    pairs_in_mesh_max: int
    load: LoadSharing


@dataclass(frozen=True)
class Compensation:
    """Before/after of a compensation."""

    before: DesignPoint
    after: DesignPoint
    objective: str
    min_backlash: float
    evaluations: int


@dataclass(frozen=True)
class ModalResult:
    """Natural frequencies [Hz] (ascending) and mass-normalised mode shapes (columns)."""

    frequencies: np.ndarray
    shapes: np.ndarray
    dof_names: list[str]
