"""Assembly of the lumped RV model: elements, stiffness matrix, forces, statics (Li 2023, §3).

:class:`RVDynamicModel` turns the parameters and errors (:mod:`.parameters`) and the mesh
excitation (:mod:`.mesh_stiffness`) into element springs acting on the material points of the
bodies (the readable element model), packs the arguments of the compiled right-hand side
(:mod:`.rhs`) and solves the static equilibrium. Modal quantities are in :mod:`.modal`.

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from gearte.errors import ConvergenceError, ParameterError
from gearte.models.cycloid_loaded_contact import fourier_eval, mesh_period_contact
from gearte.models.rv_dynamics.mesh_stiffness import (
    cycloid_mesh_stiffness_fourier,
    involute_contact_ratio,
    rectangular_mesh_stiffness_fourier,
)
from gearte.models.rv_dynamics.modal import (
    ModalResult,
    damped_eigenvalues,
    modal_analysis,
    resonance_warnings,
    rigid_mode,
    stiffness_proportional_damping,
)
from gearte.models.rv_dynamics.parameters import RVDynamicsParameters, RVErrors
from gearte.models.rv_dynamics.rhs import NPF, PF_INDEX, RHS_WORK_SIZE, kernel_table, rv_rhs
from gearte.units import (
    KG_TO_T,
    KGM2_TO_TMM2,
    N_PER_M_TO_N_PER_MM,
    NM_PER_RAD_TO_NMM_PER_RAD,
    Nm_to_Nmm,
    deg_to_rad,
)

__all__ = ["RVDynamicModel", "periodic_interp"]


def periodic_interp(table: np.ndarray, angle: float) -> float:
    """Linear interpolation of ``table`` (K samples at ``2π k / K``) at ``angle`` [rad], periodic.

    Plain twin of the interpolation in :func:`gearte.models.rv_dynamics.rhs.rv_rhs`.
    """
    k = table.size
    x = (angle / (2.0 * np.pi)) % 1.0 * k
    i0 = int(x) % k
    w = x - int(x)
    return float((1.0 - w) * table[i0] + w * table[(i0 + 1) % k])


def _check_rotation_frame(p: RVDynamicsParameters, e: RVErrors) -> None:
    """The discs' rotation excitation is tabulated with the eccentric at −z_c θ_o (no phase)."""
    if p.crank_phase_deg != 0.0 and np.any(e.disc_rotation != 0.0):
        raise ParameterError(
            "crank_phase_deg",
            p.crank_phase_deg,
            "must be 0 with pin or disc-profile errors (their excitation is tabulated in the "
            "frame of gearte.geometry.rv, eccentric of disc 1 along −z_c θ_o)",
        )


#: Most modified-Newton iterations of :meth:`RVDynamicModel.static_equilibrium` [-] (a few
#: microseconds each on the 30 degrees of freedom: about 1 s at the cap).
STATIC_MAXIT = 200_000
#: Iterations that solve with the factorised K each time (bit for bit the iteration of old; a
#: solve that converges converges within them where no clearance is open) before the inverse
#: of K is used instead.
_STATIC_SOLVE_ITERATIONS = 1_000


class RVDynamicModel:
    """The lumped model built from an RV description (parameters + errors).

    Parameters
    ----------
    params : RVDynamicsParameters
    errors : RVErrors, optional
        Defaults to no errors and no clearances.
    contact : MeshPeriodContact, optional
        Loaded contact over one mesh period at the per-disc torque; computed when omitted.
    """

    def __init__(
        self,
        params: RVDynamicsParameters,
        errors: RVErrors | None = None,
        contact=None,
    ) -> None:
        self.params = p = params
        m, n = p.crank_count, p.disc_count
        self.errors = errors if errors is not None else RVErrors(crank_count=m, disc_count=n)
        if (self.errors.crank_count, self.errors.disc_count) != (m, n):
            raise ParameterError(
                "errors",
                (self.errors.crank_count, self.errors.disc_count),
                f"must be for ({m}, {n})",
            )
        _check_rotation_frame(p, self.errors)
        self.n_bodies = 2 * m + n + 2
        self.n_dof = 3 * self.n_bodies
        t_disc = Nm_to_Nmm(p.output_torque_Nm) / n
        self.contact = contact or mesh_period_contact(p.pair, t_disc, p.contact_positions)
        override = p.cycloid_mesh_stiffness_N_per_m
        self.cycloid_fourier = cycloid_mesh_stiffness_fourier(  # N/mm
            self.contact.mesh_stiffness,
            p.cycloid_harmonics,
            mean_only=p.cycloid_stiffness == "mean",
            mean_N_per_mm=None if override is None else override * N_PER_M_TO_N_PER_MM,
        )
        self.beta_cr = self.contact.pressure_angle_mean
        if p.cycloid_pressure_angle_deg is not None:
            self.beta_cr = float(deg_to_rad(p.cycloid_pressure_angle_deg))
        sr = float(np.sum(self.contact.contact.radial_force_signed))
        self.sgn_radial = 1.0 if sr >= 0 else -1.0
        alpha = deg_to_rad(p.pressure_angle_deg)
        self.contact_ratio = involute_contact_ratio(p.sun_teeth, p.planet_teeth, p.module_mm, alpha)
        k1 = p.involute_single_pair_stiffness_N_per_m * N_PER_M_TO_N_PER_MM
        self.involute_fourier = rectangular_mesh_stiffness_fourier(
            k1, self.contact_ratio, p.involute_harmonics
        )
        self.alpha = alpha
        self.r_bs = p.module_mm * p.sun_teeth / 2 * np.cos(alpha)
        self.r_bp = p.module_mm * p.planet_teeth / 2 * np.cos(alpha)
        mass = []
        for mk, jk, cnt in (
            (p.sun_mass_kg, p.sun_inertia_kgm2, 1),
            (p.planet_mass_kg, p.planet_inertia_kgm2, m),
            (p.crank_mass_kg, p.crank_inertia_kgm2, m),
            (p.disc_mass_kg, p.disc_inertia_kgm2, n),
            (p.output_mass_kg, p.output_inertia_kgm2, 1),
        ):
            mass += [mk * KG_TO_T, mk * KG_TO_T, jk * KGM2_TO_TMM2] * cnt
        self.mass = np.array(mass)
        names = ["sun"] + [f"planet{i + 1}" for i in range(m)] + [f"crank{i + 1}" for i in range(m)]
        names += [f"disc{j + 1}" for j in range(n)] + ["output"]
        self.body_names = names
        self.dof_names = [f"{b}.{c}" for b in names for c in ("x", "y", "theta")]
        self._k_cache: dict = {}
        self._eig_cache: dict = {}
        self._beta_r = 0.0
        self._beta_r = stiffness_proportional_damping(self)

    # --- indices -------------------------------------------------------------------------
    def body(self, name: str) -> int:
        """First DOF index of a body (``"sun"``, ``"planet1"``, ``"disc2"``, ``"output"``...)."""
        return 3 * self.body_names.index(name)

    # --- packed arguments of the compiled RHS ----------------------------------------------
    def kernel_args(self, errors: RVErrors | None = None, *, damping: bool = True) -> tuple:
        """``(pf, tab)`` passed to :func:`rv_rhs`: the scalar parameters (layout ``PF_INDEX``)
        and the per-body arrays (:func:`~gearte.models.rv_dynamics.rhs.kernel_table`); errors may
        be swapped for a batch realisation."""
        p = self.params
        e = errors if errors is not None else self.errors
        pf = np.zeros(NPF)
        k_sp_mean, a_sp, b_sp = self.involute_fourier
        k_cr_mean, a_cr, b_cr = self.cycloid_fourier
        vals = {
            "w_o": p.output_speed,
            "ratio": p.ratio,
            "crank_rate": 1.0 - p.pair.pin_count,
            "phi_h0": deg_to_rad(p.crank_phase_deg),
            "a_h": p.centre_distance_mm,
            "ecc": p.pair.eccentricity_mm,
            "r_bs": self.r_bs,
            "alpha": self.alpha,
            "z_s": p.sun_teeth,
            "z_p": p.pair.pin_count,
            "k_s": p.sun_support_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "k_st": p.input_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD,
            "k_sp": k_sp_mean,
            "k_h": p.crank_bending_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "k_ht": p.crank_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD,
            "k_hb": p.crank_bearing_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "k_cb": p.turning_arm_bearing_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "k_cr": k_cr_mean,
            "k_o": p.output_support_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "beta_cr": self.beta_cr,
            "sgn_r": self.sgn_radial,
            "beta_r": self._beta_r if damping else 0.0,
            "t_o": Nm_to_Nmm(p.output_torque_Nm),
            "m_p": p.planet_mass_kg * KG_TO_T,
            "m_h": p.crank_mass_kg * KG_TO_T,
            "m_c": p.disc_mass_kg * KG_TO_T,
            "cl_oh": e.crank_bearing_clearance_mm,
            "cl_c": e.turning_arm_clearance_mm,
            "cl_h": e.output_bearing_clearance_mm,
            "r_bp": self.r_bp,
            "n_m": p.crank_count,
            "n_n": p.disc_count,
            "cos_alpha": np.cos(self.alpha),
            "sin_alpha": np.sin(self.alpha),
            "cos_beta_cr": np.cos(self.beta_cr),
            "sin_beta_cr": np.sin(self.beta_cr),
            "n_fsp": np.size(a_sp),
            "n_fcr": np.size(a_cr),
            "n_rot": np.shape(e.disc_rotation)[1],
        }
        if set(vals) != set(PF_INDEX):  # every slot of the layout filled, no other
            raise ValueError(
                f"kernel_args: pf keys differ from PF_INDEX: {set(vals) ^ set(PF_INDEX)}"
            )
        for key, val in vals.items():
            pf[PF_INDEX[key]] = val

        def cart(a):
            a = np.asarray(a, dtype=float)
            return np.stack([a[..., 0] * np.cos(a[..., 1]), a[..., 0] * np.sin(a[..., 1])], -1)

        err_g = cart([e.sun_eccentricity, e.sun_assembly, e.output_assembly])
        err_m = cart(np.stack([e.planet_eccentricity, e.carrier_hole], axis=1))
        err_mn = cart(np.stack([e.disc_hole, e.cam], axis=2))
        pin = np.asarray(e.pin_composite, dtype=float)
        m, n = p.crank_count, p.disc_count
        om = 2 * np.pi * np.arange(m) / m
        on = np.pi * np.arange(n)
        geo_m = np.stack(
            [np.cos(om), np.sin(om), np.cos(p.sun_teeth * om), np.sin(p.sun_teeth * om)], 1
        )
        zp = p.pair.pin_count
        geo_n = np.stack([np.cos(on), np.sin(on), np.cos(zp * on), np.sin(zp * on)], 1)
        tab = kernel_table(
            1.0 / self.mass,
            err_g,
            err_m,
            err_mn,
            cart(pin),
            geo_m,
            geo_n,
            e.bearing_clearances(),
            np.stack([a_sp, b_sp]),
            np.stack([a_cr, b_cr]),
            e.disc_rotation,
        )
        return pf, tab

    # --- plain element model (readable twin) ------------------------------------------------
    def elements(self, t: float, *, mesh: str = "time") -> list[dict]:
        """Element list at time t: each with kind, stiffness, rows g (deflection = g·q + e).

        ``mesh="time"`` evaluates the mesh stiffnesses at t, ``"mean"`` uses their means,
        ``"max"`` their maxima over a period (for the stability limit).
        """
        p, e = self.params, self.errors
        nd = self.n_dof
        m, n = p.crank_count, p.disc_count
        w_o = p.output_speed
        th_o = w_o * t
        th_s = p.ratio * th_o
        th_h = deg_to_rad(p.crank_phase_deg) + (1.0 - p.pair.pin_count) * th_o
        a_h = p.centre_distance_mm
        ecc = p.pair.eccentricity_mm
        clear = e.bearing_clearances()
        out = []

        def row(entries):
            g = np.zeros(nd)
            for body_idx, (gx, gy, gt) in entries:
                if body_idx is None:
                    continue
                g[3 * body_idx : 3 * body_idx + 3] += (gx, gy, gt)
            return g

        def point_rows(a, ca, b, cb, c):
            """x and y rows of the relative displacement of material points at c."""
            ra = (c[0] - ca[0], c[1] - ca[1])
            rx = [(a, (1.0, 0.0, -ra[1]))]
            ry = [(a, (0.0, 1.0, ra[0]))]
            if b is not None:
                rb = (c[0] - cb[0], c[1] - cb[1])
                rx.append((b, (-1.0, 0.0, rb[1])))
                ry.append((b, (0.0, -1.0, -rb[0])))
            return row(rx), row(ry)

        def polar(amp, ang):
            return np.array([amp * np.cos(ang), amp * np.sin(ang)])

        def series(coef, phase):
            mean, a, b = coef
            if mesh == "mean":
                return mean
            if mesh == "max":
                s = np.linspace(0, 2 * np.pi, 721)
                return float(np.max(fourier_eval(mean, a, b, s)))
            return float(fourier_eval(mean, a, b, phase))

        def bearing(name, rows, k, cl, err):
            out.append(dict(name=name, kind="bearing", k=k, g=rows, cl=cl, e=err))

        def line(name, k, g, err):
            out.append(dict(name=name, kind="line", k=k, g=g, e=err))

        i_s, i_o = 0, self.n_bodies - 1
        k = p.sun_support_stiffness_N_per_m * N_PER_M_TO_N_PER_MM
        gx, gy = point_rows(i_s, (0, 0), None, None, (0, 0))
        bearing("sun support", (gx, gy), k, 0.0, -polar(*e.sun_assembly))
        g = np.zeros(nd)
        g[2] = 1.0
        line(
            "input shaft",
            p.input_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD,
            g,
            0.0,
        )
        k = p.output_support_stiffness_N_per_m * N_PER_M_TO_N_PER_MM
        gx, gy = point_rows(i_o, (0, 0), None, None, (0, 0))
        bearing(
            "output support", (gx, gy), k, e.output_bearing_clearance_mm, -polar(*e.output_assembly)
        )
        sun_off = polar(e.sun_eccentricity[0], th_s + e.sun_eccentricity[1])
        for i in range(m):
            ip, ih = 1 + i, 1 + m + i
            psi = th_o + 2 * np.pi * i / m
            ch = a_h * np.array([np.cos(psi), np.sin(psi)])
            tdir = np.array([np.cos(psi - self.alpha), np.sin(psi - self.alpha)])
            nvec = np.array([-tdir[1], tdir[0]])
            pp = self.r_bs * tdir
            arm_a = pp[0] * nvec[1] - pp[1] * nvec[0]
            rb = pp - ch
            arm_b = rb[0] * nvec[1] - rb[1] * nvec[0]
            g = row([(0, (nvec[0], nvec[1], arm_a)), (ip, (-nvec[0], -nvec[1], -arm_b))])
            phase = p.sun_teeth * (th_s - th_o) + p.sun_teeth * 2 * np.pi * i / m
            pl_off = polar(e.planet_eccentricity[i, 0], th_h + e.planet_eccentricity[i, 1])
            line(
                f"sun-planet{i + 1} mesh",
                series(self.involute_fourier, phase),
                g,
                float(nvec @ (sun_off - pl_off)),
            )
            gx, gy = point_rows(ip, ch, ih, ch, ch)
            bearing(
                f"crank{i + 1} bending",
                (gx, gy),
                p.crank_bending_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
                0.0,
                np.zeros(2),
            )
            g = np.zeros(nd)
            g[3 * ip + 2], g[3 * ih + 2] = 1.0, -1.0
            line(
                f"crank{i + 1} torsion",
                p.crank_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD,
                g,
                0.0,
            )
            gx, gy = point_rows(ih, ch, i_o, (0, 0), ch)
            bearing(
                f"crank{i + 1} support",
                (gx, gy),
                p.crank_bearing_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
                clear[i, n],
                -polar(e.carrier_hole[i, 0], psi + e.carrier_hole[i, 1]),
            )
        for j in range(n):
            ic = 1 + 2 * m + j
            chi = th_h + np.pi * j
            ehat = np.array([np.cos(chi), np.sin(chi)])
            eperp = np.array([-ehat[1], ehat[0]])
            cc = ecc * ehat
            for i in range(m):
                ih = 1 + m + i
                psi = th_o + 2 * np.pi * i / m
                ch = a_h * np.array([np.cos(psi), np.sin(psi)])
                c = ch + cc
                gx, gy = point_rows(ih, ch, ic, cc, c)
                cam = polar(e.cam[i, j, 0], chi + e.cam[i, j, 1])
                hole = polar(e.disc_hole[i, j, 0], psi + e.disc_hole[i, j, 1])
                bearing(
                    f"crank{i + 1}-disc{j + 1} bearing",
                    (gx, gy),
                    p.turning_arm_bearing_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
                    clear[i, j],
                    cam - hole,
                )
            b = self.beta_cr
            dvec = self.sgn_radial * np.sin(b) * ehat + np.cos(b) * eperp
            nvec = -dvec
            pp = p.pair.pin_count * cc
            r = pp - cc
            g_t = r[0] * nvec[1] - r[1] * nvec[0]
            g = row([(ic, (nvec[0], nvec[1], g_t))])
            # pin and disc-profile errors: the disc must turn by Δθ_j(θ_o) more to load the pins
            d_rot = periodic_interp(e.disc_rotation[j], th_o)
            line(
                f"disc{j + 1}-pins",
                series(self.cycloid_fourier, p.pair.pin_count * chi),
                g,
                float(e.pin_composite[j, 0] * np.sin(th_o + e.pin_composite[j, 1])) - g_t * d_rot,
            )
        return out

    def stiffness_matrix(
        self, t: float = 0.0, *, mesh: str = "mean", input_shaft: bool = True
    ) -> np.ndarray:
        """K [N/mm, N, N·mm/rad mixed by DOF] assembled from the elements (clearances closed)."""
        K = np.zeros((self.n_dof, self.n_dof))
        for el in self.elements(t, mesh=mesh):
            if el["name"] == "input shaft" and not input_shaft:
                continue
            gs = el["g"] if el["kind"] == "bearing" else (el["g"],)
            for g in gs:
                K += el["k"] * np.outer(g, g)
        return K

    def external_force(self, t: float) -> np.ndarray:
        """Load torque on the output and centripetal loads of the carried bodies [N, N·mm]."""
        p = self.params
        m, n = p.crank_count, p.disc_count
        f = np.zeros(self.n_dof)
        f[-1] = -Nm_to_Nmm(p.output_torque_Nm)
        w_o = p.output_speed
        th_o = w_o * t
        th_h = deg_to_rad(p.crank_phase_deg) + (1.0 - p.pair.pin_count) * th_o
        for i in range(m):
            psi = th_o + 2 * np.pi * i / m
            c = p.centre_distance_mm * np.array([np.cos(psi), np.sin(psi)]) * w_o**2
            f[3 * (1 + i) : 3 * (1 + i) + 2] += p.planet_mass_kg * KG_TO_T * c
            f[3 * (1 + m + i) : 3 * (1 + m + i) + 2] += p.crank_mass_kg * KG_TO_T * c
        w_h = (1.0 - p.pair.pin_count) * w_o
        for j in range(n):
            chi = th_h + np.pi * j
            c = p.pair.eccentricity_mm * np.array([np.cos(chi), np.sin(chi)]) * w_h**2
            ic = 3 * (1 + 2 * m + j)
            f[ic : ic + 2] += p.disc_mass_kg * KG_TO_T * c
        return f

    def elastic_force(self, t: float, q: np.ndarray, v: np.ndarray | None = None) -> np.ndarray:
        """Element forces on the DOFs (springs with clearances, dampers) [N, N·mm]."""
        f = np.zeros(self.n_dof)
        br = self._beta_r
        v = np.zeros(self.n_dof) if v is None else v
        for el in self.elements(t):
            k = el["k"]
            if el["kind"] == "line":
                g = el["g"]
                d = g @ q + el["e"]
                f -= (k * d + br * k * (g @ v)) * g
            else:
                gx, gy = el["g"]
                d = np.array([gx @ q, gy @ q]) + el["e"]
                r = np.hypot(*d)
                cl = el["cl"]
                if cl > 0 and r <= cl:
                    continue
                s = k * (r - cl) / r if cl > 0 else k
                fx, fy = s * d + br * k * np.array([gx @ v, gy @ v])
                f -= fx * gx + fy * gy
        return f

    def rhs_numpy(self, t: float, y: np.ndarray) -> np.ndarray:
        """Plain-Python twin of :func:`rv_rhs` (element loop), for solve_ivp and tests."""
        nd = self.n_dof
        q, v = y[:nd], y[nd:]
        acc = (self.elastic_force(t, q, v) + self.external_force(t)) / self.mass
        return np.concatenate([v, acc])

    # --- statics and modes ---------------------------------------------------------------------
    def static_equilibrium(
        self,
        t: float = 0.0,
        *,
        tol: float = 1e-10,
        compiled: bool = True,
        args: tuple | None = None,
    ) -> np.ndarray:
        """Deviation q of static equilibrium at time t (modified Newton with the linear K).

        The residual (all element forces + loads at zero velocity) comes from the compiled
        :func:`rv_rhs` (``compiled=True``) or the plain element model. ``args``: this model's
        :meth:`kernel_args` when the caller holds them already (a batch run packs them once for
        the equilibrium and the integration).

        The iteration converges linearly where bearing clearances are open (the linear K is
        stiffer than the tangent stiffness: about 170 iterations at 10 µm, 1 500 at 200 µm on
        li2023_rv_errors), and a part inside its clearance drifts across it by a fixed step
        per iteration (34 000 iterations for one random realisation of that case's batch at
        10 µm), so the cap is :data:`STATIC_MAXIT`. Raises ConvergenceError (solver,
        iterations, residual, tolerance) at the cap or on a non-finite residual: a part with
        no load to push it against a contact has no equilibrium.
        """
        # K does not depend on the errors: shared by with_errors() copies. numpy's solve is
        # LAPACK's getrf + getrs, as scipy's lu_factor + lu_solve, without importing scipy.linalg
        # (~0.15 s CPU in a fresh process; nothing else on the dynamics' path imports it)
        k = self._k_cache.get(t)
        if k is None:
            k = self.stiffness_matrix(t, mesh="time")
            self._k_cache[t] = k
        nd = self.n_dof
        q = np.zeros(nd)
        f_ext = self.external_force(t)
        scale = np.max(np.abs(f_ext))
        if compiled and args is None:
            args = self.kernel_args()
        y = np.zeros(2 * nd)
        dydt = np.empty(2 * nd)
        kinv: np.ndarray | None = None
        res = np.inf
        for it in range(STATIC_MAXIT):  # noqa: B007 - reported on failure
            if compiled:
                y[:nd] = q
                rv_rhs(t, y, args, dydt, np.full(RHS_WORK_SIZE, np.nan))
                r = dydt[nd:] * self.mass
            else:
                r = self.elastic_force(t, q) + f_ext
            res = np.max(np.abs(r))
            if res <= tol * scale:
                return q
            if not np.isfinite(res):
                break
            if it < _STATIC_SOLVE_ITERATIONS:
                q = q + np.linalg.solve(k, r)
            else:  # a slow drift through clearances: the same step, cheaper per iteration
                if kinv is None:
                    kinv = np.linalg.inv(k)
                q = q + kinv @ r
        raise ConvergenceError(
            f"static_equilibrium: modified Newton did not converge in {it + 1} iterations "
            f"(residual {res:.3g} N, tolerance {tol * scale:.3g} N)"
        )

    def element_deflections(self, t: float, q: np.ndarray) -> dict[str, float]:
        """Deflection of each line element (or radial deflection of a bearing) [mm or rad]."""
        out = {}
        for el in self.elements(t):
            if el["kind"] == "line":
                out[el["name"]] = float(el["g"] @ q + el["e"])
            else:
                gx, gy = el["g"]
                out[el["name"]] = float(np.hypot(gx @ q + el["e"][0], gy @ q + el["e"][1]))
        return out

    def modal(self, t: float = 0.0, *, input_shaft: bool = True, mesh: str = "mean") -> ModalResult:
        """Undamped natural frequencies [Hz] and mode shapes (:func:`.modal.modal_analysis`)."""
        return modal_analysis(self, t, input_shaft=input_shaft, mesh=mesh)

    def rigid_mode(self, t: float = 0.0) -> np.ndarray:
        """Analytic rigid-body vector for θ_o = 1 [rad] (:func:`.modal.rigid_mode`)."""
        return rigid_mode(self, t)

    @property
    def damping_coefficient(self) -> float:
        """β_R of the stiffness-proportional element damping [s]."""
        return self._beta_r

    def damped_eigenvalues(self, t: float = 0.0, *, mesh: str = "max") -> np.ndarray:
        """Eigenvalues [1/s] of the first-order state matrix (:func:`.modal.damped_eigenvalues`).

        Computed once per (t, mesh) and handed back as the same read-only array (K and the
        damping do not depend on the errors, so :meth:`with_errors` copies share it).
        """
        ev = self._eig_cache.get((t, mesh))
        if ev is None:
            ev = damped_eigenvalues(self, t, mesh=mesh)
            ev.flags.writeable = False
            self._eig_cache[(t, mesh)] = ev
        return ev

    def resonance_warnings(
        self, margin: float = 0.1, harmonics: tuple[int, ...] = (1,)
    ) -> list[str]:
        """Mesh frequencies near a mode (:func:`.modal.resonance_warnings`)."""
        return resonance_warnings(self, margin, harmonics)

    def with_errors(self, errors: RVErrors) -> RVDynamicModel:
        """Same model (same contact analysis, same damping) with other errors."""
        new = object.__new__(RVDynamicModel)
        new.__dict__.update(self.__dict__)
        if (errors.crank_count, errors.disc_count) != (
            self.params.crank_count,
            self.params.disc_count,
        ):
            raise ParameterError("errors", (errors.crank_count, errors.disc_count), "wrong counts")
        _check_rotation_frame(self.params, errors)
        new.errors = errors
        return new

    def with_params(self, **changes) -> RVDynamicModel:
        """Model with some parameters changed (contact recomputed when the pair/load changes)."""
        new = replace(self.params, **changes)
        same = new.pair == self.params.pair and new.output_torque_Nm == self.params.output_torque_Nm
        return RVDynamicModel(new, self.errors, contact=self.contact if same else None)
