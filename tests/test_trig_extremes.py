"""The exact-extremes solver (gearte.solvers.trig_extremes) on its own: the vectorised sine /
cosine against numpy, and the extremes independent of the order of the harmonics."""

import numpy as np
import pytest

from gearte.errors import ParameterError
from gearte.solvers.trig_extremes import (
    SINCOS_MAX_ARG,
    exact_extremes,
    exact_extremes_numpy,
    sincos,
)


def test_sincos_matches_numpy_to_a_few_ulp():
    rng = np.random.default_rng(5)
    quad = np.arange(-8, 9) * (np.pi / 4)  # quadrant boundaries, where the reduction switches
    x = np.concatenate(
        [
            rng.uniform(0, 2 * np.pi, 200_000),  # the Monte-Carlo's assembly angles
            rng.uniform(-60, 60, 100_000),
            quad,
            np.nextafter(quad, np.inf),
            np.nextafter(quad, -np.inf),
            [0.0, -0.0, 1e-300, SINCOS_MAX_ARG, -SINCOS_MAX_ARG, 12345.678],
        ]
    )
    s, c = sincos(x)
    assert np.abs(s - np.sin(x)).max() <= 2.3e-16
    assert np.abs(c - np.cos(x)).max() <= 2.3e-16
    s2, c2 = sincos(x[:20].reshape(10, 2))  # shape kept
    assert s2.shape == (10, 2) and np.array_equal(s2.ravel(), s[:20])


def test_sincos_refuses_arguments_beyond_its_reduction():
    with pytest.raises(ParameterError, match="x"):
        sincos(np.array([0.0, 2e5]))


def test_extremes_do_not_depend_on_the_order_of_the_harmonics():
    rng = np.random.default_rng(9)
    n = 300
    c = rng.normal(size=n)
    Z = rng.normal(size=(n, 3)) + 1j * rng.normal(size=(n, 3))
    fx, fn = exact_extremes(c, Z, (3, 11, 21))
    perm = [2, 0, 1]
    gx, gn = exact_extremes(c, Z[:, perm], (21, 3, 11))
    np.testing.assert_allclose(gx, fx, rtol=0, atol=1e-13 * np.abs(Z).sum(1).max())
    np.testing.assert_allclose(gn, fn, rtol=0, atol=1e-13 * np.abs(Z).sum(1).max())
    tx, tn = exact_extremes_numpy(c, Z, (3, 11, 21))
    assert np.all(np.abs(fx - tx) <= 1e-11 * (np.abs(Z).sum(1) + np.abs(c)))
    assert np.all(np.abs(fn - tn) <= 1e-11 * (np.abs(Z).sum(1) + np.abs(c)))


def test_single_high_harmonic_hits_the_edge_of_the_rotation_domain():
    """One harmonic: every node offset is up to n_max h = pi/4, the edge of the polynomial
    kernels' domain; the maximum is |Z| exactly wherever the phase puts it."""
    phases = np.linspace(0, 2 * np.pi, 97)
    Z = (2.5 * np.exp(1j * phases))[:, None]
    fx, fn = exact_extremes(np.zeros(97), Z, (40,))
    np.testing.assert_allclose(fx, 2.5, rtol=1e-14)
    np.testing.assert_allclose(fn, -2.5, rtol=1e-14)
