"""Selective assembly of a lot of measured RV parts and pin grading (issue 16)."""

from __future__ import annotations

import dataclasses
import tomllib

import numpy as np
import pytest

from gearte.cases import case_path
from gearte.io.case_file import load_case
from gearte.models.rv_load_sharing import output_positions
from gearte.runners import selective_assembly as sa
from gearte.studies import run_case
from gearte.studies.rv_lot import build_lot
from gearte.units import arcmin_to_rad, arcsec_to_rad

TORQUE = 1078e3  # N·mm, rated torque of the design


@pytest.fixture(scope="module")
def bundled():
    return build_lot(load_case("synthetic_rv110e_lot"))


def _subset(lot: sa.Lot, disc_sets, crank_sets) -> sa.Lot:
    def take(a, idx):
        return None if a is None else a[list(idx)]

    return sa.Lot(
        [lot.disc_serials[k] for k in disc_sets],
        [lot.discs[k] for k in disc_sets],
        take(lot.disc_bores, disc_sets),
        [lot.crank_serials[k] for k in crank_sets],
        take(lot.cam_eccentricity, crank_sets),
        take(lot.cam_phase, crank_sets),
        take(lot.planet_runout, crank_sets),
        take(lot.cam_clearance, crank_sets),
        take(lot.carrier_clearance, crank_sets),
    )


@pytest.fixture(scope="module")
def small(bundled):
    """Four disc sets and four crank sets of the bundled synthetic lot, scored at 72 angles."""
    design, lot = bundled
    lot4 = _subset(lot, range(4), range(4, 8))
    model = sa.linear_te_model(design, TORQUE, output_positions(72))
    return design, lot4, model, sa.score_lot(design, lot4, model)


@pytest.mark.parametrize("objective", ["count_in_spec", "worst"])
def test_optimiser_equals_brute_force_over_every_assignment_and_orientation(small, objective):
    """4 disc sets × 4 crank sets × 6 disc orientations × 3 crank orientations: brute force
    enumerates 4! pairings × 18⁴ orientation choices."""
    *_, table = small
    best, _, _ = table.best()
    for limit in np.quantile(best, [0.3, 0.5, 0.8]):
        got = sa.assign(table, limit, objective)
        want = sa.brute_force(table, limit, objective)
        if objective == "count_in_spec":
            assert got.in_spec(limit) == want
        else:
            assert got.pp.max() == pytest.approx(want, rel=1e-12)


def test_part_contributions_equal_the_plain_loop_over_pairings(small):
    """The vectorised scores (one TE contribution per oriented part set) equal the plain loop
    that builds every oriented reducer and its offsets with assemble(): same linear model,
    so equal to round-off — this also checks every orientation's bookkeeping."""
    design, lot4, model, table = small
    lot2 = _subset(lot4, [0, 1], [2, 3])
    fast = sa.score_lot(design, lot2, model, planet_indexings=2)
    loop = sa.score_lot_loop(design, lot2, model, planet_indexings=2)
    assert fast.pp.shape == (2, 6, 2, 6)
    np.testing.assert_allclose(fast.pp, loop.pp, rtol=1e-9, atol=1e-15)


def test_linearised_score_close_to_the_full_model(small):
    """The linearisation (contact set and stiffness of the design) against the full non-linear
    model on three pairings of the lot: measured on this lot, within 2.5 arcsec on TE of
    5-60 arcsec (the bearing clearances of the lot are the main non-linearity)."""
    design, lot4, model, table = small
    theta = model.theta
    for kd, od, kc, oc in [(0, 0, 0, 0), (1, 3, 2, 1), (3, 5, 1, 2)]:
        red = sa.assembled_reducer(design, lot4, kd, kc, table.orientation(od, oc))
        full = sa.full_model_te(red, TORQUE, theta)
        assert abs(table.pp[kd, od, kc, oc] - full) < arcsec_to_rad(2.5)


def test_orientation_only_and_random_are_not_better_than_the_optimiser(small):
    *_, table = small
    limit = float(np.median(table.best()[0]))
    best = sa.assign(table, limit)
    rnd = sa.random_assemblies(table, limit, 100, np.random.default_rng(0))
    assert best.in_spec(limit) >= sa.orientation_only(table).in_spec(limit)
    assert best.in_spec(limit) >= rnd.max()


def test_pin_grade_brings_backlash_into_the_window(small):
    """Backlash falls as the pins grow; the chosen grade's backlash is inside the window."""
    design, lot4, model, table = small
    red = sa.assembled_reducer(design, lot4, 0, 0, sa.Orientation())
    grades = np.array([-6e-3, -3e-3, 0.0, 3e-3])
    window = (float(arcmin_to_rad(0.2)), float(arcmin_to_rad(0.6)))
    g, backlash = sa.pin_grades(red, grades, window)
    finite = backlash[np.isfinite(backlash)]
    assert np.all(np.diff(finite) < 0)
    assert g is not None and window[0] <= backlash[g] <= window[1]


def test_rv_lot_study_on_part_of_the_bundled_lot():
    """The ``rv_lot`` kind on three reducers of the bundled lot: results named as the issue
    asks, CSV instructions with one row per reducer naming every part."""
    data = tomllib.loads(case_path("synthetic_rv110e_lot").read_text(encoding="utf-8"))
    data["lot"]["disc_sets"] = data["lot"]["disc_sets"][:3]
    data["lot"]["crank_sets"] = data["lot"]["crank_sets"][:3]
    sec = data["analyses"]["selective_assembly"]
    sec.update(positions=36, random_assemblies=100)
    del data["analyses"]["pin_grading"]
    res = run_case(load_case(data))
    v = res["selective_assembly"].values
    for key in (
        "reducers_in_spec",
        "reducers_in_spec_random_mean",
        "reducers_in_spec_orientation_only",
    ):
        assert key in v
    assert v["reducers"] == 3
    csv = res["selective_assembly"].files["assembly_instructions.csv"].splitlines()
    assert len(csv) == 4 and csv[0].startswith("reducer,disc_slot_1,disc_slot_2")
    used = {c for row in csv[1:] for c in row.split(",")[1:3] + row.split(",")[4:7]}
    assert used == {f"D-{k:04d}" for k in range(1, 7)} | {f"C-{k:04d}" for k in range(1, 10)}
    # the report summary: the worst reducer checked against the spec, the counts with the spec
    # they count against (the spec column was empty)
    from gearte.report.summary import analysis_headlines

    rows = analysis_headlines(res["selective_assembly"])
    worst = rows[0]
    assert worst.quantity.lower().startswith("worst te")
    assert worst.spec == "≤ 15″" and worst.status in ("pass", "fail")
    assert (worst.status == "pass") == (v["worst_te_peak_to_peak [arcsec]"] <= 15.0)
    counts = [r for r in rows if r.quantity.startswith("Reducers in spec")]
    assert counts and all(r.spec == "TE peak-to-peak ≤ 15″" for r in counts)


def test_pin_grading_summary_names_the_backlash_window():
    """The pin-grading summary rows carry the window they grade into in the spec column."""
    from gearte.report.summary import analysis_headlines
    from gearte.results import AnalysisResult

    a = AnalysisResult(
        name="pin_grading",
        title="Pin grades",
        values={
            "backlash_window [arcmin]": [0.2, 0.6],
            "reducers_graded": 18,
            "reducers_without_grade": 6,
        },
    )
    rows = {r.quantity: r.spec for r in analysis_headlines(a)}
    assert rows["Reducers graded"] == "backlash 0.2′ – 0.6′"


@pytest.mark.slow
def test_bundled_lot_optimiser_beats_random_and_orientation_only():
    """The bundled synthetic lot of 24 reducers: more reducers in spec with the optimiser than
    the mean of 200 random assemblies and than orientation only, also by the full model."""
    res = run_case(load_case("synthetic_rv110e_lot"))
    v = res["selective_assembly"].values
    assert v["reducers"] == 24
    assert v["reducers_in_spec"] > v["reducers_in_spec_random_mean"]
    assert v["reducers_in_spec"] > v["reducers_in_spec_orientation_only"]
    assert v["reducers_in_spec_full_model"] > v["reducers_in_spec_orientation_only"]
    assert res["pin_grading"]["reducers_graded"] >= 12


def test_lot_shapes_are_checked(small):
    design, lot4, *_ = small
    bad = dataclasses.replace(lot4, cam_phase=lot4.cam_phase[:, :2])
    with pytest.raises(Exception, match="cam_phase"):
        bad.check(design)


@pytest.mark.parametrize("kind", ["synthetic_rv110e_lot", "synthetic_rv110e_serial"])
def test_measured_parts_case_refuses_a_design_that_is_not_an_rv_reducer(kind):
    """rv_lot and rv_serial share their case base (design reference, files read at
    validation): a design case of another kind is refused naming ``reducer.case``."""
    from gearte.errors import CaseFileError
    from gearte.io.case_file import load_case_dict

    path = case_path(kind)
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data["reducer"]["case"] = "jiang2024_spur_pair"
    with pytest.raises(CaseFileError, match=r"reducer\.case.*need rv_reducer"):
        load_case_dict(data, base_dir=str(path.parent))


@pytest.fixture(scope="module")
def sub_lots_full(bundled):
    """Two 6-reducer sub-lots of the bundled lot (disc sets 1–6 with crank sets 7–12, disc sets
    13–18 with crank sets 19–24) at 18 angles (the optimiser's test, not the TE's: both scores
    on the same angles): linearised scores and the full model's TE of every pairing and
    orientation (6 × 6 × 6 × 3 = 648 full solves each)."""
    design, lot = bundled
    model = sa.linear_te_model(design, TORQUE, output_positions(18))
    out = []
    for discs, cranks in ((range(0, 6), range(6, 12)), (range(12, 18), range(18, 24))):
        sub = _subset(lot, discs, cranks)
        table = sa.score_lot(design, sub, model)
        full = np.empty_like(table.pp)
        for kd, od, kc, oc in np.ndindex(*table.pp.shape):
            red = sa.assembled_reducer(design, sub, kd, kc, table.orientation(od, oc))
            full[kd, od, kc, oc] = sa.full_model_te(red, TORQUE, model.theta)
        out.append((table, full))
    return out


@pytest.mark.parametrize("objective", ["count_in_spec", "worst"])
def test_rescored_assembly_reaches_the_full_model_brute_force_optimum(sub_lots_full, objective):
    """On both 6-reducer sub-lots, for both objectives and three specs (the 20/40/60 %
    quantiles of the pairings' full-model TE): the assembly re-scored with the full model until
    stable (and certified) is the optimum of brute force over all 720 pairings of the full
    model's scores (each pairing in its best orientation); every claimed TE is the full
    model's. The linearised assignment alone misses it at least once (at 36 angles: first
    sub-lot, worst reducer 11.1″ by the full model against the optimum 8.7″; second, 2 in
    spec against 4 at the 20 % spec)."""
    missed = 0
    for table, full in sub_lots_full:
        by_pairing = sa.ScoreTable(full, table.disc_orientations, table.crank_orientations)
        best_full = by_pairing.best()[0]

        def full_te(keys, full=full):
            return np.array([full[k] for k in keys])

        for q in (0.2, 0.4, 0.6):
            limit = float(np.quantile(best_full, q))
            want = sa.brute_force_pairings(best_full, limit, objective)
            r = sa.assign_rescored(table, limit, full_te, objective)
            a = r.assembly
            keys = zip(
                a.disc_set, a.disc_orientation, a.crank_set, a.crank_orientation, strict=True
            )
            assert np.array_equal(a.pp, [full[k] for k in keys])
            assert r.stable and r.certified
            first = r.first
            f1 = full_te(
                list(
                    zip(
                        first.disc_set,
                        first.disc_orientation,
                        first.crank_set,
                        first.crank_orientation,
                        strict=True,
                    )
                )  # fmt: skip
            )
            if objective == "count_in_spec":
                assert a.in_spec(limit) == want
                missed += int(np.sum(f1 <= limit)) < want
            else:
                assert a.pp.max() == pytest.approx(want, rel=1e-12)
                missed += f1.max() > want * (1 + 1e-12)
    assert missed >= 1  # the re-scoring is needed


def test_brute_force_pairings_equals_the_enumeration_over_orientations(small):
    """Both objectives only improve when a reducer's TE falls, so the best orientation per
    pairing is optimal: the pairing-only brute force equals the one over every orientation."""
    *_, table = small
    best = table.best()[0]
    for limit in np.quantile(best, [0.3, 0.7]):
        for objective in ("count_in_spec", "worst"):
            assert sa.brute_force_pairings(best, limit, objective) == sa.brute_force(
                table, limit, objective
            )


@pytest.mark.slow
def test_bundled_lot_claims_the_full_model_count():
    """The bundled lot (24 reducers, spec 15″, count in spec): the reducers in spec claimed are
    the full model's count, and each reducer's reported TE is the full model's (three re-solved
    here); the linearisation error per reducer is reported."""
    data = tomllib.loads(case_path("synthetic_rv110e_lot").read_text(encoding="utf-8"))
    del data["analyses"]["pin_grading"]
    data["analyses"]["selective_assembly"]["random_assemblies"] = 100
    res = run_case(load_case(data))
    a = res["selective_assembly"]
    v = a.values
    assert v["reducers_in_spec"] == v["reducers_in_spec_full_model"]
    assert v["rescoring_stable"] and v["rescoring_certified"]
    rows = v["assembly_instructions"]
    assert sum(r["in_spec"] for r in rows) == v["reducers_in_spec"]
    for r in rows:
        assert r["te_peak_to_peak [arcsec]"] == r["te_peak_to_peak_full_model [arcsec]"]
        assert r["linearisation_error [arcsec]"] == pytest.approx(
            r["te_peak_to_peak_linearised [arcsec]"] - r["te_peak_to_peak_full_model [arcsec]"],
            abs=2e-3,
        )
    design, lot = build_lot(load_case(data))
    best, table = a.data["best"], a.data["table"]
    theta = output_positions(data["analyses"]["selective_assembly"]["positions"])
    for i in (0, 11, 23):
        o = table.orientation(int(best.disc_orientation[i]), int(best.crank_orientation[i]))
        red = sa.assembled_reducer(design, lot, int(best.disc_set[i]), int(best.crank_set[i]), o)
        assert best.pp[i] == sa.full_model_te(red, TORQUE, theta)
