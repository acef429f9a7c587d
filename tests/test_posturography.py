"""Quiet-standing posturography against hand-computed values (docs/posturography.md).

Every expected value below is derived by hand from the signal's geometry (a circle, a
triangle wave, a sine, Gaussian noise of known covariance), not from the code; the real
Kistler trial of biomdp is checked against the published order of magnitude of standing sway.
"""

from __future__ import annotations

import math
import pathlib

import biomdp
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pushrecovery.analysis.posturography import (
    mean_distance,
    mean_frequency,
    mean_velocity,
    path_length,
    prediction_ellipse,
    quiet_standing,
    rms_distance,
    sway_measures,
    sway_spectrum,
)
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

KISTLER = pathlib.Path(biomdp.__file__).parent / "tests" / "datasets" / "kistler_COP.c3d"
CHI2_95 = -2.0 * math.log(0.05)  # 5.9915: chi-square quantile, 2 degrees of freedom
RATE = 100.0
#: A bad argument raises one of the project's errors naming it (None: ParameterTypeError).
NAMED = (InvalidParameterError, ParameterTypeError)


def circle(radius: float, turns: int, per_turn: int, *, closed: bool) -> np.ndarray:
    """A circle about (0.3, 0.1) m run at constant speed, ``per_turn`` samples a turn."""
    n = turns * per_turn + (1 if closed else 0)
    phase = 2.0 * np.pi * np.arange(n) / per_turn
    return np.column_stack([0.3 + radius * np.cos(phase), 0.1 + radius * np.sin(phase)])


def triangle(amplitude: float, frequency: float, seconds: float, angle: float) -> np.ndarray:
    """A straight back-and-forth line at constant speed along ``angle`` from +ap to +ml."""
    t = np.arange(round(seconds * RATE)) / RATE
    phase = (t * frequency) % 1.0
    s = amplitude * np.interp(phase, [0.0, 0.25, 0.75, 1.0], [0.0, 1.0, -1.0, 0.0])
    return np.column_stack([s * math.cos(angle), s * math.sin(angle)])


def rotate(cop: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return cop @ np.array([[c, s], [-s, c]])


def random_sway(seed: int, n: int = 3000) -> np.ndarray:
    """A smooth random sway (filtered random walk), 30 s at 100 Hz, a few mm."""
    rng = np.random.default_rng(seed)
    walk = np.cumsum(rng.normal(0.0, 1e-4, (n, 2)), axis=0)
    kernel = np.ones(15) / 15.0
    smooth = np.column_stack([np.convolve(walk[:, k], kernel, "same") for k in range(2)])
    return smooth - 0.5 * np.linspace(0.0, 1.0, n)[:, None] * smooth[-1]


# -- a circle of radius r at constant speed ---------------------------------------------------


def test_circle_path_speed_and_distances():
    r, turns, per_turn, f = 0.01, 10, 200, 0.5  # 200 samples a turn at 100 Hz: 0.5 turn/s
    closed = circle(r, turns, per_turn, closed=True)
    chord = 2.0 * r * math.sin(math.pi / per_turn)  # exact length of one step
    length = path_length(closed)
    assert length.total == pytest.approx(turns * per_turn * chord, rel=1e-12)
    assert length.total == pytest.approx(turns * 2.0 * math.pi * r, rel=1e-4)  # 2πr a turn
    assert length.ap == pytest.approx(turns * 4.0 * r, rel=1e-4)  # each axis runs 4r a turn
    speed = mean_velocity(closed, RATE)
    assert speed.total == pytest.approx(2.0 * math.pi * r * f, rel=1e-4)
    # Whole turns without the repeated end point: the mean is the centre, RD = r exactly.
    whole = circle(r, turns, per_turn, closed=False)
    assert mean_distance(whole).total == pytest.approx(r, rel=1e-12)
    assert rms_distance(whole) == pytest.approx((r, r / math.sqrt(2), r / math.sqrt(2)), 1e-12)
    assert mean_distance(whole).ap == pytest.approx(2.0 * r / math.pi, rel=1e-4)  # mean |cos|


def test_circle_mean_frequency_and_ellipse():
    r, f = 0.01, 0.5
    closed = circle(r, 10, 200, closed=True)
    frequency = mean_frequency(closed, RATE)
    assert frequency.total == pytest.approx(f, rel=1e-3)  # turns per second
    assert frequency.ap == pytest.approx(math.pi * f / (2.0 * math.sqrt(2.0)), rel=1e-3)
    whole = circle(r, 10, 200, closed=False)
    n = len(whole)
    variance = r * r / 2.0 * n / (n - 1)  # per axis, sample covariance
    ellipse = prediction_ellipse(whole)
    assert ellipse.area == pytest.approx(math.pi * CHI2_95 * variance, rel=1e-9)
    assert ellipse.semi_major == pytest.approx(math.sqrt(CHI2_95 * variance), rel=1e-6)
    assert ellipse.semi_minor == pytest.approx(ellipse.semi_major, rel=1e-6)


def test_circle_spectra():
    r, f = 0.01, 0.5
    measures = sway_measures(circle(r, 20, 200, closed=False), RATE)  # 40 s, 20 s segments
    rd = measures.spectrum_rd  # RD is constant: no power, no frequency
    assert rd.total_power == 0.0 and math.isnan(rd.f50) and math.isnan(rd.centroidal_frequency)
    resolution = RATE / 2000 + 1e-9  # one bin, and rounding
    for axis in (measures.spectrum_ap, measures.spectrum_ml):
        assert axis.total_power == pytest.approx(r * r / 2.0, rel=0.02)  # a sine's power A²/2
        assert abs(axis.f50 - f) <= resolution and abs(axis.f95 - f) <= resolution
        assert axis.centroidal_frequency == pytest.approx(f, abs=resolution)
        assert axis.frequency_dispersion < 2.0 * resolution / f  # a pure tone: about Δf/(√3 f)


# -- a straight back-and-forth line ----------------------------------------------------------


@pytest.mark.parametrize("angle", [0.0, 0.6, -1.2, math.pi / 2])
def test_straight_line(angle):
    a, f = 0.02, 0.25  # 2 cm amplitude, 4 s a cycle: 10 whole cycles in 40 s
    cop = triangle(a, f, 40.0, angle)
    measures = sway_measures(cop, RATE)
    n = len(cop)
    # Path 4a a cycle over the (n - 1) steps: the last step is the one cut at the end.
    assert measures.path_length.total == pytest.approx(4 * a * 10 - a / 100, rel=1e-9)
    assert measures.mean_velocity.total == pytest.approx(4 * a * f, rel=1e-9)
    assert measures.mean_distance.total == pytest.approx(a / 2, rel=1e-3)  # uniform on [-a, a]
    assert measures.rms_distance.total == pytest.approx(a / math.sqrt(3), rel=1e-3)
    assert measures.mean_frequency.total == pytest.approx(4 * f / math.pi, rel=2e-3)
    variance = a * a / 3 * n / (n - 1)
    # A line has no area: √(λ₁ λ₂) with λ₂ = 0 up to rounding (√ε of the scale).
    assert measures.ellipse.area < 1e-7 * math.pi * CHI2_95 * variance
    assert measures.ellipse.semi_major == pytest.approx(math.sqrt(CHI2_95 * variance), rel=1e-3)
    direction = angle if angle > -math.pi / 2 else angle + math.pi
    assert measures.ellipse.angle == pytest.approx(direction, abs=1e-9)
    assert measures.range_ap == pytest.approx(2 * a * abs(math.cos(angle)), abs=1e-12)
    assert measures.range_ml == pytest.approx(2 * a * abs(math.sin(angle)), abs=1e-12)
    if angle == 0.0:
        assert measures.mean_frequency.ap == pytest.approx(math.sqrt(2) * f, rel=2e-3)
        assert math.isnan(measures.mean_frequency.ml)  # no ml motion: MDIST_ML = 0


# -- sinusoids and noise in the spectrum -----------------------------------------------------


@pytest.mark.parametrize("frequency", [0.3, 0.85, 1.5, 4.0])
def test_sine_spectrum_at_its_frequency(frequency):
    t = np.arange(6000) / RATE  # 60 s, 20 s segments: 0.05 Hz resolution
    spectrum = sway_spectrum(0.005 * np.sin(2 * np.pi * frequency * t + 0.3), RATE)
    resolution = 0.05 + 1e-9  # one bin, and rounding
    assert abs(spectrum.f50 - frequency) <= resolution
    assert abs(spectrum.f95 - frequency) <= resolution
    assert spectrum.centroidal_frequency == pytest.approx(frequency, abs=resolution)
    assert spectrum.total_power == pytest.approx(0.005**2 / 2, rel=0.02)


def test_white_noise_spectrum_is_flat_in_the_band():
    rng = np.random.default_rng(7)
    rate, (low, high) = 10.0, (0.15, 5.0)  # the band reaches Nyquist: flat G over it
    spectrum = sway_spectrum(rng.normal(0.0, 1e-3, 40000), rate)
    # Flat G on [low, high]: μ_k ∝ (high^(k+1) - low^(k+1)) / (k + 1).
    mu = [(high ** (k + 1) - low ** (k + 1)) / (k + 1) for k in range(3)]
    assert spectrum.f50 == pytest.approx((low + high) / 2, abs=0.1)
    assert spectrum.f95 == pytest.approx(low + 0.95 * (high - low), abs=0.1)
    assert spectrum.centroidal_frequency == pytest.approx(math.sqrt(mu[2] / mu[0]), rel=0.02)
    dispersion = math.sqrt(1 - mu[1] ** 2 / (mu[0] * mu[2]))
    assert spectrum.frequency_dispersion == pytest.approx(dispersion, rel=0.03)
    # Parseval: the band holds (high - low) / (rate / 2) of the variance.
    assert spectrum.total_power == pytest.approx(1e-6 * (high - low) / 5.0, rel=0.03)


def test_gaussian_noise_ellipse_holds_95_percent():
    rng = np.random.default_rng(2024)
    angle, sd = math.radians(30.0), np.array([0.006, 0.002])  # major axis 30° towards +ml
    rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    sigma = rotation @ np.diag(sd**2) @ rotation.T
    n = 20000
    cop = rng.multivariate_normal([0.25, 0.4], sigma, n)
    ellipse = prediction_ellipse(cop)
    expected = math.pi * CHI2_95 * math.sqrt(np.linalg.det(sigma))
    # sqrt(det S) has a relative standard error of about 1/sqrt(n) = 0.7 %: allow 3 %.
    assert ellipse.area == pytest.approx(expected, rel=0.03)
    assert ellipse.angle == pytest.approx(angle, abs=math.radians(1.0))
    centred = cop - cop.mean(axis=0)
    major = np.array([math.cos(ellipse.angle), math.sin(ellipse.angle)])
    minor = np.array([-major[1], major[0]])
    inside = (centred @ major / ellipse.semi_major) ** 2 + (
        centred @ minor / ellipse.semi_minor
    ) ** 2 <= 1
    assert inside.mean() == pytest.approx(0.95, abs=0.005)  # binomial sd 0.15 %


# -- invariance and scaling ------------------------------------------------------------------

INVARIANT = ("path_length", "mean_velocity", "mean_distance", "rms_distance", "mean_frequency",
             "ellipse_area", "ellipse_semi_major", "ellipse_semi_minor", "rd_total_power",
             "rd_f50", "rd_f95", "rd_centroidal_frequency", "rd_frequency_dispersion")  # fmt: skip


@given(
    seed=st.integers(0, 10_000),
    shift=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
    angle=st.floats(-math.pi, math.pi),
)
def test_translation_and_rotation_invariance(seed, shift, angle):
    cop = random_sway(seed)
    base = sway_measures(cop, RATE).to_dict()
    moved = sway_measures(cop + np.array(shift), RATE).to_dict()
    for key, value in base.items():
        assert moved[key] == pytest.approx(value, rel=1e-6, abs=1e-12), key
    turned = sway_measures(rotate(cop, angle), RATE).to_dict()
    for key in INVARIANT:
        assert turned[key] == pytest.approx(base[key], rel=1e-6, abs=1e-12), key
    change = (turned["ellipse_angle"] - base["ellipse_angle"] - angle) % math.pi
    assert min(change, math.pi - change) < 1e-6


@given(seed=st.integers(0, 10_000), scale=st.floats(0.01, 100.0))
def test_scaling_laws(seed, scale):
    cop = random_sway(seed)
    base = sway_measures(cop, RATE).to_dict()
    scaled = sway_measures(scale * cop, RATE).to_dict()
    for key, value in base.items():
        if "power" in key or key == "ellipse_area":
            power = 2
        elif any(s in key for s in ("length", "velocity", "distance", "range", "semi")):
            power = 1
        else:  # frequencies, dispersion, angle, duration, band
            power = 0
        assert scaled[key] == pytest.approx(value * scale**power, rel=1e-6, abs=1e-12), key


# -- the real quiet-standing trial -------------------------------------------------------------


def test_kistler_quiet_standing_trial():
    from pushrecovery.analysis.readers.c3d_files import read_c3d_recording

    recording = read_c3d_recording(KISTLER)
    assert recording.cop is not None and recording.force_time is not None
    rate = 1.0 / float(np.median(np.diff(recording.force_time)))
    assert rate == pytest.approx(1000.0)
    assert quiet_standing(recording.cop, rate, force=recording.force)
    m = sway_measures(recording.cop, rate)
    # Order of magnitude of standing sway: mm-to-cm excursions, mm/s-to-dm/s speeds (a unit
    # error would miss by 1000). This trial sways more than healthy adults' bipedal eyes-open
    # norms (about 5-20 mm/s, ellipse about 1e-4 m²): docs/posturography.md.
    assert 0.005 < m.mean_velocity.total < 0.2
    assert 1e-5 < m.ellipse.area < 1e-2
    assert 0.001 < m.rms_distance.total < 0.05
    # Postural sway's frequency content (Prieto 1996): most power well below 5 Hz.
    for spectrum in (m.spectrum_ap, m.spectrum_ml):
        assert 0.15 <= spectrum.f50 < 1.0 and spectrum.f95 < 3.0
    assert m.rms_distance.total**2 == pytest.approx(
        m.rms_distance.ap**2 + m.rms_distance.ml**2, rel=1e-12
    )


# -- quiet_standing --------------------------------------------------------------------------


def calm(n: int = 1000) -> tuple[np.ndarray, np.ndarray]:
    """10 s of small sway with a 700 N body's forces."""
    cop = 0.005 * triangle(1.0, 0.3, n / RATE, 0.4)
    force = np.column_stack([np.full(n, 3.0), np.full(n, -2.0), np.full(n, 700.0)])
    return cop, force


def test_quiet_standing_passes_calm_and_fails_events():
    cop, force = calm()
    assert quiet_standing(cop, RATE) and quiet_standing(cop, RATE, force=force)
    step = cop.copy()
    step[500:] += [0.0, 0.2]  # the CoP jumps 20 cm: a step
    assert not quiet_standing(step, RATE)
    ramp = cop + np.column_stack([np.arange(len(cop)) / RATE, np.zeros(len(cop))])  # 1 m/s
    assert not quiet_standing(ramp, RATE)
    gap = cop.copy()
    gap[10] = np.nan
    assert not quiet_standing(gap, RATE)
    for frame, column, value in [(300, 2, 0.0), (300, 2, 1000.0), (300, 0, 200.0)]:
        pushed = force.copy()  # plate left, a jump's landing, a 2.8 m/s² push
        pushed[frame, column] = value
        assert not quiet_standing(cop, RATE, force=pushed)


# -- bad input: every argument ---------------------------------------------------------------

GOOD = random_sway(1)
BAD_COP = [
    np.zeros(10), np.zeros((10, 3)), np.zeros((2, 2)), np.full((100, 2), np.inf), "x", None,
]  # fmt: skip
BAD_RATE = [0.0, -1.0, math.nan, math.inf, "x", None, [1.0, 2.0]]
TIME_DOMAIN = [path_length, mean_distance, rms_distance, prediction_ellipse]


@pytest.mark.parametrize("function", [*TIME_DOMAIN, mean_velocity, mean_frequency, sway_measures])
@pytest.mark.parametrize("cop", BAD_COP, ids=range(len(BAD_COP)))
def test_bad_cop(function, cop):
    args = (cop,) if function in TIME_DOMAIN else (cop, RATE)
    with pytest.raises(NAMED, match="cop"):
        function(*args)


@pytest.mark.parametrize("function", [*TIME_DOMAIN, mean_velocity, sway_measures])
def test_nan_frames_are_refused(function):
    cop = GOOD.copy()
    cop[100] = np.nan
    args = (cop,) if function in TIME_DOMAIN else (cop, RATE)
    with pytest.raises(InvalidParameterError, match="missing"):
        function(*args)


@pytest.mark.parametrize("function", [mean_velocity, mean_frequency, sway_measures])
@pytest.mark.parametrize("rate", BAD_RATE, ids=range(len(BAD_RATE)))
def test_bad_rate(function, rate):
    with pytest.raises(InvalidParameterError, match="rate"):
        function(GOOD, rate)


@pytest.mark.parametrize("rate", BAD_RATE, ids=range(len(BAD_RATE)))
def test_bad_rate_spectrum_and_quiet(rate):
    with pytest.raises(InvalidParameterError, match="rate"):
        sway_spectrum(GOOD[:, 0], rate)
    with pytest.raises(InvalidParameterError, match="rate"):
        quiet_standing(GOOD, rate)


@pytest.mark.parametrize(
    "band", [(0.0, 5.0), (5.0, 0.15), (0.15, 50.1), (math.nan, 5.0), "x", (1.0, 2.0, 3.0), None]
)
def test_bad_band(band):
    with pytest.raises(InvalidParameterError, match="band"):
        sway_measures(GOOD, RATE, band=band)
    with pytest.raises(InvalidParameterError, match="band"):
        sway_spectrum(GOOD[:, 0], RATE, band=band)


@pytest.mark.parametrize("segment", [0.0, -1.0, math.nan, "x", 5.0])
def test_bad_segment(segment):  # 5 s < 1 / 0.15 Hz: the band's low edge is not resolved
    with pytest.raises(InvalidParameterError, match="segment"):
        sway_measures(GOOD, RATE, segment=segment)
    with pytest.raises(InvalidParameterError, match="segment"):
        sway_spectrum(GOOD[:, 0], RATE, segment=segment)


def test_too_short_for_the_spectrum():
    short = GOOD[:600]  # 6 s < 1 / 0.15 Hz
    with pytest.raises(InvalidParameterError, match="1 / band low"):
        sway_measures(short, RATE)
    assert sway_measures(short, RATE, band=(0.2, 5.0)).spectrum_ap.f50 > 0  # 5 s suffice


@pytest.mark.parametrize("series", [GOOD, np.full(1000, np.nan), "x", None, 1.0])
def test_bad_series(series):
    with pytest.raises(NAMED, match="series"):
        sway_spectrum(series, RATE)


@pytest.mark.parametrize("probability", [0.4, 1.0, math.nan, "x", None])
def test_bad_probability(probability):
    with pytest.raises(InvalidParameterError, match="probability"):
        prediction_ellipse(GOOD, probability)


def test_bad_quiet_standing_arguments():
    cop, force = calm()
    for bad in [np.zeros((10, 2)), np.zeros((100, 3)), np.full((100, 2), np.inf), "x"]:
        with pytest.raises(NAMED, match="cop"):
            quiet_standing(bad, RATE)
    for bad in [force[:-1], force[:, :2], np.full_like(force, np.inf), "x"]:
        with pytest.raises(InvalidParameterError, match="force"):
            quiet_standing(cop, RATE, force=bad)
    for name, value in [("max_speed", 0.0), ("max_acceleration", -1.0),
                        ("max_load_change", 0.0), ("max_load_change", 2.0),
                        ("max_speed", math.nan)]:  # fmt: skip
        with pytest.raises(InvalidParameterError, match=name):
            quiet_standing(cop, RATE, **{name: value})


def test_to_dict_is_flat_and_labelled():
    row = sway_measures(GOOD, RATE).to_dict()
    assert all(isinstance(v, float) for v in row.values())
    keys = ("path_length_ap", "mean_velocity", "ellipse_area", "ap_f95", "rd_total_power",
            "ml_frequency_dispersion", "mean_frequency_ml", "band_low", "range_ml")  # fmt: skip
    assert set(keys) <= set(row)
