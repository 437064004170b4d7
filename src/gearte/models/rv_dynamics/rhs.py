"""Compiled right-hand side of the lumped RV model and its DTE output (Li et al. 2023, eq 24).

:func:`rv_rhs` is the numba kernel the integrators of :mod:`gearte.solvers.ode` call; its readable
plain twin is :meth:`gearte.models.rv_dynamics.assembly.RVDynamicModel.rhs_numpy` (the element
loop), and the tests compare both. The kernel's arguments are two arrays: the scalar parameters
``pf`` (layout ``PF_INDEX``) and the table ``tab`` of the per-body arrays (:func:`kernel_table`),
both packed by :meth:`~gearte.models.rv_dynamics.assembly.RVDynamicModel.kernel_args`.

What the first (cold-cache) compile of the kernels costs, and why the kernel is written as it is
(``docs/numba.md``): numba types and lowers every statement and LLVM optimises the
module once for :func:`rv_rhs` and again inside every integrator that calls it, so the kernel
reads each array element once into a local, sums each body's forces in locals and stores them
once (one store instead of a read and a write per element force), gives every variable one
assignment (reassigned names cost numba's SSA pass a sweep over the function each) and takes
two arrays instead of a tuple of twelve (each array in the tuple is unboxed, reference-counted
and passed field by field in every function the tuple goes through).

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

from gearte._jit import inner_kernel, kernel

__all__ = [
    "rv_rhs",
    "rv_dte",
    "kernel_table",
    "RHS_SOURCE_KEY",
    "RHS_WORK_SIZE",
    "PF_INDEX",
    "NPF",
]

# one slot of the memo in ``work``: t, cos/sin of θ_o, θ_s, θ_H, the involute mesh stiffness of
# each crank (≤ 6) and the cycloid–pin stiffness of each disc (≤ 3), at these offsets
_M_T, _M_COS_O, _M_SIN_O, _M_COS_S, _M_SIN_S, _M_COS_H, _M_SIN_H, _M_K_SP = range(8)
_M_K_CR = _M_K_SP + 6
_SLOT = _M_K_CR + 3
RHS_WORK_SIZE = 2 * _SLOT + 1
"""Scratch floats :func:`rv_rhs` uses to memoise time-only quantities (≤ 6 cranks, ≤ 3 discs)."""

RHS_SOURCE_KEY = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:16]
"""Hash of this file: part of the numba cache key of the integrators built on :func:`rv_rhs`."""

# --- compiled right-hand side ------------------------------------------------------------------
# --- layout of the scalar parameter vector ``pf``: the one place that names each slot -------
PF_FIELDS = (
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
    "n_fsp",  # Fourier terms of the involute mesh stiffness (columns of fsp)
    "n_fcr",  # Fourier terms of the cycloid–pin stiffness (columns of fcr)
    "n_rot",  # samples per output revolution of the discs' rotation excitation
)
"""The names of the scalar parameters in ``pf``, in their order (filled by
:meth:`~gearte.models.rv_dynamics.assembly.RVDynamicModel.kernel_args`)."""
PF_INDEX = {name: i for i, name in enumerate(PF_FIELDS)}
NPF = len(PF_FIELDS)

# The kernels read ``pf`` through these named indices, each looked up in ``PF_INDEX`` (an unknown
# name fails at import); numba reads a module's integer globals as compile-time constants, so
# ``pf[W_O]`` compiles to the same load as ``pf[0]``.
W_O = PF_INDEX["w_o"]
RATIO = PF_INDEX["ratio"]
CRANK_RATE = PF_INDEX["crank_rate"]
PHI_H0 = PF_INDEX["phi_h0"]
A_H = PF_INDEX["a_h"]
ECC = PF_INDEX["ecc"]
R_BS = PF_INDEX["r_bs"]
ALPHA = PF_INDEX["alpha"]
Z_S = PF_INDEX["z_s"]
Z_P = PF_INDEX["z_p"]
K_S = PF_INDEX["k_s"]
K_ST = PF_INDEX["k_st"]
K_SP = PF_INDEX["k_sp"]
K_H = PF_INDEX["k_h"]
K_HT = PF_INDEX["k_ht"]
K_HB = PF_INDEX["k_hb"]
K_CB = PF_INDEX["k_cb"]
K_CR = PF_INDEX["k_cr"]
K_O = PF_INDEX["k_o"]
BETA_CR = PF_INDEX["beta_cr"]
SGN_R = PF_INDEX["sgn_r"]
BETA_R = PF_INDEX["beta_r"]
T_O = PF_INDEX["t_o"]
M_P = PF_INDEX["m_p"]
M_H = PF_INDEX["m_h"]
M_C = PF_INDEX["m_c"]
CL_OH = PF_INDEX["cl_oh"]
CL_C = PF_INDEX["cl_c"]
CL_H = PF_INDEX["cl_h"]
R_BP = PF_INDEX["r_bp"]
N_M = PF_INDEX["n_m"]
N_N = PF_INDEX["n_n"]
COS_ALPHA = PF_INDEX["cos_alpha"]
SIN_ALPHA = PF_INDEX["sin_alpha"]
COS_BETA_CR = PF_INDEX["cos_beta_cr"]
SIN_BETA_CR = PF_INDEX["sin_beta_cr"]
N_FSP = PF_INDEX["n_fsp"]
N_FCR = PF_INDEX["n_fcr"]
N_ROT = PF_INDEX["n_rot"]


def kernel_table(inv_mass, err_g, err_m, err_mn, err_n, geo_m, geo_n, clear, fsp, fcr, rot_n):
    """The per-body arrays of :func:`rv_rhs`, flattened (C order) one after the other into one
    float array, in the order of the arguments (the kernel computes their offsets from the
    counts in ``pf``):

    inv_mass (nd) 1/mass [1/t, 1/(t·mm²)] of every DOF; err_g (3, 2) sun eccentricity, sun and
    output assembly offsets; err_m (M, 2, 2) planet eccentricity, carrier hole; err_mn
    (M, N, 2, 2) disc hole, cam; err_n (N, 2) pin composite error; geo_m (M, 4) cos/sin of the
    crank angle ψ_i and of z_s ψ_i; geo_n (N, 4) cos/sin of the disc phase χ_j and of z_p χ_j;
    clear (M, N + 1) bearing clearances [mm]; fsp (2, L1), fcr (2, L2) Fourier coefficients of
    the mesh stiffnesses [N/mm]; rot_n (N, K) the discs' rotation excitation [rad]. Errors are
    body-fixed Cartesian offsets (E cos β, E sin β) [mm].
    """
    parts = [
        np.asarray(a, dtype=float)
        for a in (inv_mass, err_g, err_m, err_mn, err_n, geo_m, geo_n, clear, fsp, fcr, rot_n)
    ]
    m, n = parts[3].shape[:2]
    shapes = [(3 * (2 * m + n + 2),), (3, 2), (m, 2, 2), (m, n, 2, 2), (n, 2), (m, 4), (n, 4)]
    shapes += [(m, n + 1), (2, -1), (2, -1), (n, -1)]  # -1: any length
    for a, shape in zip(parts, shapes, strict=True):
        ok = a.ndim == len(shape) and all(k in (-1, d) for k, d in zip(shape, a.shape, strict=True))
        if not ok:
            raise ValueError(f"kernel_table: an array of shape {a.shape}, expected {shape}")
    return np.concatenate([a.ravel() for a in parts])


@inner_kernel
def _bearing(dx, dy, vx, vy, k, c, cl):
    """Force (on body a) of an isotropic bearing with radial clearance cl; returns fx, fy."""
    if cl <= 0.0:
        return -k * dx - c * vx, -k * dy - c * vy
    r = np.sqrt(dx * dx + dy * dy)
    if r <= cl:
        return 0.0, 0.0
    s = k * (r - cl) / r
    return -s * dx - c * vx, -s * dy - c * vy


@inner_kernel
def _fourier2(mean, tab, o, n, c1, s1):
    """mean + Σ_l a_l cos(l s) + b_l sin(l s) given cos s and sin s (angle-addition recurrence);
    a_l = ``tab[o + l]``, b_l = ``tab[o + n + l]`` (l < n)."""
    c = c1
    s = s1
    val = mean
    for ll in range(n):
        val += tab[o + ll] * c + tab[o + n + ll] * s
        c, s = c * c1 - s * s1, s * c1 + c * s1
    return val


# no_rewrites (a numba target option its type stubs do not list): numba's IR rewrite passes
# (array expressions, constant getitems, raises) find nothing to rewrite in this kernel; skipping
# them saves ~10 % of its compile's Python work, for the same LLVM IR
@kernel(no_rewrites=True)
def rv_rhs(t, y, args, dydt, work):
    """dy/dt of the lumped RV model at time ``t`` [s], written into ``dydt`` (compiled; plain twin:
    ``RVDynamicModel.rhs_numpy``).

    y = [q (6M+3N+6), q̇]; q per body (x [mm], y [mm], θ [rad]) in the order sun, planets 1..M,
    cranks 1..M, discs 1..N, output. ``args`` = (pf, tab) from :meth:`RVDynamicModel.kernel_args`:
    the scalar parameters (``PF_INDEX``) and the per-body arrays (:func:`kernel_table`); errors
    are given there as body-fixed Cartesian offsets (E cos β, E sin β) and rotated here with the
    body, so the only trigonometric calls per evaluation are the five nominal angles. ``work``
    (``RHS_WORK_SIZE`` floats, NaN-filled, one per integration) memoises them and the mesh
    stiffnesses for the last two times, so RK4 computes them twice per step instead of four
    times; pass ``np.full(RHS_WORK_SIZE, np.nan)`` (a shorter array gives NaN derivatives, which
    the integrators report as a divergence).
    """
    pf, tab = args
    nm = np.int64(pf[N_M])  # counts: exact integers stored as floats
    nn = np.int64(pf[N_N])
    n_sp = np.int64(pf[N_FSP])
    n_cr = np.int64(pf[N_FCR])
    n_rot = np.int64(pf[N_ROT])
    nd = 3 * (2 * nm + nn + 2)
    # offsets of the arrays in tab, in kernel_table's order (inv_mass at 0)
    o_eg = nd
    o_em = o_eg + 6
    o_emn = o_em + 4 * nm
    o_en = o_emn + 4 * nm * nn
    o_gm = o_en + 2 * nn
    o_gn = o_gm + 4 * nm
    o_cl = o_gn + 4 * nn
    o_sp = o_cl + nm * (nn + 1)
    o_cr = o_sp + 2 * n_sp
    o_rot = o_cr + 2 * n_cr
    if work.size < RHS_WORK_SIZE:  # too short for the memo: NaN, which the integrators refuse
        dydt[:] = np.nan
        return
    q = y[:nd]
    v = y[nd:]
    f = dydt[nd:]
    for i0 in range(nd):
        dydt[i0] = v[i0]
        f[i0] = 0.0
    w_o = pf[W_O]
    th_o = w_o * t
    th_s = pf[RATIO] * th_o
    th_h = pf[PHI_H0] + pf[CRANK_RATE] * th_o
    # Memo of everything that depends on t only (nominal angles, mesh stiffnesses): two slots
    # [t, cos/sin of θ_o, θ_s, θ_H, k_sp,i (≤ 6), k_cr,j (≤ 3)] and a flag naming the older slot.
    o = 0 if work[_M_T] == t else _SLOT  # the slot holding t, if one does
    if work[o + _M_T] != t:
        o = _SLOT if work[2 * _SLOT] != 1.0 else 0
        work[2 * _SLOT] = 1.0 if o == _SLOT else 0.0
        work[o + _M_T] = t
        work[o + _M_COS_O] = np.cos(th_o)
        work[o + _M_SIN_O] = np.sin(th_o)
        work[o + _M_COS_S] = np.cos(th_s)
        work[o + _M_SIN_S] = np.sin(th_s)
        work[o + _M_COS_H] = np.cos(th_h)
        work[o + _M_SIN_H] = np.sin(th_h)
        ph_s = pf[Z_S] * (th_s - th_o)
        cps0 = np.cos(ph_s)
        sps0 = np.sin(ph_s)
        for i1 in range(nm):  # involute mesh stiffness (eq 11), phase z_s(θ_s − θ_o) + z_s ψ_i
            c1 = tab[o_gm + 4 * i1 + 2]
            s1 = tab[o_gm + 4 * i1 + 3]
            work[o + _M_K_SP + i1] = _fourier2(
                pf[K_SP], tab, o_sp, n_sp, cps0 * c1 - sps0 * s1, sps0 * c1 + cps0 * s1
            )
        ph_c = pf[Z_P] * th_h
        cpc0 = np.cos(ph_c)
        spc0 = np.sin(ph_c)
        for j1 in range(nn):  # cycloid–pin stiffness (eq 13), phase z_p χ_j
            c2 = tab[o_gn + 4 * j1 + 2]
            s2 = tab[o_gn + 4 * j1 + 3]
            work[o + _M_K_CR + j1] = _fourier2(
                pf[K_CR], tab, o_cr, n_cr, cpc0 * c2 - spc0 * s2, spc0 * c2 + cpc0 * s2
            )
    co = work[o + _M_COS_O]
    so = work[o + _M_SIN_O]
    cs = work[o + _M_COS_S]
    ss = work[o + _M_SIN_S]
    chh = work[o + _M_COS_H]
    shh = work[o + _M_SIN_H]
    a_h = pf[A_H]
    ecc = pf[ECC]
    r_bs = pf[R_BS]
    ca = pf[COS_ALPHA]
    sa = pf[SIN_ALPHA]
    br = pf[BETA_R]
    i_out = nd - 3
    # Each body's force [N] and moment [N·mm] is summed in locals, element after element in the
    # order of the element model, from 0.0 (0.0 - a, not -a: the sign of a zero result is kept),
    # and stored once.
    qsx = q[0]
    qsy = q[1]
    qst = q[2]
    vsx = v[0]
    vsy = v[1]
    vst = v[2]
    qox = q[i_out]
    qoy = q[i_out + 1]
    qot = q[i_out + 2]
    vox = v[i_out]
    voy = v[i_out + 1]
    vot = v[i_out + 2]
    # sun support (ground seat offset = sun assembly error) and input shaft torsion
    k_s = pf[K_S]
    bsx, bsy = _bearing(qsx - tab[o_eg + 2], qsy - tab[o_eg + 3], vsx, vsy, k_s, br * k_s, 0.0)
    fsx = 0.0 + bsx
    fsy = 0.0 + bsy
    k_st = pf[K_ST]
    fst = 0.0 + (-k_st * qst - br * k_st * vst)
    # output support
    k_o = pf[K_O]
    box, boy = _bearing(qox - tab[o_eg + 4], qoy - tab[o_eg + 5], vox, voy, k_o, br * k_o, pf[CL_H])
    fox = 0.0 + box
    foy = 0.0 + boy
    fot = 0.0
    # sun eccentricity offset (rotates with the sun)
    es0 = tab[o_eg]
    es1 = tab[o_eg + 1]
    sex = es0 * cs - es1 * ss
    sey = es0 * ss + es1 * cs
    w2 = w_o * w_o * a_h
    mp_w2 = pf[M_P] * w2
    mh_w2 = pf[M_H] * w2
    k_h = pf[K_H]
    k_ht = pf[K_HT]
    k_hb = pf[K_HB]
    for i in range(nm):
        ip = 3 * (1 + i)
        ih = 3 * (1 + nm + i)
        qpx = q[ip]
        qpy = q[ip + 1]
        qpt = q[ip + 2]
        vpx = v[ip]
        vpy = v[ip + 1]
        vpt = v[ip + 2]
        qhx = q[ih]
        qhy = q[ih + 1]
        vhx = v[ih]
        vhy = v[ih + 1]
        gm0 = tab[o_gm + 4 * i]
        gm1 = tab[o_gm + 4 * i + 1]
        cps = co * gm0 - so * gm1  # psi_i = th_o + 2π i / M
        sps = so * gm0 + co * gm1
        chx = a_h * cps
        chy = a_h * sps
        # sun–planet mesh i: line of action tangent to the sun base circle at angle psi − alpha
        tx = cps * ca + sps * sa
        ty = sps * ca - cps * sa
        nx = -ty
        ny = tx
        px = r_bs * tx
        py = r_bs * ty
        ksp = work[o + _M_K_SP + i]
        ie = o_em + 4 * i
        pe0 = tab[ie]
        pe1 = tab[ie + 1]
        pex = pe0 * chh - pe1 * shh
        pey = pe0 * shh + pe1 * chh
        ga_t = px * ny - py * nx  # arm of the sun
        gb_t = (px - chx) * ny - (py - chy) * nx  # arm of the planet
        d = (
            nx * (qsx - qpx)
            + ny * (qsy - qpy)
            + ga_t * qst
            - gb_t * qpt
            + nx * (sex - pex)
            + ny * (sey - pey)
        )
        dv = nx * (vsx - vpx) + ny * (vsy - vpy) + ga_t * vst - gb_t * vpt
        fn = -ksp * d - br * ksp * dv
        fsx += fn * nx
        fsy += fn * ny
        fst += fn * ga_t
        # planet–crank shaft: bending (translation) and torsion
        fbx, fby = _bearing(qpx - qhx, qpy - qhy, vpx - vhx, vpy - vhy, k_h, br * k_h, 0.0)
        tq = -k_ht * (qpt - q[ih + 2]) - br * k_ht * (vpt - v[ih + 2])
        f[ip + 2] = (0.0 - fn * gb_t) + tq
        f[ih + 2] = 0.0 - tq
        # crank support bearing in the output disc (hole offset rotates with the output)
        oe0 = tab[ie + 2]
        oe1 = tab[ie + 3]
        ox = oe0 * cps - oe1 * sps
        oy = oe0 * sps + oe1 * cps
        # output material point at c_H: u_o + θ_o ẑ×c_H
        dx = qhx - (qox - qot * chy) - ox
        dy = qhy - (qoy + qot * chx) - oy
        vx = vhx - (vox - vot * chy)
        vy = vhy - (voy + vot * chx)
        cl_h = tab[o_cl + (nn + 1) * i + nn]
        fkx, fky = _bearing(dx, dy, vx, vy, k_hb, br * k_hb, cl_h)
        fox -= fkx
        foy -= fky
        fot -= chx * fky - chy * fkx
        # centripetal load of the carried planet and crank (nominal circular motion)
        f[ip] = ((0.0 - fn * nx) + fbx) + mp_w2 * cps
        f[ip + 1] = ((0.0 - fn * ny) + fby) + mp_w2 * sps
        f[ih] = ((0.0 - fbx) + fkx) + mh_w2 * cps
        f[ih + 1] = ((0.0 - fby) + fky) + mh_w2 * sps
    f[0] = fsx
    f[1] = fsy
    f[2] = fst
    f[i_out] = fox
    f[i_out + 1] = foy
    # discs
    w_h = pf[CRANK_RATE] * w_o
    sb = pf[SIN_BETA_CR]
    cb = pf[COS_BETA_CR]
    k_cb = pf[K_CB]
    sgn_r = pf[SGN_R]
    zp1 = pf[Z_P] - 1.0
    mc_w2 = pf[M_C] * w_h * w_h
    # pin and disc-profile errors: rotation shift Δθ_j(θ_o) of each disc, K samples per
    # output revolution, linearly interpolated (plain twin: assembly.periodic_interp)
    x_rot = th_o / (2.0 * np.pi)
    x_rot = (x_rot - np.floor(x_rot)) * n_rot
    i_x = int(x_rot)
    w_rot = x_rot - i_x
    i_rot = i_x % n_rot
    i_rot1 = (i_rot + 1) % n_rot
    for j in range(nn):
        ic = 3 * (1 + 2 * nm + j)
        qcx = q[ic]
        qcy = q[ic + 1]
        qct = q[ic + 2]
        vcx = v[ic]
        vcy = v[ic + 1]
        vct = v[ic + 2]
        gn0 = tab[o_gn + 4 * j]
        gn1 = tab[o_gn + 4 * j + 1]
        ex = chh * gn0 - shh * gn1  # chi_j = th_h + π j
        ey = shh * gn0 + chh * gn1
        ccx = ecc * ex
        ccy = ecc * ey
        fcx = 0.0  # the disc's force and moment
        fcy = 0.0
        fct = 0.0
        for i2 in range(nm):
            ih2 = 3 * (1 + nm + i2)
            gk0 = tab[o_gm + 4 * i2]
            gk1 = tab[o_gm + 4 * i2 + 1]
            cps2 = co * gk0 - so * gk1
            sps2 = so * gk0 + co * gk1
            chx2 = a_h * cps2
            chy2 = a_h * sps2
            # turning-arm bearing at the cam centre C = c_H + e ê_χ
            imn = o_emn + 4 * (nn * i2 + j)
            ae0 = tab[imn + 2]
            ae1 = tab[imn + 3]
            amx = ae0 * ex - ae1 * ey  # cam (with crank)
            amy = ae0 * ey + ae1 * ex
            he0 = tab[imn]
            he1 = tab[imn + 1]
            hox = he0 * cps2 - he1 * sps2  # hole (with disc)
            hoy = he0 * sps2 + he1 * cps2
            # arms: C − c_H = e ê_χ (crank), C − c_c = c_H (disc)
            qht = q[ih2 + 2]
            vht = v[ih2 + 2]
            dx2 = (q[ih2] - qht * ccy) - (qcx - qct * chy2) + amx - hox
            dy2 = (q[ih2 + 1] + qht * ccx) - (qcy + qct * chx2) + amy - hoy
            vx2 = (v[ih2] - vht * ccy) - (vcx - vct * chy2)
            vy2 = (v[ih2 + 1] + vht * ccx) - (vcy + vct * chx2)
            cl_a = tab[o_cl + (nn + 1) * i2 + j]
            fax, fay = _bearing(dx2, dy2, vx2, vy2, k_cb, br * k_cb, cl_a)
            f[ih2] += fax
            f[ih2 + 1] += fay
            f[ih2 + 2] += ccx * fay - ccy * fax
            fcx -= fax
            fcy -= fay
            fct -= chx2 * fay - chy2 * fax
        # equivalent cycloid–pin contact at the pitch point P = z_p e ê_χ (eq 27, rotating)
        kcr = work[o + _M_K_CR + j]
        # force on the disc along d = sgn sinβ ê + cosβ ẑ×ê ; approach direction n = −d
        nx2 = -(sgn_r * sb * ex - cb * ey)
        ny2 = -(sgn_r * sb * ey + cb * ex)
        rx = zp1 * ccx
        ry = zp1 * ccy
        g_t = rx * ny2 - ry * nx2
        # E sin(th_o + φ) = E cosφ sin th_o + E sinφ cos th_o
        ecr = tab[o_en + 2 * j] * so + tab[o_en + 2 * j + 1] * co
        i_rj = o_rot + n_rot * j
        d_rot = (1.0 - w_rot) * tab[i_rj + i_rot] + w_rot * tab[i_rj + i_rot1]
        d2 = nx2 * qcx + ny2 * qcy + g_t * (qct - d_rot) + ecr
        dv2 = nx2 * vcx + ny2 * vcy + g_t * vct
        fn2 = -kcr * d2 - br * kcr * dv2
        # centripetal load of the disc on its eccentric circle
        f[ic] = (fcx + fn2 * nx2) + mc_w2 * ccx
        f[ic + 1] = (fcy + fn2 * ny2) + mc_w2 * ccy
        f[ic + 2] = fct + fn2 * g_t
    f[i_out + 2] = fot - pf[T_O]
    for i3 in range(nd):
        f[i3] *= tab[i3]


@kernel
def rv_dte(t, y, args):
    """Dynamic transmission error θ_o − θ_s / i [rad] of state ``y`` at time ``t`` [s]; ``args``
    as for :func:`rv_rhs`."""
    pf = args[0]
    nd = 3 * (2 * np.int64(pf[N_M]) + np.int64(pf[N_N]) + 2)
    return y[nd - 1] - y[2] / pf[RATIO]
