"""Hu et al. 2020 (paper 000) as whole reducers: total (geometric + elastic) TE of the initial
(Table 3) and modified (Table 6) prototypes, catalogue quantities and compensation.

The paper reports the total TE 1.4559' -> 0.8538' (Adams, -41.35 %) and 1.552' -> 0.819' on the
test bench (-47.22 %). Its Adams model has flexible cycloid discs and rigid everything else; the
bearings of a real reducer add compliance common to both prototypes. gearte evaluates both
settings; see docs/validation/hu2020-total-te.md.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gearte.geometry.cycloid import closing_rotation
from gearte.geometry.rv import Cranks, Supports
from gearte.io.case_file import load_case
from gearte.models.rv_catalogue import catalogue_values, torsion_test
from gearte.models.rv_compensation import compensate
from gearte.models.rv_load_sharing import output_positions, transmission_error
from gearte.studies.rv_reducer import build_reducer
from gearte.units import Nm_to_Nmm, Nmm_per_rad_to_Nm_per_arcmin, arcmin_to_rad, rad_to_arcmin

HU2020 = {"te_initial [arcmin]": 1.4559, "te_modified [arcmin]": 0.8538, "sim [%]": 41.35,
          "test [%]": 47.22, "pins_initial": 9, "pins_modified": 17}  # fmt: skip
TORQUE = Nm_to_Nmm(1141.0)  # loads each disc with the paper's T_c (examples' comments)


@pytest.fixture(scope="module")
def prototypes():
    return (
        build_reducer(load_case("hu2020_rv80e_initial_reducer").reducer),
        build_reducer(load_case("hu2020_rv80e_modified_reducer").reducer),
    )


def _rigid_supports(red, factor=1e4):
    """Bearings, mesh and supports ``factor`` times stiffer, no pin seat, crank bending or
    torsion: only the cycloid contacts compliant (the paper's Adams setting)."""
    fs, cr = red.first_stage, red.cranks
    return red.replace(
        pins=dataclasses.replace(red.pins, seat_compliance=None, bending_compliance=None),
        first_stage=dataclasses.replace(
            fs,
            mesh_stiffness=fs.mesh_stiffness * factor,
            sun_support_stiffness=fs.sun_support_stiffness * factor,
        ),
        cranks=Cranks(cr.count, cr.circle_radius, cr.eccentricity,
                      cr.cam_bearing_stiffness * factor, cr.carrier_bearing_stiffness * factor),
        supports=Supports(red.supports.carrier_radial_stiffness * factor),
    )  # fmt: skip


@pytest.fixture(scope="module")
def te(prototypes):
    th = output_positions(120)
    out = {}
    for tag, make in (("real", lambda r: r), ("rigid", _rigid_supports)):
        out[tag] = [transmission_error(make(r), TORQUE, th) for r in prototypes]
    return out


def _reduction(a, b):
    return 100.0 * (1.0 - b / a)


def test_hu2020_modified_prototype_has_lower_total_te(te):
    """Reduction of the mean loaded lag, initial → modified prototype, at T_c of the examples.

    Paper: -41.35 % (Adams: flexible discs, everything else rigid), -47.22 % (test bench).
    gearte, bearing-compliant reducer with the bundled case's stiffness chain (pin seats, crank
    bending and torsion, bearings linearised at rated torque; -22.06 % without them): -19.75 %
    (documented deviation: the compliance of bearings and shafts, common to both prototypes,
    dilutes the gain); supports
    and first stage stiffened 1e4×, no seats or shaft compliance (the paper's Adams setting):
    0.8881' → 0.2062', -76.78 % (documented deviation: gearte's rigid setting also stiffens
    the crank bearings the Adams model keeps flexible through the discs). The paper's two
    numbers lie between gearte's two settings.

    The contact rows take each pin's normal and arm at the true contact point of the shifted
    profile (docs/contact-law.md, "Modified profiles"), no longer through the pitch point
    (eq 36); that moved these numbers from -19.76 % and 0.8921' → 0.2077', -76.71 % (+0.07
    points in the rigid setting, -0.01 in the compliant one). Nothing was fitted.
    Tolerance 0.05 points: the 120-position load-sharing solution is converged far below that.
    """
    rows = {}
    for tag, (ini, mod) in te.items():
        lag = [rad_to_arcmin(-t.total.mean()) for t in (ini, mod)]
        pp = [rad_to_arcmin(t.total_pp) for t in (ini, mod)]
        rows[tag] = (lag, pp)
        print(
            f"{tag}: mean loaded lag {lag[0]:.3f}' -> {lag[1]:.3f}' "
            f'({_reduction(*lag):.1f} %), TE p-p {pp[0] * 60:.4f}" -> {pp[1] * 60:.4f}" '
            f"({_reduction(*pp):.1f} %); paper {HU2020['sim [%]']} % sim, "
            f"{HU2020['test [%]']} % test"
        )
        assert lag[1] < lag[0]
        assert pp[1] < pp[0]  # mesh ripple over the revolution (no errors)
    # the paper's reductions lie between the bearing-compliant reducer (common compliance
    # dilutes the gain) and the paper's own setting (only the cycloid contacts compliant)
    low = _reduction(*rows["real"][0])
    high = _reduction(*rows["rigid"][0])
    assert low == pytest.approx(19.75, abs=0.05)
    assert high == pytest.approx(76.78, abs=0.05)
    assert low < HU2020["sim [%]"] < high
    assert low < HU2020["test [%]"] < high


def test_hu2020_geometric_and_elastic_parts_add_up(te):
    for ini, mod in te.values():
        for t in (ini, mod):
            np.testing.assert_allclose(t.geometric + t.elastic, t.total, atol=1e-15)
    # initial prototype: geometric lag = one flank of the backlash, kinematic check below
    ini = te["rigid"][0]
    assert rad_to_arcmin(-ini.geometric.mean()) == pytest.approx(0.2737, rel=0.03)


def test_hu2020_pins_in_mesh_initial_vs_modified(te):
    ini, mod = (t.loaded for t in te["real"])
    print(
        f"pairs in mesh {ini.pairs_in_mesh.min()}-{ini.pairs_in_mesh.max()} -> "
        f"{mod.pairs_in_mesh.min()}-{mod.pairs_in_mesh.max()} (paper 9 -> 17); peak "
        f"{ini.peak_pin_load:.0f} -> {mod.peak_pin_load:.0f} N (paper 1910.3 -> 1435.9 N)"
    )
    assert abs(int(ini.pairs_in_mesh.max()) - HU2020["pins_initial"]) <= 1
    assert mod.pairs_in_mesh.min() >= ini.pairs_in_mesh.max() + 5
    assert mod.peak_pin_load < ini.peak_pin_load


def test_hu2020_backlash_equals_kinematic_closing_rotation(prototypes):
    """Backlash at the output = 2 β0 z_c / (z_p + z1/z2) with β0 the disc's closing rotation.

    With the input locked an output rotation Δθ moves the pitch point by a (z_p + z1/z2) Δθ,
    a disc rotation β about its centre by a z_c β: same normal approach at every pin.
    """
    ini = _rigid_supports(prototypes[0])
    beta0 = closing_rotation(z_p=40, r_p=76.0, a=1.5, dr_rp=-0.022, dr_p=-0.0437)
    expected = 2 * beta0 * 39 / (40 + 22 / 60)
    cat = catalogue_values(ini)
    assert cat.backlash == pytest.approx(expected, rel=0.02)
    # modified prototype: negative closing rotation, preloaded, no backlash
    assert catalogue_values(prototypes[1]).backlash < arcmin_to_rad(1e-3)


def test_hu2020_hysteresis_curve_monotonic_with_backlash_jump(prototypes):
    red = prototypes[0]
    curve = torsion_test(red, (0.0, 1.0, -1.0, 1.0), steps_per_segment=10)
    T, ang = curve.torque, curve.angle
    seg = np.sign(np.diff(T))
    dang = np.diff(ang)
    assert np.all(dang[seg != 0] * seg[seg != 0] >= -1e-12)
    cat = catalogue_values(red)
    assert rad_to_arcmin(cat.lost_motion) > rad_to_arcmin(cat.backlash) > 0.5
    # gearte's own catalogue value (the paper prints no rigidity; 423.24 before the case had
    # the stiffness chain's pin seats, crank bending/torsion, main-bearing data and bearings
    # linearised at rated torque,
    # docs/validation/hu2020-total-te.md); 0.1 % tolerance of the finite-difference slope
    # between the rated-torque points; 350.08 before the contact rows took the normals and arms
    # at the true contact point of the shifted profile (+0.08 %, docs/contact-law.md)
    assert Nmm_per_rad_to_Nm_per_arcmin(cat.torsional_rigidity) == pytest.approx(350.37, rel=1e-3)


def test_hu2020_compensation_lowers_lag_keeping_backlash(prototypes):
    red = prototypes[0]
    comp = compensate(
        red, TORQUE, {"shift_modification": (0.0, 0.025)},
        min_backlash=arcmin_to_rad(0.1), objective="mean_lag", positions=24,
    )  # fmt: skip
    assert comp.after.backlash >= arcmin_to_rad(0.1) * (1 - 1e-9)
    assert comp.after.mean_lag < comp.before.mean_lag
    assert comp.after.pairs_in_mesh_min >= comp.before.pairs_in_mesh_min
    # the shift change reduces the backlash to the admissible minimum (within the search step)
    assert rad_to_arcmin(comp.after.backlash) == pytest.approx(0.1, abs=0.03)
