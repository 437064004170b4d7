"""Compiled twins of the per-pin cycloid formulas of :mod:`gearte.geometry.cycloid`.

One kernel, :func:`pin_mesh_table`, evaluates at every mesh position and pin the meshing phase
(:func:`~gearte.geometry.cycloid.meshing_phase`), the normalised arm l/r_c = sin φ / S (eq 4,
36), the initial clearance of eq 32 (:func:`~gearte.geometry.cycloid.initial_clearance`) and the
curvature radius of eq 40 (:func:`~gearte.geometry.cycloid.curvature_radius`), for the compiled
tooth contact (:mod:`gearte.models.cycloid_contact`). The numpy functions stay the reference;
``tests/test_contact_compiled.py`` checks the twin against them to 1e-12. sin φ and cos φ come from
the sum formulas of the mesh angle and the pin offsets (no transcendental call per pin); they
differ from ``np.sin(φ)`` by rounding only.

References
----------
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481, eq 4, 32, 36, 40.
doi:10.3390/app10020481
"""

from __future__ import annotations

import math

import numpy as np

from gearte._jit import kernel

__all__ = ["pin_mesh_table"]


@kernel
def _pin_mesh_table(theta, z_p, K1, R, r, dr_rp, dr_p):  # pragma: no cover - compiled
    n = theta.shape[0]
    phase = np.empty((n, z_p))
    lr = np.empty((n, z_p))
    clr = np.empty((n, z_p))
    rho = np.empty((n, z_p))
    off = np.empty(z_p)
    sa = np.empty(z_p)
    ca = np.empty(z_p)
    for i in range(z_p):
        off[i] = 2.0 * np.pi * i / z_p
        sa[i] = math.sin(off[i])
        ca[i] = math.cos(off[i])
    two_pi = 2.0 * np.pi
    sq = math.sqrt(1.0 - K1 * K1)
    kz = K1 * (z_p + 1)
    den0 = 1.0 + z_p * K1 * K1
    for k in range(n):
        st = math.sin(theta[k])
        ct = math.cos(theta[k])
        for i in range(z_p):
            x = theta[k] + off[i]
            phase[k, i] = x if 0.0 <= x < two_pi else x % two_pi
            s = st * ca[i] + ct * sa[i]
            c = ct * ca[i] - st * sa[i]
            S = math.sqrt(1.0 + K1 * K1 - 2.0 * K1 * c)  # eq 4
            inv_S = 1.0 / S
            s_S = s * inv_S
            lr[k, i] = s_S  # eq 36 over r_c
            clr[k, i] = dr_rp * (1.0 - s_S) - dr_p * (1.0 - K1 * c - sq * s) * inv_S  # eq 32
            den = kz * c - den0
            rho[k, i] = R * S * S * S / den + r if den != 0.0 else math.inf  # eq 40
    return phase, lr, clr, rho


def pin_mesh_table(
    theta: np.ndarray,
    *,
    z_p: int,
    K1: float,
    R: float,
    r: float,
    dr_rp: float,
    dr_p: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Phase, arm ratio, eq 32 clearance and eq 40 curvature of every pin (compiled).

    Parameters
    ----------
    theta : ndarray (n,)
        Mesh positions: phase of pin 1 [rad].
    z_p : int
        Number of pins [-].
    K1 : float
        Short-width coefficient [-] (:attr:`gearte.geometry.cycloid.CycloidStage.K1`).
    R, r : float
        Pin-circle and pin radius of eq 40 [mm] (:func:`gearte.geometry.cycloid.geometry_radii`).
    dr_rp, dr_p : float
        Equidistant and shifted modifications Δr_rp, Δr_p [mm].

    Returns
    -------
    phase : ndarray (n, z_p)
        Meshing phase φ_i in [0, 2π) [rad].
    lr : ndarray (n, z_p)
        l_i / r_c = sin φ_i / S_i [-] (eq 36).
    clearance : ndarray (n, z_p)
        Δ_i of eq 32 [mm] (every pin; meaningful on the loaded flank).
    rho : ndarray (n, z_p)
        Curvature radius ρ(φ_i) of eq 40 [mm].

    References
    ----------
    Hu et al. (2020) eq 4, 32, 36, 40, doi:10.3390/app10020481.
    """
    th = np.ascontiguousarray(np.atleast_1d(np.asarray(theta, dtype=float)))
    return _pin_mesh_table(th, int(z_p), float(K1), float(R), float(r), float(dr_rp), float(dr_p))
