"""Modal analysis of the lumped RV model: natural frequencies, mode shapes, rigid-body mode,
stiffness-proportional damping, damped eigenvalues and resonance warnings (Li et al. 2023, §4.1).

Functions of a :class:`gearte.models.rv_dynamics.assembly.RVDynamicModel` (its stiffness matrix
and masses); the model's methods of the same names call them.

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from gearte.models.rv_records import ModalResult
from gearte.units import deg_to_rad

if TYPE_CHECKING:  # the model calls these functions; typing only
    from gearte.models.rv_dynamics.assembly import RVDynamicModel

__all__ = [
    "ModalResult",
    "modal_analysis",
    "rigid_mode",
    "stiffness_proportional_damping",
    "damped_eigenvalues",
    "resonance_warnings",
]


def modal_analysis(
    model: RVDynamicModel, t: float = 0.0, *, input_shaft: bool = True, mesh: str = "mean"
) -> ModalResult:
    """Undamped natural frequencies [Hz] and mode shapes of ``model`` at time ``t`` [s].

    ``mesh`` selects the mesh stiffnesses ("mean", "time" or "max", see
    :meth:`RVDynamicModel.elements`); ``input_shaft=False`` removes the input torsional spring
    (the model then has the rigid-body mode of :func:`rigid_mode`).
    """
    K = model.stiffness_matrix(t, mesh=mesh, input_shaft=input_shaft)
    s = 1.0 / np.sqrt(model.mass)
    lam, vec = np.linalg.eigh(s[:, None] * K * s[None, :])
    lam = np.where(np.abs(lam) < 1e-9 * np.max(lam), 0.0, lam)
    freq = np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)
    return ModalResult(frequencies=freq, shapes=s[:, None] * vec, dof_names=model.dof_names)


def rigid_mode(model: RVDynamicModel, t: float = 0.0) -> np.ndarray:
    """Analytic rigid-body vector of ``model`` for θ_o = 1 [rad]: θ_s = i, θ_p = θ_H = 1 − z_p,
    θ_c = 1.

    Translations [mm/rad] of the carried bodies at time ``t`` [s] follow from their rotation.
    """
    p = model.params
    m, n = p.crank_count, p.disc_count
    q = np.zeros(model.n_dof)
    th_o = p.output_speed * t
    th_h = deg_to_rad(p.crank_phase_deg) + (1.0 - p.pair.pin_count) * th_o
    rate = 1.0 - p.pair.pin_count
    q[2] = p.ratio
    for i in range(m):
        psi = th_o + 2 * np.pi * i / m
        tang = p.centre_distance_mm * np.array([-np.sin(psi), np.cos(psi)])
        for b in (1 + i, 1 + m + i):
            q[3 * b : 3 * b + 2] = tang
            q[3 * b + 2] = rate
    for j in range(n):
        chi = th_h + np.pi * j
        ic = 3 * (1 + 2 * m + j)
        q[ic : ic + 2] = rate * p.pair.eccentricity_mm * np.array([-np.sin(chi), np.cos(chi)])
        q[ic + 2] = 1.0
    q[-1] = 1.0
    return q


def stiffness_proportional_damping(model: RVDynamicModel) -> float:
    """β_R = 2ζ/ω_1 [s] of ``model``: ω_1 its lowest elastic mode (with the input shaft), ζ its
    damping ratio."""
    f = modal_analysis(model).frequencies
    w1 = 2 * np.pi * f[f > 0][0]
    return 2.0 * model.params.damping_ratio / w1


def damped_eigenvalues(model: RVDynamicModel, t: float = 0.0, *, mesh: str = "max") -> np.ndarray:
    """Eigenvalues [1/s] of the first-order state matrix of ``model`` at time ``t`` [s].

    ``mesh`` as in :func:`modal_analysis` ("max": the stiffest state, for the RK4 stability
    limit).
    """
    K = model.stiffness_matrix(t, mesh=mesh)
    minv = 1.0 / model.mass
    nd = model.n_dof
    A = np.zeros((2 * nd, 2 * nd))
    A[:nd, nd:] = np.eye(nd)
    A[nd:, :nd] = -minv[:, None] * K
    A[nd:, nd:] = -minv[:, None] * (model.damping_coefficient * K)
    return np.linalg.eigvals(A)


def resonance_warnings(
    model: RVDynamicModel, margin: float = 0.1, harmonics: tuple[int, ...] = (1,)
) -> list[str]:
    """Warnings when a mesh frequency [Hz] of ``model`` × ``harmonics`` lies within ±margin of a
    natural frequency.

    ``margin`` [-] is the relative band (0.1 = ±10 %).
    """
    freqs = modal_analysis(model).frequencies
    freqs = freqs[freqs > 0]
    msgs = []
    for name, fm in model.params.frequencies().items():
        if "mesh" not in name:
            continue
        for h in harmonics:
            near = freqs[np.abs(freqs - h * fm) <= margin * h * fm]
            for fn in near:
                msgs.append(
                    f"{name} frequency {'×2 ' if h == 2 else ''}{h * fm:.1f} Hz is within "
                    f"{100 * abs(fn - h * fm) / (h * fm):.1f}% of the natural frequency "
                    f"{fn:.1f} Hz: the response is resonant and hypersensitive to damping"
                )
    return msgs
