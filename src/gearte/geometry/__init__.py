"""Pure geometry of gears and cycloid discs (profiles, clearances, equivalent gears). Units: mm, rad."""
