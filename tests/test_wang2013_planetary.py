"""Wang et al. 2013 (paper 002): planetary eccentricity errors, coupled TE, assembly, Monte-Carlo.

Paper figures used (Table 1 data, eq 9, Table 3, §3.1-3.2):
* e5 + e9 = 28.19 µm, |21 + 12 - 28.19| = 4.81 µm, e2 + e7 = 10.94 µm (printed to 0.01 µm);
* allocated TE 131.5″ (printed to 0.1″) with Table 3 angles gamma_s = beta_l + 7pi/9,
  gamma_c = beta_l + 8pi/9, gamma_p = 0;
* random assembly, 50 000 samples: min 111″, max 456″, mean 297″, sd 70″ (Fig 2, integers).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from gearte.errors import ParameterError
from gearte.geometry.planetary import PlanetarySet, willis_speeds
from gearte.io.case_file import load_case
from gearte.models.planetary_errors import (
    coupled_te,
    derive_terms,
    exact_extremes,
    exact_extremes_numpy,
    frequency_basis,
    grid_extremes_numpy,
    terms_from_table,
)
from gearte.runners.planetary_assembly import optimal_assembly, paper_rule_assembly
from gearte.runners.planetary_mc import run_scenario
from gearte.studies.planetary import build_terms
from gearte.units import rad_to_arcsec

ALPHA = np.pi / 9
TABLE1_UM = {"E_s": 13.0, "A_s": 12.0, "E_p1": 16.0, "A_p1": 8.0, "E_r": 21.0, "A_c": 15.0}


def wang_set(**kw) -> PlanetarySet:
    args = dict(z_sun=12, z_planet=36, z_ring=84, module=1.0, pressure_angle=ALPHA, n_planets=3)
    args.update(kw)
    return PlanetarySet(**args)


def mm(d: dict[str, float]) -> dict[str, float]:
    return {k: v * 1e-3 for k, v in d.items()}


@pytest.fixture(scope="module")
def eq9():
    terms, mags, angs = build_terms(load_case("wang2013_2kh_eq9"))
    return terms, mags, angs


# --------------------------------------------------------------------------- kinematics
@pytest.mark.parametrize(
    "fixed, inp, out",
    [
        ("ring", "sun", "carrier"),
        ("carrier", "sun", "ring"),
        ("sun", "carrier", "ring"),
        ("ring", "carrier", "sun"),
    ],
)
def test_frequencies_follow_willis(fixed, inp, out):
    """Frequencies of the derived terms against the Willis equation written independently for
    the *internal* mesh, (w_p - w_c)/(w_r - w_c) = z_r/z_p (the code uses the sun mesh)."""
    p = wang_set(fixed=fixed, input=inp, output=out)
    w = willis_speeds(12, 84, fixed, inp)
    wp_rel = Fraction(84, 36) * (
        Fraction(w["ring"]).limit_denominator() - Fraction(w["carrier"]).limit_denominator()
    )
    freq = {t.magnitude: t.frequency for t in derive_terms(p).terms}
    wc = Fraction(w["carrier"]).limit_denominator()
    assert freq["E_s"] == Fraction(w["sun"]).limit_denominator() - wc
    assert freq["E_r"] == Fraction(w["ring"]).limit_denominator() - wc
    assert freq["A_s"] == freq["A_c"] == -wc
    assert freq["E_p1"] == wp_rel
    assert freq["A_p1"] == 0


def test_wang_example_speeds_and_ratio():
    p = wang_set()
    r = p.speed_ratios()
    assert (r["carrier"], r["planet_rel"]) == (Fraction(1, 8), Fraction(-7, 24))
    assert p.ratio == 8.0
    # eq 9 prefactor 1/(48000 cos(pi/9)) per µm
    assert p.output_scale() * 1e-3 == pytest.approx(1 / (48000 * np.cos(ALPHA)), rel=1e-14)
    q0, harm, _ = frequency_basis(derive_terms(p))
    assert q0 == Fraction(1, 24) and harm == (3, 7, 21)


# --------------------------------------------------------------------------- signs by symmetry
def _const_te(p: PlanetarySet, mags: dict[str, float], angs: dict[str, float]) -> float:
    """Signed output error [rad] at t = 0."""
    r = coupled_te(
        derive_terms(p), {**dict.fromkeys(derive_terms(p).magnitudes, 0.0), **mags}, angs
    )
    return float(r.signal(np.array([0.0]))[0] * r.scale)


@pytest.mark.parametrize("angle", [0.0, 0.7, 2.0, 4.0])
def test_rigid_translation_of_sun_ring_and_carrier_cancels(angle):
    """Sun axis, ring and carrier axis displaced together by the same vector: nothing changes
    relative to each other, so the TE must vanish at all times (Wang's ring sign fails this)."""
    p = wang_set()
    terms = derive_terms(p)
    mags = {**dict.fromkeys(terms.magnitudes, 0.0), "A_s": 0.01, "A_r": 0.01, "A_c": 0.01}
    angs = {"gamma_s": angle, "gamma_r": angle, "gamma_c": angle}
    r = coupled_te(terms, mags, angs)
    assert r.amplitude < 1e-15


def test_radial_planet_offset_cancels_and_tangential_gives_d_over_a():
    """A planet's tooth centre moved radially between sun and ring changes nothing; moved
    tangentially by d it makes the carrier lag by d/a exactly (rigid-body argument)."""
    p = wang_set()
    d = 0.01
    assert abs(_const_te(p, {"A_p1": d}, {"gamma_p1": 0.0})) < 1e-15
    assert _const_te(p, {"A_p1": d}, {"gamma_p1": np.pi / 2}) == pytest.approx(
        -d / p.centre_distance, rel=1e-12
    )
    # the planet's manufacturing eccentricity is the same rigid offset, turning with the planet
    r = coupled_te(derive_terms(p), {**mm(dict.fromkeys(TABLE1_UM, 0.0)), "E_p1": d, "A_r": 0}, {})
    assert r.amplitude == pytest.approx(d / p.centre_distance, rel=1e-12)


def test_mean_over_planets_cancels_sun_ring_carrier_terms():
    """With equally spaced planets and ideal load sharing the once-per-carrier-turn terms of
    sun, ring and carrier average out; only planet terms remain (gain 1/N)."""
    p = wang_set()
    terms = derive_terms(p, "mean")
    mags = {k: 0.0 for k in terms.magnitudes}
    mags.update({"E_s": 0.013, "A_s": 0.012, "E_r": 0.021, "A_c": 0.015})
    assert coupled_te(terms, mags, {"gamma_s": 1.0, "gamma_c": 2.0}).amplitude < 1e-15


# --------------------------------------------------------------------------- exact amplitude
def test_exact_kernel_matches_twin_and_fine_grid():
    rng = np.random.default_rng(7)
    n = 120
    c = rng.normal(size=n)
    Z = rng.normal(size=(n, 3)) + 1j * rng.normal(size=(n, 3))
    Z[: n // 4, 0] = 0  # some with flat regions
    harm = (3, 11, 21)
    fx, fn = exact_extremes(c, Z, harm)
    tx, tn = exact_extremes_numpy(c, Z, harm)
    gx, gn = grid_extremes_numpy(c, Z, harm, points=200_000)
    scale = np.abs(Z).sum(1) + np.abs(c)
    assert np.all(np.abs(fx - tx) <= 1e-11 * scale) and np.all(np.abs(fn - tn) <= 1e-11 * scale)
    # the fine grid can only be below the true max, by at most h²/8 Σ|Z| n²
    bound = (2 * np.pi / 200_000) ** 2 / 8 * (np.abs(Z) * np.array(harm) ** 2).sum(1)
    assert np.all(fx >= gx - 1e-12) and np.all(fx - gx <= bound + 1e-12)
    assert np.all(fn <= gn + 1e-12) and np.all(gn - fn <= bound + 1e-12)


def test_exact_amplitude_of_third_harmonic_injection():
    """sin x + (1/6) sin 3x = 1.5 s - (2/3) s³ with s = sin x: the maximum is at s = sqrt(3)/2
    and equals sqrt(3)/2 exactly (the classic third-harmonic injection)."""
    fx, fn = exact_extremes(np.array([0.0]), np.array([[1.0 + 0j, 1 / 6 + 0j]]), (1, 3))
    assert fx[0] == pytest.approx(np.sqrt(3) / 2, rel=1e-14)
    assert fn[0] == pytest.approx(-np.sqrt(3) / 2, rel=1e-14)


def test_same_frequency_sum_is_exact_phasor_sum():
    """Two terms of one frequency: amplitude sqrt(A1² + A2² + 2 A1 A2 cos(phi1 - phi2)) (eq 3)."""
    terms = terms_from_table(
        [
            {"magnitude": "a", "frequency": "1/8", "phase": 0.3, "angle": None},
            {"magnitude": "b", "frequency": "1/8", "phase": 2.9, "angle": None},
        ],
        scale=1.0,
    )
    r = coupled_te(terms, {"a": 2.0, "b": 1.5}, {})
    assert r.amplitude == pytest.approx(np.sqrt(4 + 2.25 + 6 * np.cos(0.3 - 2.9)), rel=1e-12)
    assert r.peak_to_peak == pytest.approx(2 * r.amplitude, rel=1e-12)


# --------------------------------------------------------------------------- eq 9 as printed
def test_wang2013_eq9_groups_and_table3_allocation(eq9):
    terms, mags, _ = eq9
    plan = paper_rule_assembly(terms, mags, {"beta_l": 0.0})
    deg = {k: np.rad2deg(v) for k, v in plan.angles.items()}
    # Table 3: gamma_s = beta_l + 7pi/9, gamma_c = beta_l + 8pi/9, gamma_p = 0
    assert deg["gamma_s"] == pytest.approx(140.0, abs=1e-9)
    assert deg["gamma_c"] == pytest.approx(160.0, abs=1e-9)
    assert deg["gamma_p"] == pytest.approx(0.0, abs=1e-9)
    assert set(plan.set_by_rule) == {"gamma_s", "gamma_c", "gamma_p"}
    r = coupled_te(terms, mags, plan.angles)
    amp = {str(f): abs(z) * 1e3 for f, z in zip(r.frequencies, r.phasors, strict=True)}
    assert amp["1/8"] == pytest.approx(4.81, abs=0.005)
    assert amp["11/24"] == pytest.approx(10.94, abs=0.005)
    assert amp["7/8"] == pytest.approx(13.0, abs=1e-12)
    assert abs(r.constant) < 1e-15
    # e5 + e9 alone: 28.19 µm
    only_c = {k: (v if k == "A_c" else 0.0) for k, v in mags.items()}
    assert coupled_te(terms, only_c, {}).amplitude / abs(terms.scale) * 1e3 == pytest.approx(
        28.19, abs=0.005
    )
    # the paper's allocated TE, as it defines it (lambda = 1 across frequencies): 131.5″
    assert rad_to_arcsec(plan.amplitude_sum) == pytest.approx(131.5, abs=0.05)
    # exact amplitude at the same angles (beta_s = beta_p = 0) is lower, never higher
    assert plan.amplitude <= plan.amplitude_sum


def test_wang2013_fig2_random_assembly_statistics(eq9):
    """Fig 2 (50 000 samples): min 111″, max 456″, mean 297″, sd 70″ (printed as integers).
    Tolerances: rounding 0.5″ + 3 standard errors (SE mean 0.31″, SE sd ~0.16″); for the
    extremes 3 x the seed-to-seed spread measured over 30 seeds (min 1.75″, max 0.8″)."""
    terms, mags, _ = eq9
    r = run_scenario(terms, "random_assembly", mags, samples=50_000, seed=2013)
    s = r.stats
    asec = float(rad_to_arcsec(1.0))
    assert s.count == 50_000
    assert s.mean * asec == pytest.approx(297, abs=0.5 + 3 * 0.31)
    assert s.sd * asec == pytest.approx(70, abs=0.5 + 3 * 0.16)
    assert s.min * asec == pytest.approx(111, abs=0.5 + 3 * 1.75)
    assert s.max * asec == pytest.approx(456, abs=0.5 + 3 * 0.8)


def test_half_tolerance_is_exactly_half(eq9):
    """TE is homogeneous of degree 1 in the magnitudes: with the same seed, the half-tolerance
    run is the full run halved. Hence Wang's Fig 3 mean 140″ (vs 297/2) cannot come from the
    Fig 2 model (docs/validation/wang2013.md)."""
    terms, mags, _ = eq9
    full = run_scenario(terms, "random_assembly", mags, samples=20_000, seed=5)
    half = run_scenario(terms, "random_assembly_half_tolerance", mags, samples=20_000, seed=5)
    assert half.stats.mean == pytest.approx(full.stats.mean / 2, rel=1e-12)
    assert half.stats.max == pytest.approx(full.stats.max / 2, rel=1e-12)


def test_wang2013_fig4_allocated_random_magnitudes(eq9):
    """Fig 4: min 10″, max 216″, mean 90″, sd 30″ with the Rayleigh reading 'tolerance = 2
    sigma, truncated' (the paper does not state sigma; see the validation doc)."""
    terms, mags, _ = eq9
    plan = paper_rule_assembly(terms, mags, {"beta_l": 0.0})
    fixed = {a: plan.angles[a] for a in plan.set_by_rule}
    r = run_scenario(
        terms,
        "allocated_assembly_random_magnitudes",
        mags,
        samples=50_000,
        seed=11,
        assembly_angles=fixed,
    )
    asec = float(rad_to_arcsec(1.0))
    assert r.stats.mean * asec == pytest.approx(90, abs=0.5 + 3 * 0.14)
    assert r.stats.sd * asec == pytest.approx(30, abs=0.5 + 3 * 0.1)


def test_results_do_not_depend_on_workers(eq9):
    terms, mags, _ = eq9
    a = run_scenario(terms, "random_assembly", mags, samples=30_000, chunk_size=5_000, workers=1)
    b = run_scenario(terms, "random_assembly", mags, samples=30_000, chunk_size=5_000, workers=2)
    assert (a.stats.mean, a.stats.m2, a.stats.min, a.stats.max) == (
        b.stats.mean,
        b.stats.m2,
        b.stats.min,
        b.stats.max,
    )
    assert np.array_equal(a.hist, b.hist)


# --------------------------------------------------------------------------- optimal assembly
def test_optimal_beats_sign_rule_when_three_phasors_form_a_triangle():
    """Three same-frequency units 21, 12, 28.19: the ±1 rule leaves |21 + 12 - 28.19| = 4.81,
    but since each is below the sum of the others they close a triangle: the optimum is 0."""
    terms = terms_from_table(
        [
            {"magnitude": "r", "frequency": "1/8", "phase": 0.0, "angle": "ref"},
            {"magnitude": "s", "frequency": "1/8", "phase": 0.0, "angle": "gs"},
            {"magnitude": "c", "frequency": "1/8", "phase": 0.0, "angle": "gc"},
        ],
        scale=1.0,
        reference_angle="ref",
    )
    mags = {"r": 21.0, "s": 12.0, "c": 28.19}
    rule = paper_rule_assembly(terms, mags)
    assert rule.amplitude == pytest.approx(4.81, abs=1e-9)
    opt = optimal_assembly(terms, mags, starts=256, polish=4)
    assert opt.amplitude < 1e-8
    # law of cosines: the angle between the 21 and 12 phasors closes the triangle
    cos_t = (28.19**2 - 21**2 - 12**2) / (2 * 21 * 12)
    dth = abs(np.angle(np.exp(1j * (opt.angles["gs"] - opt.angles["ref"]))))
    assert dth == pytest.approx(np.arccos(cos_t), abs=1e-5)


def test_optimal_assembly_of_wang_example(eq9):
    terms, mags, _ = eq9
    rule = paper_rule_assembly(terms, mags, {"beta_l": 0.0})
    opt = optimal_assembly(terms, mags, starts=1024, polish=4, extra_starts=[rule.angles])
    assert opt.amplitude <= rule.amplitude + 1e-15
    # global: independent quasi-random start sets reach the same minimum
    opt2 = optimal_assembly(terms, mags, starts=1024, polish=4, seed=99)
    assert opt2.amplitude == pytest.approx(opt.amplitude, rel=1e-8)
    # and it lies below the sum of the two groups that cannot be cancelled (13 + 10.94 µm):
    # the residual 1/8 group is used to shave the peaks, which the ±1 rule cannot do
    assert rad_to_arcsec(opt.amplitude) == pytest.approx(107.55, abs=0.01)


def test_compiled_nelder_mead_polish_matches_scipy_twin(eq9):
    """The compiled polish is a port of SciPy's adaptive Nelder-Mead on the same objective: from
    the same starts it reaches the same minimum (to rounding) and the same optimum overall."""
    terms, mags, _ = eq9
    rule = paper_rule_assembly(terms, mags, {"beta_l": 0.0})
    kw = dict(starts=256, polish=3, extra_starts=[rule.angles])
    fast = optimal_assembly(terms, mags, **kw)
    twin = optimal_assembly(terms, mags, compiled=False, **kw)
    assert fast.amplitude == pytest.approx(twin.amplitude, rel=1e-12)
    assert rad_to_arcsec(fast.amplitude) == pytest.approx(107.55, abs=0.01)


def test_optimal_assembly_on_threads_is_the_one_thread_result(eq9):
    """The polish's starts run on threads (issue 12: Wang's warm run); each start takes the
    same steps, so the plan is bit-identical for any number of threads."""
    terms, mags, _ = eq9
    rule = paper_rule_assembly(terms, mags, {"beta_l": 0.0})
    kw = dict(starts=512, polish=5, extra_starts=[rule.angles])
    one = optimal_assembly(terms, mags, workers=1, **kw)
    for workers in (2, 3):
        assert optimal_assembly(terms, mags, workers=workers, **kw) == one


def test_halton_starts_fill_each_axis_evenly():
    """Shifted Halton points: in [0, 1), deterministic per seed, and every 1-D projection of
    n points in base b leaves no gap wider than ~b/2n (a pseudo-random set leaves gaps
    ~ ln(n)/n, 6-8/n here)."""
    from gearte.runners.planetary_assembly import halton_starts

    a = halton_starts(1024, 3, 7)
    assert a.shape == (1024, 3)
    assert np.all((a >= 0) & (a < 1))
    assert np.array_equal(a, halton_starts(1024, 3, 7))
    assert not np.array_equal(a, halton_starts(1024, 3, 8))
    for j in range(3):  # bases 2, 3, 5
        x = np.sort(a[:, j])
        gaps = np.diff(np.concatenate([x, [x[0] + 1.0]]))
        assert gaps.max() < 2.5 / 1024


# --------------------------------------------------------------------------- bad input
def test_bad_geometry_is_named():
    with pytest.raises(ParameterError, match="z_ring.*z_r = z_s \\+ 2 z_p = 84"):
        wang_set(z_ring=85)
    with pytest.raises(ParameterError, match="cannot be assembled"):
        wang_set(n_planets=5)  # (12 + 84) / 5 is not an integer
    with pytest.raises(ParameterError, match="planet_angles"):
        wang_set(planet_angles=(0.0, 2.0, 4.0))
    with pytest.raises(ParameterError, match="overlap"):
        wang_set(n_planets=6)
    with pytest.raises(ParameterError, match="permutation"):
        wang_set(fixed="sun", input="sun")
    # non-standard gears may violate the concentricity condition on purpose
    assert wang_set(z_ring=84, standard=False).z_ring == 84


def test_negative_magnitude_is_an_error():
    terms = derive_terms(wang_set())
    mags = {**dict.fromkeys(terms.magnitudes, 0.0), "E_s": -0.001}
    with pytest.raises(ParameterError, match="magnitudes.E_s"):
        coupled_te(terms, mags, {})
    with pytest.raises(ParameterError, match="missing"):
        coupled_te(terms, {"E_s": 0.01}, {})


def test_derived_terms_vs_eq9_term_by_term(eq9):
    """Derived terms equal eq 9's bracket term by term except the documented discrepancies:
    e2 (frequency 7/24 not 11/24, and phase + pi), e6 (phase + pi), e7 (frequency 7/24)."""
    eq_terms, _, _ = eq9
    derived = derive_terms(wang_set())
    by_name = {t.name.split("/planet")[0]: t for t in derived.terms}
    pairs = {  # eq 9 term -> (derived term, expected frequency, extra phase)
        "e1": ("E_s/external", Fraction(7, 8), 0.0),
        "e2": ("E_p1/external", Fraction(7, 24), np.pi),
        "e3": ("A_s/external", Fraction(1, 8), 0.0),
        "e4": ("A_p1/external", Fraction(0), 0.0),
        "e5": ("A_c/external", Fraction(1, 8), 0.0),
        "e6": ("E_r/internal", Fraction(1, 8), np.pi),
        "e7": ("E_p1/internal", Fraction(7, 24), 0.0),
        "e8": ("A_p1/internal", Fraction(0), 0.0),
        "e9": ("A_c/internal", Fraction(1, 8), 0.0),
    }
    rng = np.random.default_rng(3)
    t = rng.uniform(0, 100, 7)  # input angle w_s t [rad]
    th = rng.uniform(0, 2 * np.pi)  # any common angle value
    for e in eq_terms.terms:
        key = e.name.split()[0]
        dname, q, extra = pairs[key]
        d = by_name[dname]
        # both written as +-sin(q t + phase + k theta); derived has k = +1 with the signed q
        dv = d.gain * np.sin(float(d.frequency) * t + d.phase + d.angle_coeff * th)
        ev = np.sin(float(q) * t + e.phase + extra + e.angle_coeff * th)  # eq 9 with the fix
        assert abs(d.frequency) == q
        assert np.allclose(dv, ev, atol=1e-12), key


def test_exact_kernel_near_ties_and_degenerate_inputs():
    """Peaks of (nearly) equal height are where pruning could pick the wrong one: compare with
    the twin that refines every discrete extremum. Also a pure constant and one harmonic."""
    rng = np.random.default_rng(11)
    n = 200
    Z = np.zeros((n, 3), dtype=complex)
    Z[:, 0] = np.exp(1j * rng.uniform(0, 2 * np.pi, n))  # harmonic 3: three equal peaks
    Z[:, 1] = 10.0 ** rng.uniform(-12, -3, n) * np.exp(1j * rng.uniform(0, 2 * np.pi, n))
    Z[:, 2] = 10.0 ** rng.uniform(-12, -3, n) * np.exp(1j * rng.uniform(0, 2 * np.pi, n))
    c = rng.normal(size=n) * 0.1
    harm = (3, 7, 21)
    fx, fn = exact_extremes(c, Z, harm)
    tx, tn = exact_extremes_numpy(c, Z, harm)
    assert np.allclose(fx, tx, rtol=0, atol=1e-13) and np.allclose(fn, tn, rtol=0, atol=1e-13)
    fx, fn = exact_extremes(np.array([0.3]), np.zeros((1, 3), dtype=complex), harm)
    assert fx[0] == pytest.approx(0.3, abs=1e-15) and fn[0] == pytest.approx(0.3, abs=1e-15)
    fx, fn = exact_extremes(np.array([0.0]), np.array([[0, 0, 2.0 - 1.0j]]), harm)
    assert fx[0] == pytest.approx(np.sqrt(5), rel=1e-14)
    assert fn[0] == pytest.approx(-np.sqrt(5), rel=1e-14)


@pytest.mark.parametrize("a1, a2", [(21.0, 12.0), (13.0, 10.94), (5.0, 4.99)])
def test_wang2013_conclusion4_compensation_interval(a1, a2):
    """Wang §1(2) / conclusion (4): two same-frequency terms (A1 > A2) compensate (B2 < A1)
    exactly when the phase difference lies in (arccos(-A2/2A1), 2pi - arccos(-A2/2A1)); the
    best is ±pi with B2 = A1 - A2."""
    edge = np.arccos(-a2 / (2 * a1))
    for dphi, expect in [(edge, a1), (np.pi, a1 - a2), (0.0, a1 + a2)]:
        terms = terms_from_table(
            [
                {"magnitude": "a", "frequency": "1/8", "phase": dphi, "angle": None},
                {"magnitude": "b", "frequency": "1/8", "phase": 0.0, "angle": None},
            ],
            scale=1.0,
        )
        assert coupled_te(terms, {"a": a1, "b": a2}, {}).amplitude == pytest.approx(
            expect, rel=1e-12
        )
