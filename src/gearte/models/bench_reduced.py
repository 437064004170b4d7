"""Reduced RV model of one serial's bench data: hysteresis curve and angular TE per direction.

Fast enough to be fitted by least squares to thousands of bench samples in a fraction of a
second, and derived from the whole-reducer model (:mod:`gearte.models.rv_load_sharing` through
:mod:`gearte.models.rv_catalogue`) by three constants: the nominal torsional rigidity ``K_nom``
and the backlash per unit radial clearance of the cam (crank–disc) and carrier crank bearings,
``g_cam``, ``g_car`` — see :func:`gearte.runners.bench_calibration.reduced_constants`.

Hysteresis (input locked, output torque ``T`` [N·mm], branch ``s = +1`` for rising torque,
``−1`` for falling)::

    θ(T, s) = θ0 + F(T − s T_fr) + C_rig T
    F(u)    = (β/2) tanh(u / T_β) + (T_r / (f K_nom)) c_p sgn(u) |u/T_r|^p + Σ_k a_k ψ_{q_k}(u/T_r)
    β       = B0 + g_cam (c_cam − c0_cam) + g_car (c_car − c0_car),
    c_p     = 0.5 / (1 − 0.5^p),   p = 0.9
    ψ_q(x)  = sgn(x) (|x|^q − κ_q |x|^p),   κ_q = (1 − 0.5^q) / (1 − 0.5^p)

* ``β`` is the whole model's backlash, linearised in the two crank-bearing clearances about the
  design: ``B0`` the design's backlash (clearances ``c0``, profile modifications and all), ``g`` the
  backlash per mm of clearance. So ``c_cam``, ``c_car`` are the bearings' clearances themselves and
  a calibrated serial written with them does not count the design's backlash twice.
* ``F`` is the frictionless reducer: free play ``β`` taken up over a transition torque ``T_β``,
  then a stiffening elastic law (Palmgren line contact ``δ ∝ Q^0.9``); ``c_p`` makes the
  catalogue rigidity ``(T_r/2)/(θ(T_r) − θ(T_r/2))`` of the elastic part exactly ``f K_nom``, so
  ``f`` is a contact-stiffness factor on the whole model's rigidity.
* The shape terms ``a_k ψ_{q_k}`` [rad] (exponents :data:`SHAPE_EXPONENTS`) bend the elastic law
  where one exponent is not the whole model's (pins engaging one by one at low load): each is odd
  and has ``ψ_q(1) = ψ_q(1/2)``, so the catalogue rigidity stays ``f K_nom``. Nuisance parameters:
  they let the loop width be read against the reducer's true slope (the friction torque's
  interval), and describe no property of the serial.
* Friction is a torque ``T_fr`` opposing the motion inside the reducer (Coulomb), so the loop
  width is the play plus the elastic twist of ``2 T_fr``.
* ``C_rig`` [rad/(N·mm)] is the compliance of the rig (shafts, couplings, encoder mount) between
  the torque sensor and the output encoder; it carries the measured torque, not the friction.

Angular TE of direction ``d`` (+1 forward, −1 backward) at output position ``φ`` [rad]::

    TE_d(φ) = o + d (β + w)/2 + Σ_j [a_j cos(n_j φ) + b_j sin(n_j φ)] + a_e cos φ + b_e sin φ

with the error families ``j`` at their characteristic orders ``n_j``
(:func:`gearte.models.orders.rv_characteristic_orders`): the geometric errors of a part repeat
with that part's rotation; ``(a_e, b_e)`` is the output encoder's eccentricity (rig) and ``w`` the
running wind-up (elastic twist under the running friction torque) so that the forward–backward
difference is ``β + w``.

This is a reduced model: it keeps what a bench can see of the whole model (play, stiffness,
friction, the orders of the error families) and none of the load sharing; its limitations are
stated in docs/bench.md.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "STIFFNESS_EXPONENT",
    "SHAPE_EXPONENTS",
    "ReducedRV",
    "shape_basis",
    "hysteresis_parameters",
    "play",
    "HYSTERESIS_PARAMETERS",
    "hysteresis_angle",
    "te_trace",
    "te_basis",
    "hysteresis_jacobian",
    "te_orders",
    "te_coefficients",
    "parameter_names",
]

STIFFNESS_EXPONENT = 0.9
"""``p`` of the elastic law (Palmgren line contact, δ ∝ Q^0.9)."""

HYSTERESIS_PARAMETERS = (
    "cam_bearing_clearance",  # [mm]
    "carrier_bearing_clearance",  # [mm]
    "play_transition_torque",  # T_β [N·mm]
    "contact_stiffness_factor",  # f [-]
    "rig_compliance",  # C_rig [rad/(N·mm)]
    "friction_torque",  # T_fr [N·mm]
    "angle_offset",  # θ0 [rad]
)
TE_COMMON = ("te_offset", "running_windup")  # o [rad], w [rad]

SHAPE_EXPONENTS: tuple[float, ...] = (0.6, 1.5)
"""Exponents ``q_k`` of the elastic law's shape terms ``ψ_q`` (:func:`shape_basis`)."""


@dataclass(frozen=True)
class ReducedRV:
    """Constants of the reduced model of one reducer type.

    Attributes
    ----------
    rated_torque : float
        ``T_r`` [N·mm].
    nominal_rigidity : float
        ``K_nom`` [N·mm/rad], the whole model's catalogue rigidity.
    backlash_per_clearance : (float, float)
        ``(g_cam, g_car)`` [rad/mm].
    families : dict
        Error family name → order (integer harmonic of the output revolution).
    design_backlash : float
        ``B0`` [rad], the whole model's backlash of the design.
    design_clearances : (float, float)
        ``(c0_cam, c0_car)`` [mm], the design's clearances.
    shape_exponents : tuple of float
        Exponents ``q_k`` [-] of the elastic law's shape terms (:func:`shape_basis`), one fitted
        amplitude each (:meth:`shape_parameters`); ``()`` gives the single-exponent law.
    """

    rated_torque: float
    nominal_rigidity: float
    backlash_per_clearance: tuple[float, float]
    families: dict[str, int] = field(default_factory=dict)
    design_backlash: float = 0.0
    design_clearances: tuple[float, float] = (0.0, 0.0)
    shape_exponents: tuple[float, ...] = SHAPE_EXPONENTS

    def shape_parameters(self) -> tuple[str, ...]:
        """Names of the shape terms' amplitudes ``a_k`` [rad], one per exponent."""
        return tuple(f"elastic_shape_{k + 1}" for k in range(len(self.shape_exponents)))

    def family_parameters(self) -> tuple[str, ...]:
        names: list[str] = []
        for fam in (*self.families, "encoder eccentricity"):
            key = fam.replace(" ", "_")
            names += [f"{key}_cos", f"{key}_sin"]
        return tuple(names)


def parameter_names(model: ReducedRV) -> tuple[str, ...]:
    """All parameter names: hysteresis, TE common, then (cos, sin) per family and the encoder.

    Parameters
    ----------
    model : ReducedRV
        Constants of the reducer type.

    Returns
    -------
    tuple of str
        The names, in the order of the fit's parameter vector.
    """
    return (*hysteresis_parameters(model), *TE_COMMON, *model.family_parameters())


def hysteresis_parameters(model: ReducedRV) -> tuple[str, ...]:
    """The parameters of the hysteresis curve: :data:`HYSTERESIS_PARAMETERS` and the shape
    terms' amplitudes of ``model`` (:meth:`ReducedRV.shape_parameters`)."""
    return (*HYSTERESIS_PARAMETERS, *model.shape_parameters())


def shape_basis(x: ArrayLike, q: float) -> tuple[np.ndarray, np.ndarray]:
    """Shape term ``ψ_q(x) = sgn(x) (|x|^q − κ_q |x|^p)`` [-] and its slope ``dψ_q/dx`` [-].

    ``κ_q = (1 − 0.5^q)/(1 − 0.5^p)`` makes ``ψ_q(1) = ψ_q(1/2)``: a shape term bends the elastic
    law without changing its catalogue rigidity, so ``f K_nom`` stays the rigidity of the
    elastic part whatever the shape amplitudes. Odd in ``x``, zero at 0. The slope at ``x = 0``
    is evaluated at ``|x| = 1e-12``.

    Parameters
    ----------
    x : array_like
        ``u / T_r`` [-].
    q : float
        Exponent [-] (> 0).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        ``ψ_q(x)`` and ``ψ_q'(x)`` [-].
    """
    p = STIFFNESS_EXPONENT
    xa = np.asarray(x, dtype=float)
    ax = np.abs(xa)
    kappa = (1.0 - 0.5**q) / (1.0 - 0.5**p)
    value = np.sign(xa) * (ax**q - kappa * ax**p)
    axc = np.maximum(ax, 1e-12)
    slope = q * axc ** (q - 1.0) - kappa * p * axc ** (p - 1.0)
    return value, slope


def play(model: ReducedRV, p: dict) -> Any:
    """The free play ``β`` [rad] of the parameters ``p`` (module docstring; arrays broadcast).

    Parameters
    ----------
    model : ReducedRV
        Constants of the reducer type (``g``, ``B0``, ``c0``).
    p : dict
        Parameters; ``cam_bearing_clearance`` and ``carrier_bearing_clearance`` [mm] are read.

    Returns
    -------
    float or numpy.ndarray
        ``β = B0 + g_cam (c_cam − c0_cam) + g_car (c_car − c0_car)`` [rad].
    """
    g_cam, g_car = model.backlash_per_clearance
    c0_cam, c0_car = model.design_clearances
    return (
        model.design_backlash
        + g_cam * (p["cam_bearing_clearance"] - c0_cam)
        + g_car * (p["carrier_bearing_clearance"] - c0_car)
    )


def _play(p: dict, model: ReducedRV) -> Any:
    return play(model, p)


def _loading_branch(
    model: ReducedRV, params: dict, torque: ArrayLike, direction: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """The terms :func:`hysteresis_angle` and its Jacobian share: ``T`` [N·mm], ``s`` [-],
    ``u = T − s T_fr`` [N·mm], ``x = u / T_r`` [-] and the elastic scale
    ``e = T_r c_p / (f K_nom)`` [rad] (module docstring)."""
    t = np.asarray(torque, dtype=float)
    s = np.asarray(direction, dtype=float)
    tr = model.rated_torque
    u = t - s * params["friction_torque"]
    cp = 0.5 / (1.0 - 0.5**STIFFNESS_EXPONENT)
    e = tr * cp / (params["contact_stiffness_factor"] * model.nominal_rigidity)
    return t, s, u, u / tr, e


def hysteresis_angle(
    model: ReducedRV, params: dict, torque: ArrayLike, direction: ArrayLike
) -> np.ndarray:
    """Output torsion angle [rad] at the measured torques [N·mm] and branches (±1).

    Parameters
    ----------
    model : ReducedRV
        Constants of the reducer type.
    params : dict
        Parameter name (:func:`parameter_names`) → value, in the units listed with
        :data:`HYSTERESIS_PARAMETERS` ([mm], [N·mm], [-], [rad/(N·mm)], [rad]).
    torque : array_like, shape (K,)
        Measured output torque T [N·mm].
    direction : array_like, shape (K,)
        Branch s of each sample [-]: +1 rising, −1 falling torque.

    Returns
    -------
    numpy.ndarray
        θ(T, s) [rad] (module docstring).
    """
    t, _, u, x, e = _loading_branch(model, params, torque, direction)
    elastic = e * np.sign(x) * np.abs(x) ** STIFFNESS_EXPONENT
    for name, q in zip(model.shape_parameters(), model.shape_exponents, strict=True):
        elastic = elastic + params[name] * shape_basis(x, q)[0]
    play = 0.5 * _play(params, model) * np.tanh(u / params["play_transition_torque"])
    return params["angle_offset"] + play + elastic + params["rig_compliance"] * t


def hysteresis_jacobian(
    model: ReducedRV, params: dict, torque: ArrayLike, direction: ArrayLike
) -> dict[str, np.ndarray]:
    """Partial derivatives of :func:`hysteresis_angle` with respect to each of
    :data:`HYSTERESIS_PARAMETERS` [rad per parameter unit], analytic.

    At exactly ``u = T − s T_fr = 0`` the elastic law's slope ``|u|^(p−1)`` is infinite; it is
    evaluated at ``|u/T_r| = 1e-12`` there.

    Parameters
    ----------
    model : ReducedRV
        Constants of the reducer type.
    params : dict
        Parameter name (:func:`parameter_names`) → value, in the units listed with
        :data:`HYSTERESIS_PARAMETERS` ([mm], [N·mm], [-], [rad/(N·mm)], [rad]).
    torque : array_like, shape (K,)
        Measured output torque T [N·mm].
    direction : array_like, shape (K,)
        Branch s of each sample [-]: +1 rising, −1 falling torque.

    Returns
    -------
    dict
        Parameter name → ∂θ/∂parameter, shape (K,).
    """
    t, s, u, x, e = _loading_branch(model, params, torque, direction)
    tr = model.rated_torque
    g_cam, g_car = model.backlash_per_clearance
    tb = params["play_transition_torque"]
    f = params["contact_stiffness_factor"]
    p = STIFFNESS_EXPONENT
    ax = np.maximum(np.abs(x), 1e-12)
    th = np.tanh(u / tb)
    sech2 = 1.0 - th**2
    beta = _play(params, model)
    d_du = 0.5 * beta * sech2 / tb + e * p * ax ** (p - 1.0) / tr
    shape = {}
    for name, q in zip(model.shape_parameters(), model.shape_exponents, strict=True):
        value, slope = shape_basis(x, q)
        shape[name] = value
        d_du = d_du + params[name] * slope / tr
    return {
        **shape,
        "cam_bearing_clearance": 0.5 * g_cam * th,
        "carrier_bearing_clearance": 0.5 * g_car * th,
        "play_transition_torque": -0.5 * beta * sech2 * u / tb**2,
        "contact_stiffness_factor": -(e / f) * np.sign(x) * np.abs(x) ** p,
        "rig_compliance": t.copy(),
        "friction_torque": -s * d_du,
        "angle_offset": np.ones_like(t),
    }


def te_orders(model: ReducedRV) -> list[int]:
    """The distinct orders of the TE model (the families' and the encoder's order 1)."""
    out: list[int] = []
    for n in (*model.families.values(), 1):
        if int(n) not in out:
            out.append(int(n))
    return out


def te_basis(model: ReducedRV, position: ArrayLike) -> np.ndarray:
    """``(K, 1 + 2 U)`` columns ``1, cos(n φ), sin(n φ)`` for the ``U`` distinct orders of
    :func:`te_orders` (families sharing an order share its columns).

    Parameters
    ----------
    model : ReducedRV
        Constants of the reducer type.
    position : array_like, shape (K,)
        Output position φ [rad].

    Returns
    -------
    numpy.ndarray, shape (K, 1 + 2 U)
        The basis [-].
    """
    phi = np.asarray(position, dtype=float)
    cols = [np.ones_like(phi)]
    for n in te_orders(model):
        cols += [np.cos(n * phi), np.sin(n * phi)]
    return np.column_stack(cols)


def te_coefficients(model: ReducedRV, params: dict, direction: int) -> np.ndarray:
    """Coefficients of :func:`te_basis` [rad]: the offset of the direction, then per order the
    sums of the cos and sin amplitudes of the families at that order.

    Parameters
    ----------
    model : ReducedRV
        Constants of the reducer type.
    params : dict
        Parameter name (:func:`parameter_names`) → value, in the units listed with
        :data:`HYSTERESIS_PARAMETERS` ([mm], [N·mm], [-], [rad/(N·mm)], [rad]).
    direction : int
        +1 forward, −1 backward [-].

    Returns
    -------
    numpy.ndarray, shape (1 + 2 U,)
        Coefficients [rad].
    """
    orders = te_orders(model)
    c = np.zeros(1 + 2 * len(orders))
    c[0] = params["te_offset"] + 0.5 * direction * (_play(params, model) + params["running_windup"])
    for fam, n in (*model.families.items(), ("encoder eccentricity", 1)):
        key = fam.replace(" ", "_")
        k = 1 + 2 * orders.index(int(n))
        c[k] += params[f"{key}_cos"]
        c[k + 1] += params[f"{key}_sin"]
    return c


def te_trace(
    model: ReducedRV,
    params: dict,
    position: ArrayLike,
    direction: int,
    basis: np.ndarray | None = None,
) -> np.ndarray:
    """Angular TE [rad] of one direction (+1 forward, −1 backward) at output positions [rad].

    Parameters
    ----------
    model : ReducedRV
        Constants of the reducer type.
    params : dict
        Parameter name (:func:`parameter_names`) → value, in the units listed with
        :data:`HYSTERESIS_PARAMETERS` ([mm], [N·mm], [-], [rad/(N·mm)], [rad]).
    position : array_like, shape (K,)
        Output position φ [rad].
    direction : int
        +1 forward, −1 backward [-].
    basis : numpy.ndarray, optional
        :func:`te_basis` of ``position`` [-], computed once for repeated calls.

    Returns
    -------
    numpy.ndarray, shape (K,)
        TE_d(φ) [rad].
    """
    b = te_basis(model, position) if basis is None else basis
    return b @ te_coefficients(model, params, direction)
