"""Order spectrum of a transmission-error trace and the physical source of each line.

An *order* is a harmonic of one output revolution: a TE component at order ``n`` repeats ``n``
times per output revolution. The characteristic orders of an RV reducer (involute first stage
``z1``/``z2`` with ``M`` planets on cranks, cycloid discs of ``z_c = z_p − 1`` lobes in ``z_p``
fixed pins, output = carrier) follow from its tooth numbers alone
(:func:`rv_characteristic_orders`); the same numbers times the output speed are the
characteristic frequencies of the dynamics model (Li et al. 2023, paper 004), so
:func:`label_frequency` labels a frequency line and an order line alike.

References
----------
Li, X., et al. (2023). Dynamic transmission error of RV reducers with manufacturing errors
(gearte's paper 004; see docs/validation/li2023.md).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError

__all__ = [
    "label_frequency",
    "rv_characteristic_orders",
    "order_spectrum",
    "labelled_orders",
    "mean_standard_error",
    "rv_tooth_orders",
    "label_order",
    "unexplained_lines",
]


def label_frequency(f: float, sources: dict[str, float], tol: float) -> str:
    """Physical source of a spectral line at f [Hz]: a harmonic of a source or a mesh sideband.

    Tries h × source first (h = 1..8 for meshes, whose rectangular stiffness wave is rich in
    harmonics, 1..4 for rotations), then mesh ± k × rotation sidebands (k = 1..3); returns
    ``"unidentified"`` when nothing lies within ``tol`` [Hz]. ``f``, ``sources`` and ``tol`` may
    equally be orders (per output revolution).

    Parameters
    ----------
    f : float
        Frequency of the line [Hz] (or order [-]).
    sources : dict
        Source name → its fundamental frequency [Hz] (or order [-]); names containing "mesh" or
        "rotation" take part in sidebands.
    tol : float
        Largest distance accepted [Hz] (or [-]).

    Returns
    -------
    str
        The label, e.g. ``"2× cycloid mesh"``, a sideband, or ``"unidentified"``.
    """
    best, err = "unidentified", tol
    for name, fs in sources.items():
        for h in range(1, 9 if "mesh" in name else 5):
            d = abs(f - h * fs)
            if d <= err:
                best, err = (name if h == 1 else f"{h}× {name}"), d
    if best != "unidentified":
        return best
    meshes = {k: v for k, v in sources.items() if "mesh" in k}
    rots = {k: v for k, v in sources.items() if "rotation" in k}
    for mn, fm in meshes.items():
        for h in (1, 2):
            for rn, fr in rots.items():
                for k in (1, 2, 3):
                    for sgn in (+1, -1):
                        d = abs(f - (h * fm + sgn * k * fr))
                        if d <= err:
                            sb = f"{'' if h == 1 else f'{h}× '}{mn} {'+' if sgn > 0 else '−'} "
                            best, err = sb + f"{'' if k == 1 else f'{k}× '}{rn} (sideband)", d
    return best


def rv_characteristic_orders(sun_teeth: int, planet_teeth: int, pin_count: int) -> dict[str, float]:
    """Characteristic orders (per output revolution) of an RV reducer from its tooth numbers.

    Parameters
    ----------
    sun_teeth, planet_teeth : int
        ``z1``, ``z2`` of the involute first stage.
    pin_count : int
        ``z_p`` (the discs have ``z_c = z_p − 1`` lobes).

    Returns
    -------
    dict
        ``output rotation`` 1; ``input rotation`` the ratio ``i = 1 + z_p z2/z1``; ``crank
        rotation`` ``z_p`` (relative to the carrier); ``involute mesh`` ``z1 (i − 1) = z_p z2``;
        ``cycloid mesh`` ``z_p z_c``. The keys are those of the dynamics model's frequencies.

    Examples
    --------
    >>> rv_characteristic_orders(22, 60, 40)["crank rotation"]
    40.0
    """
    for name, v, lo in (("sun_teeth", sun_teeth, 6), ("planet_teeth", planet_teeth, 6),
                        ("pin_count", pin_count, 3)):  # fmt: skip
        if int(v) != v or v < lo:
            raise ParameterError(name, v, f"must be an integer >= {lo}")
    ratio = 1.0 + pin_count * planet_teeth / sun_teeth
    return {
        "output rotation": 1.0,
        "input rotation": ratio,
        "crank rotation": float(pin_count),
        "involute mesh": sun_teeth * (ratio - 1.0),
        "cycloid mesh": float(pin_count * (pin_count - 1)),
    }


def order_spectrum(
    position: ArrayLike, te: ArrayLike, n: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Amplitude and phase of each order of a TE trace over one output revolution.

    Parameters
    ----------
    position : (K,) output position [rad], monotone in either sense, covering one revolution
    te : (K,) transmission error [any angle unit]
    n : int, optional
        Points of the uniform grid the trace is resampled on (linear, periodic interpolation);
        default ``K`` (a trace sampled uniformly in position is then taken as it is).

    Returns
    -------
    orders : (n//2 + 1,) 0, 1, 2, ...
    amplitude : same unit as ``te``; the order-0 entry is the mean
    phase : [rad] with ``te(φ) ≈ mean + Σ amplitude_k cos(k φ + phase_k)``, ``φ`` the position

    Notes
    -----
    Orders are integers: components that are not periodic per output revolution (the input
    rotation when the ratio is not an integer) spread over the neighbouring orders.
    """
    pos = np.asarray(position, dtype=float)
    y = np.asarray(te, dtype=float)
    if pos.shape != y.shape or pos.ndim != 1 or pos.size < 8:
        raise ParameterError("te", y.shape, "needs >= 8 samples matching the positions")
    n = pos.size if n is None else int(n)
    phi0 = float(np.min(pos))
    grid = phi0 + 2 * np.pi * np.arange(n) / n
    if np.allclose(np.sort(pos), grid, rtol=0.0, atol=1e-12):
        yy = y[np.argsort(pos)]
    else:
        yy = np.interp(grid, pos, y, period=2 * np.pi)
    spec = np.fft.rfft(yy) / n
    orders = np.arange(spec.size)
    amp = 2.0 * np.abs(spec)
    amp[0] = spec[0].real
    if n % 2 == 0:
        amp[-1] = np.abs(spec[-1])
    phase = np.angle(spec) - orders * phi0
    phase = np.angle(np.exp(1j * phase))
    return orders, amp, phase


def labelled_orders(
    orders: np.ndarray,
    amplitude: np.ndarray,
    phase: np.ndarray,
    sources: dict[str, float],
    n_orders: int = 12,
    min_share: float = 1e-3,
) -> list[dict]:
    """The ``n_orders`` largest orders (≥ ``min_share`` of the largest), each with its source.

    Returns a list of ``{"order", "amplitude", "phase", "source"}`` (amplitude in the spectrum's
    unit, phase [rad]), largest first; sources by :func:`label_order`.
    """
    amp = np.asarray(amplitude)[1:]
    if amp.size == 0 or amp.max() <= 0:
        return []
    idx = np.argsort(amp)[::-1][:n_orders]
    idx = idx[amp[idx] >= min_share * amp.max()] + 1
    return [
        {
            "order": int(orders[i]),
            "amplitude": float(amplitude[i]),
            "phase": float(phase[i]),
            "source": label_order(int(orders[i]), sources),
        }
        for i in idx
    ]


def mean_standard_error(amplitude: ArrayLike) -> float:
    """Standard error of a trace's mean from the noise floor of its order spectrum.

    Parameters
    ----------
    amplitude : array_like
        Amplitudes of :func:`order_spectrum` (order 0 first, then 1, 2, ...) [any angle unit].

    Returns
    -------
    float
        ``σ/√N`` [unit of ``amplitude``]: ``σ`` of white noise on the ``N`` samples, from the
        median line amplitude (most orders carry noise only).

    Notes
    -----
    White noise of standard deviation ``σ`` on ``N`` samples gives line amplitudes ``2|X_k|/N``
    that are Rayleigh distributed with scale ``σ √(2/N)``, median ``σ √(2/N) √(2 ln 2)``; so
    ``σ/√N = median / (2 √(ln 2))``. Over one revolution the periodic content averages out of
    the mean exactly, so this is the mean's whole noise (not the repeatability between runs).
    """
    amp = np.asarray(amplitude, dtype=float)[1:]
    if amp.size < 8:
        raise ParameterError("amplitude", amp.size, "needs >= 8 orders")
    return float(np.median(amp) / (2.0 * np.sqrt(np.log(2.0))))


def rv_tooth_orders(sun_teeth: int, planet_teeth: int, pin_count: int) -> dict[str, float]:
    """Orders of every tooth number of an RV reducer: :func:`rv_characteristic_orders` plus the
    disc's lobe count ``z_c = z_p − 1`` (``cycloid lobes``).

    A lobe-to-lobe error of a disc (profile or pitch of its ``z_c`` lobes) repeats ``z_c`` times
    per output revolution; with ``z_p = 40`` pins: 39, its harmonics 78, 156, ... and, around
    the harmonics of the crank rotation, the sidebands 159 = 4·40 − 1, 318 = 8·40 − 2
    (:func:`label_order`).

    Parameters
    ----------
    sun_teeth, planet_teeth, pin_count : int
        ``z1``, ``z2``, ``z_p``.

    Returns
    -------
    dict
        Source name → its order per output revolution [-].

    Examples
    --------
    >>> rv_tooth_orders(22, 60, 40)["cycloid lobes"]
    39.0
    """
    out = rv_characteristic_orders(sun_teeth, planet_teeth, pin_count)
    out["cycloid lobes"] = float(pin_count - 1)
    return out


def label_order(order: int, sources: dict[str, float], tol: float = 0.5) -> str:
    """Physical source of a TE order: a harmonic of a source or a sideband around one.

    Tries, in this order, ``h × source`` (h = 1..8; 1..4 for sources below order 2, the output
    rotation), then ``h × source ± k × rotation`` (k = 1..3, rotations: the sources named
    "... rotation" with an integer order, the output rotation first, around the harmonics of the
    other sources of order ≥ 2), the smallest ``k`` (then ``h``) first. Within ``tol`` orders.

    Parameters
    ----------
    order : int
        The order [-].
    sources : dict
        Source name → its order [-] (e.g. :func:`rv_tooth_orders`).
    tol : float
        Largest distance accepted [-].

    Returns
    -------
    str
        E.g. ``"4× cycloid lobes"``, ``"4× crank rotation − output rotation (sideband)"``, or
        ``"unidentified"``.

    Examples
    --------
    >>> src = rv_tooth_orders(22, 60, 40)
    >>> [label_order(n, src) for n in (39, 78, 156, 159, 318)]  # doctest: +NORMALIZE_WHITESPACE
    ['cycloid lobes', '2× cycloid lobes', '4× cycloid lobes',
     '4× crank rotation − output rotation (sideband)',
     '8× crank rotation − 2× output rotation (sideband)']
    """
    x = float(order)
    for h in range(1, 9):
        for name, f in sources.items():
            if f < 2 and h > 4:  # low orders (the output rotation): harmonics 1..4 only
                continue
            if abs(x - h * f) <= tol:
                return name if h == 1 else f"{h}× {name}"
    rots = [(n, f) for n, f in sources.items() if "rotation" in n and abs(f - round(f)) < 1e-9]
    rots.sort(key=lambda nf: nf[1])
    for k in (1, 2, 3):
        for rn, fr in rots:
            for h in range(1, 9):
                for name, f in sources.items():
                    if name == rn or f < 2:  # no sidebands of a low order around itself
                        continue
                    for sgn in (-1, +1):
                        if abs(x - (h * f + sgn * k * fr)) <= tol and h * f + sgn * k * fr > 0:
                            base = name if h == 1 else f"{h}× {name}"
                            side = rn if k == 1 else f"{k}× {rn}"
                            return f"{base} {'+' if sgn > 0 else '−'} {side} (sideband)"
    return "unidentified"


def unexplained_lines(
    lines: list[dict], peak_to_peak: float, noise: float, *, fraction: float = 0.05
) -> list[dict]:
    """Lines of a labelled spectrum that no source explains and that matter for the trace.

    Parameters
    ----------
    lines : list of dict
        :func:`labelled_orders` output (``amplitude`` in the trace's unit).
    peak_to_peak : float
        Peak-to-peak of the trace [same unit].
    noise : float
        Noise floor of a line's amplitude, e.g. the median amplitude of the spectrum [same unit].
    fraction : float
        A line counts when its amplitude is at least this share of the peak-to-peak [-] and at
        least 4 × the noise floor.

    Returns
    -------
    list of dict
        The unexplained lines, largest first.
    """
    limit = max(fraction * peak_to_peak, 4.0 * noise)
    return [x for x in lines if x["source"] == "unidentified" and x["amplitude"] >= limit]
