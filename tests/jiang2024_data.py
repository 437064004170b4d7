"""The data of Jiang et al. (2024) as gearte objects, shared by the test_jiang2024_* files.

Tables 1-2 (spur pair) and 5-6 (bevel pair) converted to mm; Tables 4 and 8 (3DCS rows).
"""

from __future__ import annotations

import math

from gearte.models.backlash import BevelGear, BevelPair, SpurGear, SpurPair

UM = 1e-3
ALPHA = math.radians(20.0)

# Table 4 / Table 8, 3DCS simulation rows: (min, mean, max) normal backlash [µm]
SPUR_3DCS_UM = (34.0, 54.0, 75.0)
BEVEL_3DCS_UM = (72.0, 90.0, 108.0)
# Table 4 / Table 8, theory rows
SPUR_THEORY_UM = (32.0, 53.0, 74.0)
BEVEL_THEORY_UM = (70.0, 90.0, 110.0)
SPUR_D_MM = 275.0  # driven gear pitch diameter (Table 1)
BEVEL_DM_MM = 102.1  # driven gear mean diameter (Table 5)


def spur_pair() -> SpurPair:
    """Tables 1-2."""
    return SpurPair(
        SpurGear(28, -19 * UM, -30 * UM, 27 * UM),
        SpurGear(110, -21 * UM, -32 * UM, 31 * UM),
        module=2.5,
        pressure_angle=ALPHA,
        centre_distance_tol=20 * UM,
        bearing_clearance=(2 * UM, 30 * UM),
        runout=8 * UM,
        min_backlash_limit=15 * UM,
    )


def bevel_pair() -> BevelPair:
    """Tables 5-6 (the printed values apply to both gears)."""
    g = BevelGear(31, -32 * UM, -53 * UM, (10 * UM, 30 * UM), 12 * UM, 12 * UM)
    return BevelPair(
        g,
        g,
        module=3.5,
        pressure_angle=ALPHA,
        face_width=9.0,
        shaft_distance_tol=9 * UM,
        shaft_angle_tol=10 * UM,
        composite_tol=20 * UM,
        min_backlash_limit=19 * UM,
    )
