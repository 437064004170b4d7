"""Translational–torsional lumped dynamic model of an RV reducer (Li et al. 2023, section 3).

6M + 3N + 6 degrees of freedom (M cranks/planets, N cycloid discs): x, y, θ of the sun, of each
planet, of each crank, of each disc and of the output disc (carrier). With M = 3, N = 2: 30 DOF.

How it is built (see docs/validation/li2023.md for the derivation and every assumption):

* Coordinates are deviations from the nominal rigid motion, translations in the fixed frame and
  rotations **absolute** (measured from the housing), so the rigid kinematics are testable: with the
  input shaft spring removed the stiffness matrix has exactly one null vector, θ_s : θ_p : θ_H :
  θ_c : θ_o = 121 : −39 : −39 : 1 : 1 (plus the translations of the carried bodies).
* Every connection is an element spring (+ damper) acting on the *material points* of its two
  bodies at a contact point: a line element (involute mesh, equivalent cycloid–pin contact) along a
  direction n, or an isotropic bearing (two directions, optional radial clearance as piecewise
  stiffness), or a torsion spring. Deflection = projection of the relative displacement of the
  material points + the error offsets of the features involved.
* The geometry (planet positions on the carrier, crank eccentric direction, the pitch point of the
  cycloid–pin pair and its line of action) is evaluated on the nominal configuration at time t: the
  cycloid–pin direction rotates with the crank (the paper writes a fixed direction).
* Excitations: involute mesh stiffness (rectangular wave of the contact ratio, Fourier series,
  eq 11), cycloid–pin stiffness from the loaded contact
  (:mod:`gearte.models.cycloid_loaded_contact`,
  Fourier series, eq 13), the eccentricity/assembly errors of Table 3 on explicitly chosen
  cranks/discs, bearing clearances, constant load torque on the output, speed-controlled motor
  behind the input torsional stiffness.
* Damping: stiffness-proportional per element, c_e(t) = β_R k_e(t), with β_R = 2ζ/ω_1 so the lowest
  elastic mode has damping ratio ζ (paper 004 gives no damping).

Internal units: mm, N, s, hence mass in tonne (t = 1e3 kg) and inertia in t·mm²; inputs carry
paper units (kg, kg·m², N/m, N·m/rad, N·m, rpm) in their names and are converted once, in
:mod:`.assembly`, with the factors of :mod:`gearte.units`.

Modules (one concern each):

* :mod:`.parameters` — :class:`RVDynamicsParameters`, :class:`RVErrors` and their construction from
  the shared RV description (:func:`parameters_from_reducer`, :func:`errors_from_reducer`);
* :mod:`.mesh_stiffness` — involute and cycloid–pin mesh-stiffness excitation (eqs 11, 13);
* :mod:`.assembly` — :class:`RVDynamicModel`: elements, stiffness matrix, forces, statics, and the
  packed arguments of the compiled right-hand side;
* :mod:`.rhs` — the compiled right-hand side :func:`rv_rhs` and DTE output :func:`rv_dte`;
* :mod:`.modal` — natural frequencies, rigid-body mode, damping, resonance warnings;
* :mod:`.excitation` — per-pin and disc-profile errors as each disc's loaded rotation shift
  (:func:`disc_rotation_error`), from the same pin clearances as the quasi-static model.

Running the model (DTE, spectrum, error batches) composes it with the integrators and the
execution layer: :mod:`gearte.runners.rv_dynamics_sim`.

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from gearte.models.rv_dynamics.assembly import RVDynamicModel
from gearte.models.rv_dynamics.excitation import disc_rotation_error, has_pin_errors
from gearte.models.rv_dynamics.mesh_stiffness import (
    cycloid_mesh_stiffness_fourier,
    involute_contact_ratio,
    rectangular_mesh_stiffness_fourier,
)
from gearte.models.rv_dynamics.modal import ModalResult
from gearte.models.rv_dynamics.parameters import (
    DYNAMIC_ONLY,
    RVDynamicsParameters,
    RVErrors,
    errors_from_reducer,
    parameters_from_reducer,
)
from gearte.models.rv_dynamics.rhs import RHS_SOURCE_KEY, RHS_WORK_SIZE, rv_dte, rv_rhs

__all__ = [
    "RVDynamicsParameters",
    "RVErrors",
    "RVDynamicModel",
    "ModalResult",
    "involute_contact_ratio",
    "rectangular_mesh_stiffness_fourier",
    "cycloid_mesh_stiffness_fourier",
    "rv_rhs",
    "rv_dte",
    "RHS_SOURCE_KEY",
    "RHS_WORK_SIZE",
    "parameters_from_reducer",
    "errors_from_reducer",
    "DYNAMIC_ONLY",
    "disc_rotation_error",
    "has_pin_errors",
]
