"""Pure geometry of gears and cycloid discs (profiles, clearances, equivalents); mm, rad."""
