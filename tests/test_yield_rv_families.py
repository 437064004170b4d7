"""Every disc and pin error family of the RV tolerance set (issue 14 item 1: the same keys as the
measured errors) is drawn in the RV yield Monte-Carlo: a tolerance on it changes the sampled
outputs, and a zero tolerance reproduces the deterministic reducer with that error at zero."""

from __future__ import annotations

import pytest

import gearte
from gearte.runners.yield_models import RVReducerYield, rv_error_keys
from gearte.studies.rv_reducer import build_reducer
from gearte.tolerance.yield_mc import Tolerance, ToleranceSet, run_yield

#: family → (law, drawn with a uniform direction)
FAMILIES = {
    "disc_radial_runout": ("rayleigh", True),
    "disc_cumulative_pitch": ("rayleigh", True),
    "discs.equidistant_modification_errors": ("normal", False),
    "discs.shift_modification_errors": ("normal", False),
    "pins.radius_errors": ("normal", False),
    "pins.radial_position_errors": ("normal", False),
    "pins.tangential_position_errors": ("normal", False),
}
QUANTITIES = ("lost_motion [arcmin]", "angular_te [arcmin]", "loaded_te [arcmin]")


@pytest.fixture(scope="module")
def rv():
    """hu2020_rv80e_modified_reducer (modified profile: the pins have clearance, so small
    errors move every output smoothly), TE at 12 output positions."""
    red = build_reducer(gearte.load_case("hu2020_rv80e_modified_reducer").reducer)
    return red, RVReducerYield(red, positions=12)


def _set(keys, family: str, tol: float) -> ToleranceSet:
    kind, phase = FAMILIES[family]
    return ToleranceSet(
        tuple(Tolerance(k, kind, tol, phase=phase, family=family) for k in keys[family])
    )


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_rv_yield_each_disc_and_pin_family_changes_the_samples_and_zero_is_deterministic(
    rv, family
):
    """10 µm on every instance of the family: the three samples differ from the reducer with
    that family at zero (by more than 1e-6′ in at least one of lost motion, unloaded and loaded
    TE) and from each other; 0 µm: every sample equals that reducer solved on its own
    (per-sample path, ``batched=False``) to 1e-9 relative."""
    red, model = rv
    keys = rv_error_keys(red)
    assert keys[family], family
    zero = run_yield(model, _set(keys, family, 0.0), [], 3, seed=1, chunk_size=3)
    drawn = run_yield(model, _set(keys, family, 10.0), [], 3, seed=1, chunk_size=3)
    ref = RVReducerYield(red, positions=12, batched=False).one(
        model.reducer_for({k: 0.0 for k in keys[family]})
    )
    moved = []
    for q in QUANTITIES:
        st0 = zero.quantities[q].stats
        assert st0.min == st0.max, q
        assert st0.min == pytest.approx(ref[q], rel=1e-9, abs=1e-12), q
        st = drawn.quantities[q].stats
        moved.append(max(abs(st.max - st0.min), abs(st.min - st0.min)) > 1e-6 and st.sd > 0)
    assert any(moved), (family, [drawn.quantities[q].stats for q in QUANTITIES])
