r"""Quiet-standing posturography: the standard sway measures of a centre-of-pressure trace.

Input: a CoP time series ``cop`` (n, 2) [m], columns (ap, ml) in body axes (ap forward +, ml
to the subject's left +, :mod:`~pushrecovery.analysis.recording`), at a constant ``rate``
[Hz]. Missing frames are NaN in this project: the measures refuse them (analyse a window
without gaps). AP, ML are the CoP minus its mean, RD = √(AP² + ML²) the resultant distance.
Definitions: Prieto et al. 1996 (IEEE Trans Biomed Eng 43(9):956-966) for the distances,
velocities, frequencies and spectra; Schubert & Kirchner 2014 (Gait & Posture 39(1):518-522)
for the prediction ellipse; practice after Duarte & Freitas 2010 (Rev Bras Fisioter
14(3):183-192). docs/posturography.md has the equations, the PSD choices, a worked example
and why no PyPI library is used.

Over 400 lines on purpose: one measure per function (the Prieto 1996 set, the ellipse and
the spectrum) and the quiet-standing check they all rely on.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import detrend, welch

from pushrecovery.analysis.recording import LOADED
from pushrecovery.arguments import bounded_float, float_array, positive_float
from pushrecovery.errors import InvalidParameterError

__all__ = [
    "BAND", "SEGMENT", "Components", "Ellipse", "Spectrum", "SwayMeasures", "mean_distance",
    "mean_frequency", "mean_velocity", "path_length", "prediction_ellipse", "quiet_standing",
    "rms_distance", "sway_measures", "sway_spectrum",
]  # fmt: skip

#: Spectral band [Hz]: Prieto et al. (1996) analyse 0.15-5 Hz.
BAND: tuple[float, float] = (0.15, 5.0)
#: Welch segment [s] (0.05 Hz resolution); the whole trial when it is shorter.
SEGMENT = 20.0
#: Lag of the CoP speed in :func:`quiet_standing` [s]: long enough to average sample noise.
SPEED_LAG = 0.1
GRAVITY = 9.81  #: [m/s²], for the mass a vertical force implies


class Components(NamedTuple):
    """One measure of the resultant (``total``) and along each body axis, in its unit."""

    total: float
    ap: float
    ml: float


@dataclass(frozen=True, slots=True)
class Ellipse:
    """``area`` [m²], semi-axes [m], major axis from +ap towards +ml in (−π/2, π/2] [rad]."""

    area: float
    semi_major: float
    semi_minor: float
    angle: float


@dataclass(frozen=True, slots=True)
class Spectrum:
    """Prieto's frequency measures of one series in a band, NaN frequencies without power.

    ``total_power`` μ₀ [m²]; ``f50``, ``f95`` the lowest PSD frequencies below which 50 %
    (95 %) of the band power lies [Hz]; ``centroidal_frequency`` √(μ₂/μ₀) [Hz];
    ``frequency_dispersion`` √(1 − μ₁²/(μ₀ μ₂)) [-] (0: a pure tone; 0.5: flat from 0 Hz).
    """

    total_power: float
    f50: float
    f95: float
    centroidal_frequency: float
    frequency_dispersion: float


@dataclass(frozen=True, slots=True)
class SwayMeasures:
    """The sway measures of one quiet-standing trial (definitions: module docstring).

    Attributes: ``duration`` T = (n − 1) / rate [s]; Components (resultant, ap, ml)
    ``path_length`` TOTEX [m], ``mean_velocity`` MVELO [m/s], ``mean_distance`` MDIST [m],
    ``rms_distance`` RDIST [m], ``mean_frequency`` MFREQ [Hz] (NaN for a still CoP);
    ``range_ap``, ``range_ml`` peak to peak [m]; ``ellipse`` the 95 % prediction ellipse;
    ``spectrum_rd``, ``spectrum_ap``, ``spectrum_ml`` the spectra of RD, AP, ML in ``band``
    [Hz].
    """

    duration: float
    path_length: Components
    mean_velocity: Components
    mean_distance: Components
    rms_distance: Components
    range_ap: float
    range_ml: float
    ellipse: Ellipse
    mean_frequency: Components
    spectrum_rd: Spectrum
    spectrum_ap: Spectrum
    spectrum_ml: Spectrum
    band: tuple[float, float]

    def to_dict(self) -> dict[str, float]:
        """Flat {name: value} for a table row, in the attributes' SI units.

        Components give ``name`` (resultant), ``name_ap``, ``name_ml``; the ellipse
        ``ellipse_area``...; the spectra ``rd_f50``, ``ap_f50``...; ``band_low``, ``band_high``.
        """
        row: dict[str, float] = {}
        for item in fields(self):
            name, value = item.name, getattr(self, item.name)
            if isinstance(value, Components):
                row.update({name: value.total, f"{name}_ap": value.ap, f"{name}_ml": value.ml})
            elif isinstance(value, Ellipse | Spectrum):
                prefix = name.removeprefix("spectrum_")
                row.update({f"{prefix}_{k}": float(v) for k, v in asdict(value).items()})
            elif name == "band":
                row["band_low"], row["band_high"] = value
            else:
                row[name] = float(value)
        return row


def _cop(cop: ArrayLike) -> NDArray[np.float64]:
    """Check a CoP trace: (n, 2), n >= 3, finite (a NaN frame is refused as a gap)."""
    array = float_array("cop", cop)
    if array.ndim != 2 or array.shape[1] != 2 or array.shape[0] < 3:
        raise InvalidParameterError(
            f"cop must be an array of shape (n, 2) (ap, ml) [m] with n >= 3, got {array.shape}"
        )
    missing = int(np.isnan(array).any(axis=1).sum())
    if missing:
        raise InvalidParameterError(
            f"cop must have no missing (NaN) frame, got {missing}: analyse a window without gaps"
        )
    if np.isinf(array).any():
        raise InvalidParameterError("cop must be finite, got infinite values")
    return array


def path_length(cop: ArrayLike) -> Components:
    r"""Length of the CoP path, TOTEX (Prieto et al. 1996) [m].

    .. math:: \mathrm{TOTEX} = \sum_k \sqrt{\Delta AP_k^2 + \Delta ML_k^2},\quad
              \mathrm{TOTEX}_{AP} = \sum_k |\Delta AP_k|

    ``cop``: (n, 2) (ap, ml) [m], n >= 3, no NaN. Returns (total, ap, ml) [m].

    Raises
    ------
    InvalidParameterError
        ``cop`` not (n, 2) with n >= 3, or with NaN or infinite values.
    """
    step = np.diff(_cop(cop), axis=0)
    along = np.abs(step).sum(axis=0)
    return Components(float(np.hypot(step[:, 0], step[:, 1]).sum()), *map(float, along))


def mean_velocity(cop: ArrayLike, rate: float) -> Components:
    """Mean CoP speed, MVELO = TOTEX / T, T = (n − 1) / rate (Prieto et al. 1996) [m/s].

    T spans the n − 1 steps (Prieto: the trial duration): a CoP at constant speed v gives v.
    ``cop`` as in :func:`path_length`, ``rate`` [Hz] > 0 (else InvalidParameterError).
    Returns (total, ap, ml) [m/s].
    """
    rate = positive_float("rate", rate, "Hz")
    array = _cop(cop)
    duration = (len(array) - 1) / rate
    return Components(*(value / duration for value in path_length(array)))


def mean_distance(cop: ArrayLike) -> Components:
    r"""Mean distance from the mean CoP, MDIST (Prieto et al. 1996) [m].

    .. math:: \mathrm{MDIST} = \tfrac{1}{n}\sum_k RD_k,\quad
              \mathrm{MDIST}_{AP} = \tfrac{1}{n}\sum_k |AP_k|

    ``cop`` and the errors as in :func:`path_length`; returns (total, ap, ml) [m].
    """
    centred = (array := _cop(cop)) - array.mean(axis=0)
    along = np.abs(centred).mean(axis=0)
    return Components(float(np.hypot(centred[:, 0], centred[:, 1]).mean()), *map(float, along))


def rms_distance(cop: ArrayLike) -> Components:
    r"""RMS distance from the mean CoP, RDIST (Prieto et al. 1996) [m].

    .. math:: \mathrm{RDIST} = \sqrt{\tfrac{1}{n}\sum_k RD_k^2},\quad
              \mathrm{RDIST}_{AP} = \sqrt{\tfrac{1}{n}\sum_k AP_k^2}

    (per axis the standard deviation with divisor n). ``cop`` and the errors as in
    :func:`path_length`; returns (total, ap, ml) [m].
    """
    square = _cop(cop).var(axis=0)
    return Components(float(np.sqrt(square.sum())), *map(float, np.sqrt(square)))


def mean_frequency(cop: ArrayLike, rate: float) -> Components:
    r"""Mean frequency, MFREQ (Prieto et al. 1996) [Hz]; NaN where MDIST is 0.

    .. math:: \mathrm{MFREQ} = \frac{\mathrm{MVELO}}{2\pi\,\mathrm{MDIST}},\quad
              \mathrm{MFREQ}_{AP} = \frac{\mathrm{MVELO}_{AP}}{4\sqrt{2}\,\mathrm{MDIST}_{AP}}

    The resultant is the turn rate of a circle of radius MDIST run at MVELO; per axis, Prieto's
    sinusoid form (a sine of frequency f gives π f / (2√2) ≈ 1.11 f, a triangle wave √2 f).
    Arguments and errors as :func:`mean_velocity`; returns (total, ap, ml) [Hz], NaN for a
    component without sway (a mean distance of 0: the frequency is undefined, as the ml of a
    recording along ap only).
    """
    velocity, distance = mean_velocity(cop, rate), mean_distance(cop)
    scale = (2.0 * math.pi, 4.0 * math.sqrt(2.0), 4.0 * math.sqrt(2.0))
    pairs = zip(velocity, distance, scale, strict=True)
    return Components(*(v / (k * d) if d > 0.0 else math.nan for v, d, k in pairs))


def prediction_ellipse(cop: ArrayLike, probability: float = 0.95) -> Ellipse:
    r"""Prediction ellipse of the CoP (Schubert & Kirchner 2014, Gait & Posture 39:518-522).

    With λ₁ ≥ λ₂ the eigenvalues of the sample covariance (divisor n − 1) of (ap, ml) and
    χ²_p(2) = −2 ln(1 − p) the chi-square quantile of 2 degrees of freedom (5.991 at 0.95):

    .. math:: A = \pi\,\chi^2_p(2)\sqrt{\lambda_1\lambda_2},\quad
              a = \sqrt{\chi^2_p(2)\,\lambda_1},\quad b = \sqrt{\chi^2_p(2)\,\lambda_2}

    It holds a fraction p of the samples (unlike the confidence ellipse of the mean).

    Parameters
    ----------
    cop : array_like, shape (n, 2)
        CoP (ap, ml) [m], n >= 3, no NaN.
    probability : float
        Fraction of the samples the ellipse is to hold, in [0.5, 0.999].

    Raises
    ------
    InvalidParameterError
        A bad ``cop`` (:func:`path_length`) or ``probability``.
    """
    probability = bounded_float("probability", probability, 0.5, 0.999)
    (s_aa, s_am), (_, s_mm) = np.cov(_cop(cop), rowvar=False, ddof=1)
    half, spread = 0.5 * (s_aa + s_mm), math.hypot(0.5 * (s_aa - s_mm), s_am)
    major, minor = half + spread, max(half - spread, 0.0)
    chi2 = -2.0 * math.log1p(-probability)
    angle = 0.5 * math.atan2(2.0 * s_am, s_aa - s_mm)
    angle = angle if angle > -math.pi / 2 else math.pi / 2
    area = math.pi * chi2 * math.sqrt(major * minor)
    return Ellipse(area, math.sqrt(chi2 * major), math.sqrt(chi2 * minor), angle)


def _band(band: object, rate: float) -> tuple[float, float]:
    """Check a band (low, high) [Hz]: 0 < low < high <= rate / 2."""
    try:
        if isinstance(band, np.ndarray) and band.dtype.kind == "c":
            raise TypeError  # float() would drop the imaginary parts with a warning
        low, high = (float(value) for value in band)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        shown = f"shape {band.shape}" if isinstance(band, np.ndarray) else repr(band)[:60]
        raise InvalidParameterError(f"band must be (low, high) [Hz], got {shown}") from None
    if not 0.0 < low < high <= rate / 2.0:  # NaN fails too
        raise InvalidParameterError(
            f"band must satisfy 0 < low < high <= rate / 2 = {rate / 2.0:g} Hz, got {band!r}"
        )
    return low, high


def _segment_samples(n: int, rate: float, low: float, segment: object) -> int:
    """Welch segment in samples: ``segment`` [s] or the trial, lasting at least 1 / low."""
    seconds = positive_float("segment", segment, "s")
    samples = n if seconds * rate >= n else round(seconds * rate)
    if samples < rate / low:
        raise InvalidParameterError(
            f"segment and the trial must last >= 1 / band low = {1.0 / low:g} s, got segment="
            f"{seconds:g} s, trial {n / rate:g} s: record longer or raise band low"
        )
    return samples


def sway_spectrum(
    series: ArrayLike, rate: float, *, band: tuple[float, float] = BAND, segment: float = SEGMENT
) -> Spectrum:
    r"""Prieto's (1996) frequency measures of one sway series (AP, ML or RD).

    The series is linearly detrended; its one-sided PSD G(f) is Welch's estimate
    (:func:`scipy.signal.welch`: Hann window, ``segment``-second segments or the whole series
    when shorter, 50 % overlap, each segment's mean removed, density scaling). Over the bins
    f_j in ``band`` (resolution Δf = rate / segment samples),

    .. math:: \mu_k = \sum_j f_j^k\,G(f_j)\,\Delta f,\quad
              \mathrm{CFREQ} = \sqrt{\mu_2/\mu_0},\quad
              \mathrm{FREQD} = \sqrt{1 - \mu_1^2/(\mu_0\mu_2)}

    and the 50 % (95 %) power frequency is the lowest f_j where the cumulative band power
    reaches 50 % (95 %) of μ₀. No power in the band gives μ₀ = 0 and NaN frequencies.

    Parameters
    ----------
    series : array_like, shape (n,)
        Sway [m], finite, at ``rate`` [Hz] (> 0).
    band : (float, float)
        (low, high) [Hz], 0 < low < high <= rate / 2; default 0.15-5 Hz (Prieto).
    segment : float
        Welch segment [s], > 0; it (or the series, if shorter) must last >= 1 / low, else
        InvalidParameterError (as for any bad argument).
    """
    rate = positive_float("rate", rate, "Hz")
    values = float_array("series", series)
    if values.ndim != 1 or not np.isfinite(values).all():
        finite = "" if values.ndim != 1 else " with non-finite values"
        raise InvalidParameterError(f"series must be finite, (n,) [m], got {values.shape}{finite}")
    low, high = _band(band, rate)
    samples = _segment_samples(len(values), rate, low, segment)
    frequency, density = welch(
        detrend(values, type="linear"), fs=rate, window="hann", nperseg=samples,
        noverlap=samples // 2, detrend="constant", scaling="density",
    )  # fmt: skip
    inside = (frequency >= low) & (frequency <= high)
    f, power = frequency[inside], density[inside] * (rate / samples)
    mu0, mu1, mu2 = (float(np.sum(f**k * power)) for k in range(3))
    if not mu0 > (1e-9 * float(np.max(np.abs(values)))) ** 2:  # rounding only (a circle's RD)
        return Spectrum(0.0, math.nan, math.nan, math.nan, math.nan)
    cumulative = np.cumsum(power) / mu0
    f50, f95 = (float(f[min(np.searchsorted(cumulative, p), len(f) - 1)]) for p in (0.5, 0.95))
    dispersion = math.sqrt(max(1.0 - mu1 * mu1 / (mu0 * mu2), 0.0))
    return Spectrum(mu0, f50, f95, math.sqrt(mu2 / mu0), dispersion)


def sway_measures(
    cop: ArrayLike, rate: float, *, band: tuple[float, float] = BAND, segment: float = SEGMENT
) -> SwayMeasures:
    """All the sway measures of one quiet-standing trial (definitions: module docstring).

    ``cop`` (n, 2) [m] (ap, ml), no NaN; ``rate`` [Hz] > 0; ``band`` [Hz] and ``segment``
    [s] as in :func:`sway_spectrum`. Raises :class:`InvalidParameterError` for a bad argument
    or a trial shorter than 1 / band low.
    """
    array = _cop(cop)
    rate = positive_float("rate", rate, "Hz")
    low, high = _band(band, rate)
    _segment_samples(len(array), rate, low, segment)  # a short trial fails before the work
    centred = array - array.mean(axis=0)
    series = (np.hypot(centred[:, 0], centred[:, 1]), centred[:, 0], centred[:, 1])
    rd, ap, ml = (sway_spectrum(s, rate, band=(low, high), segment=segment) for s in series)
    range_ap, range_ml = (float(v) for v in np.ptp(array, axis=0))
    return SwayMeasures(
        (len(array) - 1) / rate, path_length(array), mean_velocity(array, rate),
        mean_distance(array), rms_distance(array), range_ap, range_ml, prediction_ellipse(array),
        mean_frequency(array, rate), rd, ap, ml, (low, high),
    )  # fmt: skip


def quiet_standing(
    cop: ArrayLike, rate: float, *, force: ArrayLike | None = None, max_speed: float = 0.5,
    max_acceleration: float = 2.0, max_load_change: float = 0.25,
) -> bool:  # fmt: skip
    """Whether a window looks like quiet standing. A heuristic with chosen thresholds.

    True when every CoP frame is present (the plate stays loaded), the CoP speed over 0.1 s
    (:data:`SPEED_LAG`) stays <= ``max_speed`` (a step or a push moves it at ~1 m/s), and,
    with ``force``, F_z stays >= :data:`~.recording.LOADED` and within ``max_load_change``
    of its median (no step off, no jump) and the CoM acceleration ‖F_h‖ / m, m = median(F_z)
    / g, stays <= ``max_acceleration``. The defaults are not published values: they pass the
    biomdp Kistler quiet-standing trial (at most 0.32 m/s, 1.1 m/s², 11 %) and fail a step,
    a 1 m/s CoP ramp or an unloaded plate. One plate cannot tell that both feet are loaded.

    Parameters
    ----------
    cop : array_like, shape (n, 2)
        CoP (ap, ml) [m], n > 0.1 s × rate; NaN frames make the window not quiet.
    rate : float
        Sampling rate [Hz], > 0.
    force : array_like, shape (n, 3), optional
        Ground reaction force on the subject (ap, ml, up) [N] at the CoP's frames.
    max_speed, max_acceleration, max_load_change : float
        [m/s] > 0, [m/s²] > 0, fraction of the median vertical force in [0.01, 1]. Out of
        range, or a ``cop`` or ``force`` of the wrong shape, raises InvalidParameterError.
    """
    rate = positive_float("rate", rate, "Hz")
    lag = max(1, round(SPEED_LAG * rate))
    array = float_array("cop", cop)
    if array.ndim != 2 or array.shape[1] != 2 or array.shape[0] <= lag or np.isinf(array).any():
        raise InvalidParameterError(
            f"cop must be a finite-or-NaN array of shape (n, 2) [m], n > {lag} "
            f"(0.1 s at {rate:g} Hz), got shape {array.shape}"
        )
    max_speed = positive_float("max_speed", max_speed, "m/s")
    max_acceleration = positive_float("max_acceleration", max_acceleration, "m/s^2")
    max_load_change = bounded_float("max_load_change", max_load_change, 0.01, 1.0)
    loads = None if force is None else float_array("force", force)
    if loads is not None and (loads.shape != (len(array), 3) or np.isinf(loads).any()):
        shape = f"({len(array)}, 3)"
        raise InvalidParameterError(f"force must be finite or NaN, {shape} [N], got {loads.shape}")
    if np.isnan(array).any() or (loads is not None and np.isnan(loads).any()):
        return False
    shift = array[lag:] - array[:-lag]
    if np.hypot(shift[:, 0], shift[:, 1]).max() > max_speed * lag / rate:
        return False
    if loads is None:
        return True
    vertical = loads[:, 2]
    typical = float(np.median(vertical))
    if vertical.min() < LOADED or np.abs(vertical - typical).max() > max_load_change * typical:
        return False
    return bool(np.hypot(loads[:, 0], loads[:, 1]).max() <= max_acceleration * typical / GRAVITY)
