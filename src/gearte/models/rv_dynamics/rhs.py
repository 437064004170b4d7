"""Compiled right-hand side of the lumped RV model and its DTE output (Li et al. 2023, eq 24).

:func:`rv_rhs` is the numba kernel the integrators of :mod:`gearte.solvers.ode` call; its readable
plain twin is :meth:`gearte.models.rv_dynamics.assembly.RVDynamicModel.rhs_numpy` (the element
loop), and the tests compare both. The scalar parameter vector's layout is ``PF_INDEX``; its
values are packed by :meth:`~gearte.models.rv_dynamics.assembly.RVDynamicModel.kernel_args`.

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
from numba import njit

__all__ = ["rv_rhs", "rv_dte", "RHS_SOURCE_KEY", "RHS_WORK_SIZE", "PF_INDEX", "NPF"]

_SLOT = 16  # t, 6 trigonometric values, 6 involute and 3 cycloid mesh stiffnesses
RHS_WORK_SIZE = 2 * _SLOT + 1
"""Scratch floats :func:`rv_rhs` uses to memoise time-only quantities (≤ 6 cranks, ≤ 3 discs)."""

RHS_SOURCE_KEY = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:16]
"""Hash of this file: part of the numba cache key of the integrators built on :func:`rv_rhs`."""

# --- compiled right-hand side ------------------------------------------------------------------
# layout of the scalar parameter vector ``pf``
PF_INDEX = {
    name: i
    for i, name in enumerate(
        [
            "w_o",  # nominal output speed [rad/s]
            "ratio",  # i
            "crank_rate",  # crank absolute speed / ω_o = 1 − z_p
            "phi_h0",  # crank phase at t = 0 [rad]
            "a_h",  # crank circle radius [mm]
            "ecc",  # eccentricity [mm]
            "r_bs",  # base radius of the sun [mm]
            "alpha",  # working pressure angle of the involute pair [rad]
            "z_s",
            "z_p",
            "k_s",
            "k_st",
            "k_sp",  # mean involute mesh stiffness [N/mm]
            "k_h",
            "k_ht",
            "k_hb",
            "k_cb",
            "k_cr",  # mean cycloid–pin stiffness [N/mm]
            "k_o",
            "beta_cr",  # equivalent pressure angle [rad]
            "sgn_r",  # sign of the radial component of the pin resultant (+1 outward)
            "beta_r",  # stiffness-proportional damping coefficient [s]
            "t_o",  # load torque on the output [N·mm]
            "m_p",
            "m_h",
            "m_c",
            "cl_oh",  # scalar clearances (the kernel reads the per-bearing array ``clear``)
            "cl_c",
            "cl_h",
            "r_bp",
            "n_m",
            "n_n",
            "cos_alpha",
            "sin_alpha",
            "cos_beta_cr",
            "sin_beta_cr",
        ]
    )
}
NPF = len(PF_INDEX)


@njit(cache=True, nogil=True)
def _bearing(dx, dy, vx, vy, k, c, cl):
    """Force (on body a) of an isotropic bearing with radial clearance cl; returns fx, fy."""
    if cl <= 0.0:
        return -k * dx - c * vx, -k * dy - c * vy
    r = np.sqrt(dx * dx + dy * dy)
    if r <= cl:
        return 0.0, 0.0
    s = k * (r - cl) / r
    return -s * dx - c * vx, -s * dy - c * vy


@njit(cache=True, nogil=True)
def _fourier2(mean, coef, c1, s1):
    """mean + Σ_l a_l cos(l s) + b_l sin(l s) given cos s and sin s (angle-addition recurrence)."""
    c = c1
    s = s1
    val = mean
    for ll in range(coef.shape[1]):
        val += coef[0, ll] * c + coef[1, ll] * s
        c, s = c * c1 - s * s1, s * c1 + c * s1
    return val


@njit(cache=True, nogil=True)
def rv_rhs(t, y, args, dydt, work):
    """dy/dt of the lumped RV model at time ``t`` [s], written into ``dydt`` (compiled; plain twin:
    ``RVDynamicModel.rhs_numpy``).

    y = [q (6M+3N+6), q̇]; q per body (x [mm], y [mm], θ [rad]) in the order sun, planets 1..M,
    cranks 1..M, discs 1..N, output. ``args`` = (pf, inv_mass, fsp, fcr, err_g, err_m, err_mn,
    err_n, geo_m, geo_n, rot_n, clear) from :meth:`RVDynamicModel.kernel_args` (``rot_n``: the
    discs' rotation excitation, ``clear``: the clearance of every crank bearing); errors are given
    there as body-fixed Cartesian offsets (E cos β, E sin β) and rotated here with the body, so the
    only trigonometric calls per evaluation are the five nominal angles. ``work`` (``RHS_WORK_SIZE``
    floats, NaN-filled, one per integration) memoises them and the mesh stiffnesses for the last two
    times, so RK4 computes them twice per step instead of four times; pass ``np.full(RHS_WORK_SIZE,
    np.nan)`` (a shorter array makes the call allocate its own).
    """
    pf, inv_m, fsp, fcr, err_g, err_m, err_mn, err_n, geo_m, geo_n, rot_n, clear = args
    nm = int(pf[30])
    nn = int(pf[31])
    nd = 3 * (2 * nm + nn + 2)
    q = y[:nd]
    v = y[nd:]
    f = dydt[nd:]
    for i in range(nd):
        dydt[i] = v[i]
        f[i] = 0.0
    w_o = pf[0]
    th_o = w_o * t
    th_s = pf[1] * th_o
    th_h = pf[3] + pf[2] * th_o
    # Memo of everything that depends on t only (nominal angles, mesh stiffnesses): two slots
    # [t, cos/sin of θ_o, θ_s, θ_H, k_sp,i (≤ 6), k_cr,j (≤ 3)] and a flag naming the older slot.
    if work.size < RHS_WORK_SIZE:
        work = np.full(RHS_WORK_SIZE, np.nan)
    if work[0] == t:
        o = 0
    elif work[_SLOT] == t:
        o = _SLOT
    else:
        o = _SLOT if work[2 * _SLOT] != 1.0 else 0
        work[2 * _SLOT] = 1.0 if o == _SLOT else 0.0
        work[o] = t
        work[o + 1] = np.cos(th_o)
        work[o + 2] = np.sin(th_o)
        work[o + 3] = np.cos(th_s)
        work[o + 4] = np.sin(th_s)
        work[o + 5] = np.cos(th_h)
        work[o + 6] = np.sin(th_h)
        ph_s = pf[8] * (th_s - th_o)
        cps0 = np.cos(ph_s)
        sps0 = np.sin(ph_s)
        for i in range(nm):  # involute mesh stiffness (eq 11), phase z_s(θ_s − θ_o) + z_s ψ_i
            work[o + 7 + i] = _fourier2(
                pf[12],
                fsp,
                cps0 * geo_m[i, 2] - sps0 * geo_m[i, 3],
                sps0 * geo_m[i, 2] + cps0 * geo_m[i, 3],
            )
        ph_c = pf[9] * th_h
        cpc0 = np.cos(ph_c)
        spc0 = np.sin(ph_c)
        for j in range(nn):  # cycloid–pin stiffness (eq 13), phase z_p χ_j
            work[o + 13 + j] = _fourier2(
                pf[17],
                fcr,
                cpc0 * geo_n[j, 2] - spc0 * geo_n[j, 3],
                spc0 * geo_n[j, 2] + cpc0 * geo_n[j, 3],
            )
    co = work[o + 1]
    so = work[o + 2]
    cs = work[o + 3]
    ss = work[o + 4]
    chh = work[o + 5]
    shh = work[o + 6]
    a_h = pf[4]
    ecc = pf[5]
    r_bs = pf[6]
    ca = pf[32]
    sa = pf[33]
    br = pf[21]
    i_out = nd - 3
    # sun support (ground seat offset = sun assembly error) and input shaft torsion
    k = pf[10]
    fx, fy = _bearing(q[0] - err_g[1, 0], q[1] - err_g[1, 1], v[0], v[1], k, br * k, 0.0)
    f[0] += fx
    f[1] += fy
    k = pf[11]
    f[2] += -k * q[2] - br * k * v[2]
    # output support
    k = pf[18]
    fx, fy = _bearing(
        q[i_out] - err_g[2, 0],
        q[i_out + 1] - err_g[2, 1],
        v[i_out],
        v[i_out + 1],
        k,
        br * k,
        pf[28],
    )
    f[i_out] += fx
    f[i_out + 1] += fy
    # sun eccentricity offset (rotates with the sun)
    sex = err_g[0, 0] * cs - err_g[0, 1] * ss
    sey = err_g[0, 0] * ss + err_g[0, 1] * cs
    w2 = w_o * w_o * a_h
    for i in range(nm):
        ip = 3 * (1 + i)
        ih = 3 * (1 + nm + i)
        cps = co * geo_m[i, 0] - so * geo_m[i, 1]  # psi_i = th_o + 2π i / M
        sps = so * geo_m[i, 0] + co * geo_m[i, 1]
        chx = a_h * cps
        chy = a_h * sps
        # sun–planet mesh i: line of action tangent to the sun base circle at angle psi − alpha
        tx = cps * ca + sps * sa
        ty = sps * ca - cps * sa
        nx = -ty
        ny = tx
        px = r_bs * tx
        py = r_bs * ty
        ksp = work[o + 7 + i]
        pex = err_m[i, 0, 0] * chh - err_m[i, 0, 1] * shh
        pey = err_m[i, 0, 0] * shh + err_m[i, 0, 1] * chh
        ga_t = px * ny - py * nx  # arm of the sun
        gb_t = (px - chx) * ny - (py - chy) * nx  # arm of the planet
        d = (
            nx * (q[0] - q[ip])
            + ny * (q[1] - q[ip + 1])
            + ga_t * q[2]
            - gb_t * q[ip + 2]
            + nx * (sex - pex)
            + ny * (sey - pey)
        )
        dv = nx * (v[0] - v[ip]) + ny * (v[1] - v[ip + 1]) + ga_t * v[2] - gb_t * v[ip + 2]
        fn = -ksp * d - br * ksp * dv
        f[0] += fn * nx
        f[1] += fn * ny
        f[2] += fn * ga_t
        f[ip] -= fn * nx
        f[ip + 1] -= fn * ny
        f[ip + 2] -= fn * gb_t
        # planet–crank shaft: bending (translation) and torsion
        k = pf[13]
        fx, fy = _bearing(
            q[ip] - q[ih],
            q[ip + 1] - q[ih + 1],
            v[ip] - v[ih],
            v[ip + 1] - v[ih + 1],
            k,
            br * k,
            0.0,
        )
        f[ip] += fx
        f[ip + 1] += fy
        f[ih] -= fx
        f[ih + 1] -= fy
        k = pf[14]
        tq = -k * (q[ip + 2] - q[ih + 2]) - br * k * (v[ip + 2] - v[ih + 2])
        f[ip + 2] += tq
        f[ih + 2] -= tq
        # crank support bearing in the output disc (hole offset rotates with the output)
        k = pf[15]
        ox = err_m[i, 1, 0] * cps - err_m[i, 1, 1] * sps
        oy = err_m[i, 1, 0] * sps + err_m[i, 1, 1] * cps
        # output material point at c_H: u_o + θ_o ẑ×c_H
        dx = q[ih] - (q[i_out] - q[i_out + 2] * chy) - ox
        dy = q[ih + 1] - (q[i_out + 1] + q[i_out + 2] * chx) - oy
        vx = v[ih] - (v[i_out] - v[i_out + 2] * chy)
        vy = v[ih + 1] - (v[i_out + 1] + v[i_out + 2] * chx)
        fx, fy = _bearing(dx, dy, vx, vy, k, br * k, clear[i, nn])
        f[ih] += fx
        f[ih + 1] += fy
        f[i_out] -= fx
        f[i_out + 1] -= fy
        f[i_out + 2] -= chx * fy - chy * fx
        # centripetal load of the carried planet and crank (nominal circular motion)
        f[ip] += pf[23] * w2 * cps
        f[ip + 1] += pf[23] * w2 * sps
        f[ih] += pf[24] * w2 * cps
        f[ih + 1] += pf[24] * w2 * sps
    # discs
    w_h = pf[2] * w_o
    sb = pf[35]
    cb = pf[34]
    # pin and disc-profile errors: rotation shift Δθ_j(θ_o) of each disc, K samples per
    # output revolution, linearly interpolated (plain twin: assembly.periodic_interp)
    n_rot = rot_n.shape[1]
    x_rot = th_o / (2.0 * np.pi)
    x_rot = (x_rot - np.floor(x_rot)) * n_rot
    i_rot = int(x_rot)
    w_rot = x_rot - i_rot
    i_rot = i_rot % n_rot
    i_rot1 = (i_rot + 1) % n_rot
    for j in range(nn):
        ic = 3 * (1 + 2 * nm + j)
        ex = chh * geo_n[j, 0] - shh * geo_n[j, 1]  # chi_j = th_h + π j
        ey = shh * geo_n[j, 0] + chh * geo_n[j, 1]
        ccx = ecc * ex
        ccy = ecc * ey
        for i in range(nm):
            ih = 3 * (1 + nm + i)
            cps = co * geo_m[i, 0] - so * geo_m[i, 1]
            sps = so * geo_m[i, 0] + co * geo_m[i, 1]
            chx = a_h * cps
            chy = a_h * sps
            # turning-arm bearing at the cam centre C = c_H + e ê_χ
            k = pf[16]
            amx = err_mn[i, j, 1, 0] * ex - err_mn[i, j, 1, 1] * ey  # cam (with crank)
            amy = err_mn[i, j, 1, 0] * ey + err_mn[i, j, 1, 1] * ex
            hox = err_mn[i, j, 0, 0] * cps - err_mn[i, j, 0, 1] * sps  # hole (with disc)
            hoy = err_mn[i, j, 0, 0] * sps + err_mn[i, j, 0, 1] * cps
            # arms: C − c_H = e ê_χ (crank), C − c_c = c_H (disc)
            dx = (q[ih] - q[ih + 2] * ccy) - (q[ic] - q[ic + 2] * chy) + amx - hox
            dy = (q[ih + 1] + q[ih + 2] * ccx) - (q[ic + 1] + q[ic + 2] * chx) + amy - hoy
            vx = (v[ih] - v[ih + 2] * ccy) - (v[ic] - v[ic + 2] * chy)
            vy = (v[ih + 1] + v[ih + 2] * ccx) - (v[ic + 1] + v[ic + 2] * chx)
            fx, fy = _bearing(dx, dy, vx, vy, k, br * k, clear[i, j])
            f[ih] += fx
            f[ih + 1] += fy
            f[ih + 2] += ccx * fy - ccy * fx
            f[ic] -= fx
            f[ic + 1] -= fy
            f[ic + 2] -= chx * fy - chy * fx
        # equivalent cycloid–pin contact at the pitch point P = z_p e ê_χ (eq 27, rotating)
        kcr = work[o + 13 + j]
        # force on the disc along d = sgn sinβ ê + cosβ ẑ×ê ; approach direction n = −d
        nx = -(pf[20] * sb * ex - cb * ey)
        ny = -(pf[20] * sb * ey + cb * ex)
        rx = (pf[9] - 1.0) * ccx
        ry = (pf[9] - 1.0) * ccy
        g_t = rx * ny - ry * nx
        ecr = (
            err_n[j, 0] * so + err_n[j, 1] * co
        )  # E sin(th_o + φ) = E cosφ sin th_o + E sinφ cos th_o
        d_rot = (1.0 - w_rot) * rot_n[j, i_rot] + w_rot * rot_n[j, i_rot1]
        d = nx * q[ic] + ny * q[ic + 1] + g_t * (q[ic + 2] - d_rot) + ecr
        dv = nx * v[ic] + ny * v[ic + 1] + g_t * v[ic + 2]
        fn = -kcr * d - br * kcr * dv
        f[ic] += fn * nx
        f[ic + 1] += fn * ny
        f[ic + 2] += fn * g_t
        # centripetal load of the disc on its eccentric circle
        f[ic] += pf[25] * w_h * w_h * ccx
        f[ic + 1] += pf[25] * w_h * w_h * ccy
    f[i_out + 2] -= pf[22]
    for i in range(nd):
        f[i] *= inv_m[i]


@njit(cache=True, nogil=True)
def rv_dte(t, y, args):
    """Dynamic transmission error θ_o − θ_s / i [rad] of state ``y`` at time ``t`` [s]; ``args``
    as for :func:`rv_rhs`."""
    pf = args[0]
    nd = 3 * (2 * int(pf[30]) + int(pf[31]) + 2)
    return y[nd - 1] - y[2] / pf[1]
