"""Comparing two RVReducers field by field (the rv_reducer family's sections round trip)."""

from __future__ import annotations

import dataclasses

import numpy as np


def _fields(x, path="reducer"):
    """``(path, value)`` of every leaf of a (nested) dataclass: arrays, numbers, strings."""
    if dataclasses.is_dataclass(x):
        for f in dataclasses.fields(x):
            if not f.name.startswith("_"):
                yield from _fields(getattr(x, f.name), f"{path}.{f.name}")
    elif isinstance(x, tuple):
        for i, y in enumerate(x):
            yield from _fields(y, f"{path}[{i}]")
    else:
        yield path, x


def assert_same_reducer(got, want):
    """Every field and array of two RVReducers equal, to the round-off of the unit conversions
    (µm ↔ mm, deg ↔ rad, vector ↔ length and direction, stiffness ↔ compliance: 1e-12)."""
    a, b = dict(_fields(want)), dict(_fields(got))
    assert a.keys() == b.keys()
    for key, x in a.items():
        y = b[key]
        if x is None or isinstance(x, str | bool):
            assert y == x, key
            continue
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        assert y.shape == x.shape, key
        np.testing.assert_allclose(y, x, rtol=1e-12, atol=1e-15, err_msg=key)
