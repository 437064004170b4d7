"""Pin and disc-profile errors as a rotation excitation of each disc's cycloid–pin spring.

The lumped model (Li et al. 2023) joins each disc to the pin ring by one equivalent spring, so
errors that sit on single pins (radius, radial and tangential position) or on a disc's profile
(radial run-out, cumulative pitch, modification errors of that disc) cannot enter it as offsets
of a part. They enter as what they do to the loaded contact: at every output angle, the disc
must turn by ``Δθ_j(θ)`` more (or less) than with the nominal pins and profile before the pins
carry the same torque. :func:`disc_rotation_error` computes ``Δθ_j`` from the same per-pin
clearances as the quasi-static model (:func:`gearte.geometry.rv.pin_contacts`) and the same
contact law (:func:`gearte.models.rv_load_sharing.contact_law`); the dynamic model then reads
the spring's deflection as ``n·u_j + g_θ (θ_j − Δθ_j(θ_o))``, so a static solution of the
dynamic model turns each disc by ``Δθ_j`` against the error-free one.

What is approximated (documented in docs/rv-reducer-description.md): each disc is solved alone,
turning about its fixed centre under its share ``T/N`` of the output torque (the quasi-static
model also lets it translate on its cam bearings and shares the torque between the discs by
their stiffness); the equivalent spring's stiffness ripple stays that of the nominal pair.

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Machines 11(6), 626, eq 3-4.
doi:10.3390/machines11060626
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481, eq 32, 37-44.
doi:10.3390/app10020481
"""

from __future__ import annotations

import numpy as np

from gearte.errors import ParameterError
from gearte.geometry.rv import (
    ManufacturingErrors,
    PinContacts,
    PinRing,
    RVReducer,
    pin_contacts,
)
from gearte.solvers.contact import solve_rotation

__all__ = ["disc_rotation_error", "has_pin_errors", "loaded_disc_rotation"]


def has_pin_errors(reducer: RVReducer) -> bool:
    """Whether ``reducer`` has an error that acts on single pin contacts.

    Per-pin radius or position errors, disc radial run-out, disc cumulative pitch error, a
    per-disc modification error or a measured disc.
    """
    e, p = reducer.error_set, reducer.pins
    return bool(
        np.any(e.disc_runout != 0)
        or np.any(e.disc_pitch != 0)
        or np.any(e.disc_modification != 0)
        or np.any(p.radius_errors != 0)
        or np.any(p.radial_position_errors != 0)
        or np.any(p.tangential_position_errors != 0)
        or (e.measured_discs is not None and any(m is not None for m in e.measured_discs))
    )


def loaded_disc_rotation(
    contacts: PinContacts,
    a0: np.ndarray,
    a1: np.ndarray,
    torque_per_disc: float,
    guess: np.ndarray | None = None,
    *,
    rtol: float = 1e-10,
    power: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (lag) of each disc about its fixed centre that carries ``torque_per_disc``.

    Parameters
    ----------
    contacts : PinContacts
        Arms and initial clearances of every pin (:func:`gearte.geometry.rv.pin_contacts`).
    a0, a1 : numpy.ndarray
        Contact-law coefficients per contact, shape ``(P, N, z_p)`` [mm/N]
        (:meth:`gearte.models.rv_load_sharing.PinContactLaw.coefficients`).
    torque_per_disc : float
        Torque each disc carries [N·mm], > 0.
    guess : numpy.ndarray, optional
        ``(P, N)`` elastic rotation [rad] near the answer (e.g. without the errors): the start
        of each Newton iteration; by default each row starts from the previous row's answer.
    rtol : float
        Relative tolerance on the elastic rotation [-].
    power : (numpy.ndarray, numpy.ndarray), optional
        ``(a2, a3)`` [mm/N^a3, -] per contact, ``(P, N, z_p)``, of a power law
        ``δ = a2 F^a3`` (Palmgren's;
        ``a0 = a1 = 0``; :meth:`gearte.models.rv_load_sharing.PinContactLaw.law_coefficients`).

    Returns
    -------
    numpy.ndarray
        ``(P, N)`` rotation [rad], positive = lag (the direction the output torque turns the
        disc): the rotation at first contact ``min_k g_k / l_k`` plus the elastic rotation;
        and ``(P, N)`` the elastic rotation alone [rad].

    Notes
    -----
    Pin ``k`` carries load on the flank where its arm ``l_k = −arm_k > 0``; compatibility
    ``δ_k = l_k φ − g_k`` and equilibrium ``Σ F(δ_k) l_k = T`` (Li 2023 eq 3–4; Hu 2020
    eq 37–44), ``F(δ)`` the inverse of the contact law
    (:func:`gearte.models.contact_law.force_from_coefficients`). ``T(φ)`` increases; the root
    is found by the compiled safeguarded Newton iteration of
    :func:`gearte.solvers.contact.solve_rotation` (``dT/dφ = Σ k_t l²``), the one that the
    cycloid tooth contact and the Li 2023 loaded contact use.

    References
    ----------
    Li X. et al. (2023), Machines 11(6), 626, eq 3-4. doi:10.3390/machines11060626
    """
    P, N, zp = contacts.gap.shape
    lever = -contacts.arm
    loaded = lever > 1e-9 * np.max(np.abs(lever))
    lv = np.where(loaded, lever, 0.0).reshape(P * N, zp)
    g = contacts.gap.reshape(P * N, zp)
    b0, b1 = a0.reshape(P * N, zp), a1.reshape(P * N, zp)
    ratio = np.where(lv > 0.0, g / np.where(lv > 0.0, lv, 1.0), np.inf)
    first = np.min(ratio, axis=1)
    clear = np.where(lv > 0.0, g - first[:, None] * lv, 0.0)

    flat_power = None if power is None else (power[0].reshape(P * N, zp),
                                             power[1].reshape(P * N, zp))  # fmt: skip
    try:
        rot, _ = solve_rotation(
            lv,
            clear,
            b0,
            b1,
            torque_per_disc,
            rtol=rtol,
            rot_start=None if guess is None else np.asarray(guess, dtype=float).reshape(P * N),
            power=flat_power,
        )
    except ParameterError as exc:
        raise ParameterError("torque_per_disc", torque_per_disc, exc.reason) from None
    return (first + rot).reshape(P, N), rot.reshape(P, N)


def disc_rotation_error(
    reducer: RVReducer, torque_per_disc: float, samples_per_mesh: int = 4
) -> np.ndarray:
    """Loaded rotation shift of each disc caused by the pin and disc-profile errors [rad].

    Parameters
    ----------
    reducer : RVReducer
        The description with its errors; only the families of :func:`has_pin_errors` matter.
    torque_per_disc : float
        Torque each disc carries [N·mm] (the output torque / N), > 0, and no more than the
        pins carry (the case files' pin-pressure ceiling,
        :func:`gearte.models.rv_load_sharing.check_reducer_torque` with the whole share on one
        disc).
    samples_per_mesh : int
        Output angles per mesh period ``2π/(z_p z_c)`` [-] (≥ 2).

    Returns
    -------
    numpy.ndarray
        ``(N, K)`` with ``K = samples_per_mesh z_p z_c``: ``Δθ_j`` at the output angles
        ``2π k / K`` [rad], absolute (negative = the disc lags more than without the errors);
        ``(N, 1)`` zeros when the reducer has none of these errors.

    Notes
    -----
    ``Δθ_j(θ) = −(φ_j(θ; errors) − φ_j(θ; none))`` with ``φ_j`` from
    :func:`loaded_disc_rotation` on the clearances of :func:`gearte.geometry.rv.pin_contacts`
    with and without the errors, at the same positions, so a reducer without these errors gives
    exactly zero. The pattern repeats after one output revolution (pin errors are fixed in the
    housing, disc errors turn with the output); ``samples_per_mesh`` resolves the mesh ripple.

    References
    ----------
    Li X. et al. (2023), Machines 11(6), 626, eq 3-4. doi:10.3390/machines11060626
    """
    from gearte.models.rv_load_sharing import check_reducer_torque, contact_law

    n_discs = reducer.discs.count
    if not has_pin_errors(reducer):
        return np.zeros((n_discs, 1))
    if not np.isfinite(torque_per_disc) or torque_per_disc <= 0:
        raise ParameterError("torque_per_disc", torque_per_disc, "must be finite and > 0 N·mm")
    # beyond the pins' contact law the loaded rotation is no solution (the case files' check)
    check_reducer_torque(reducer, torque_per_disc, "torque_per_disc", share=1.0)
    if int(samples_per_mesh) != samples_per_mesh or samples_per_mesh < 2:
        raise ParameterError("samples_per_mesh", samples_per_mesh, "must be an integer ≥ 2")
    zp, zc = reducer.pins.count, reducer.cycloid_teeth
    k = int(samples_per_mesh) * zp * zc
    theta = 2.0 * np.pi * np.arange(k) / k
    law = contact_law(reducer)

    def coefficients(phase):  # (a0, a1, power): the power part only for a power law
        a0, a1, a2, a3 = law.law_coefficients(phase)
        a0 = law.series_a0(a0, np.arange(n_discs)[None, :, None])  # pin seat + bending in series
        return a0, a1, ((a2, a3) if np.any(a2 != 0.0) else None)

    nominal = reducer.replace(
        pins=PinRing(reducer.pins.count, reducer.pins.pin_radius, reducer.pins.circle_radius),
        errors=ManufacturingErrors.none(reducer.cranks.count, n_discs),
    )
    # without errors the pattern repeats every mesh period: solve one, tile it
    m = int(samples_per_mesh)
    pc0 = pin_contacts(nominal, theta[:m])
    a0, a1, power = coefficients(pc0.phase)
    rot0, ela0 = loaded_disc_rotation(pc0, a0, a1, torque_per_disc, power=power)
    reps = k // m
    out = np.empty((n_discs, k))
    chunk = 512 * m
    for s in range(0, k, chunk):
        th = theta[s : s + chunk]
        pc = pin_contacts(reducer, th)
        a0, a1, power = coefficients(pc.phase)
        r0 = np.tile(rot0, (reps, 1))[s : s + chunk]
        e0 = np.tile(ela0, (reps, 1))[s : s + chunk]
        rot, _ = loaded_disc_rotation(pc, a0, a1, torque_per_disc, guess=e0, power=power)
        out[:, s : s + chunk] = -(rot - r0).T
    return out
