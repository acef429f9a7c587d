"""What a push campaign sweeps: the grid (or random sample) of pushes, and its checks.

A campaign is one model + controller on one backend, pushed from every CoM position x0 with
every push (a velocity ẋ [m/s] or an impulse J [N s], J = m ẋ) for every combination of the
swept body parameters. Push ``i`` is fully defined by the spec and ``i``: the grid order is
parameters (outermost, in the order given), then x0, then the push; a random campaign
(``samples``) draws push ``i`` from ``numpy.random.default_rng([seed, i])``, so that no result
depends on how the pushes are split into batches or spread over workers.

On the 3-D models (``biped3d``, ``g1``; :mod:`~pushrecovery.campaign.spec.humanoid`) the
body stands in its own posture (x0 = 0 only), each push also has an azimuth (the grid:
parameters, x0, azimuth, push; a random campaign draws it uniformly between the smallest and
largest azimuth), the pushes may be fractions of the ankle's predicted critical impulse along
it (``fraction``), and the controller is the whole-body controller with one strategy set
(``wbc-ankle``, ``wbc-hip``, ``wbc-step``).

Over 400 lines on purpose: one concept, the spec and its checks; the 3-D part is in
:mod:`~pushrecovery.campaign.spec.humanoid`.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pushrecovery.arguments import bounded_float, non_negative_float
from pushrecovery.campaign.ranges import MAX_PUSHES, Range, value_range
from pushrecovery.campaign.ranges import interval as _interval
from pushrecovery.campaign.spec.humanoid import (
    MODELS_3D,
    WBC_CONTROLLERS,
    check_spec3d,
    critical_impulse,
    standing_origin,
)
from pushrecovery.control.base import controller_class
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.params import BodyParams
from pushrecovery.sim.mjcf_source import MjcfSource

__all__ = [
    "BACKENDS",
    "MAX_PUSHES",
    "CampaignError",
    "CampaignSpec",
    "Push",
    "value_range",
]


class CampaignError(PushRecoveryError):
    """A campaign cannot run: unreachable scheduler, a directory holding another campaign."""


#: Backends a campaign runs on, with their models.
BACKENDS: Mapping[str, tuple[str, ...]] = {
    "analytic": ("lipm", "pendulum", "flywheel", "stepping", "stepping-plane"),
    "mujoco": ("foot", "torso", "biped", *MODELS_3D),
}
#: Wall time a push may take by default, and at most [s].
DEFAULT_PUSH_TIMEOUT = 120.0
MAX_PUSH_TIMEOUT = 3600.0
#: Pushes per batch when the spec does not say: about a second of work per batch through the
#: one-push loop (0.5-2 s on the reference machine; docs/campaigns.md, "Execution").
DEFAULT_BATCH = {"analytic": 100, "mujoco": 10}
#: Largest default batch of the analytic pairs whose batch runs as one compiled loop
#: (``sim.many.COMPILED``): about a second of work too (~140 µs per pendulum push, ~30 µs
#: per LIPM push, ~1 ms per stepping + recovery push). A Dask task costs a few ms of
#: scheduling and one Parquet file: at 100 such pushes per batch (12 ms of work) that would be
#: most of a campaign's time.
COMPILED_BATCH = {("pendulum", "ankle-pd"): 10_000, ("lipm", "ankle-pd"): 10_000,
                  ("stepping", "recovery"): 1_000}  # fmt: skip
#: A default batch of a compiled pair grows past ``DEFAULT_BATCH`` only while the campaign
#: keeps at least this many batches: enough to share among the workers and to resume from.
MIN_BATCHES = 16


@dataclass(frozen=True, slots=True)
class Push:
    """One push of a campaign: its index, the body, the CoM start and the push.

    3-D models: its ``azimuth`` [deg], ``xdot`` = J/m along it, ``fraction`` of J*_ankle.
    """

    index: int
    params: BodyParams
    swept: tuple[float, ...]
    x0: float
    xdot: float
    azimuth: float | None = None
    fraction: float | None = None

    @property
    def impulse(self) -> float:
        """The push as an impulse at the CoM, m ẋ [N s]."""
        return self.params.mass * self.xdot


@dataclass(frozen=True)
class CampaignSpec:
    """A push campaign (see the module docstring for the order of the pushes).

    Parameters
    ----------
    backend : {"analytic", "mujoco"}
        Physics: velocity jumps on the analytic models, real forces at the CoM on MuJoCo.
    model, controller : str
        Plant (``BACKENDS[backend]``) and controller registry names; on the 3-D models
        (``biped3d``, ``g1``, ``mjcf``) the controller is one of ``WBC_CONTROLLERS``.
    params : BodyParams
        The body; swept parameters replace their field.
    x0 : (start, stop, step)
        CoM positions before the push, relative to the ankle [m], strictly on the foot
        (3-D models: 0 only, the standing posture).
    xdot, impulse, fraction : (start, stop, step)
        The pushes, as the CoM velocity they give [m/s], as impulses [N s] or (3-D models)
        as fractions of the ankle's predicted critical impulse along each azimuth [-]
        (exactly one).
    sweeps : mapping of str to (start, stop, step)
        Body parameters to sweep (``BodyParams`` field names), in SI units.
    samples : int or None
        ``None``: the full grid. Otherwise this many pushes drawn uniformly from the box of the
        ranges (their steps unused) with ``seed``.
    seed : int
        Seed of the random draws (``samples``), >= 0.
    duration : float
        Longest simulated time per push [s], > 0.
    batch_size : int or None
        Pushes per task sent to a worker; ``None``: 100 analytic, 10 MuJoCo, and for the
        pairs run as one compiled loop (``COMPILED_BATCH``) up to 10,000 (``pendulum``,
        ``lipm`` + ``ankle-pd``) or 1,000 (``stepping`` + ``recovery``) while the campaign
        keeps 16 batches (:attr:`batch`).
    push_timeout : float
        Wall time one push may take [s], in (0, 3600] (default 120): a push that takes longer
        is an ``error`` row, and a worker that stops answering is stopped
        (:mod:`~pushrecovery.campaign.isolation`).
    azimuths : tuple of float or None
        3-D models only: the pushes' directions [deg], 0 forward, 90 left (default (0,));
        1 to 360 angles in [−360, 360], distinct modulo 360.
    mjcf : MjcfSource or None
        Model ``mjcf`` only (and then required): the user's MJCF humanoid, its file and bodies;
        ``params`` is its derived body (``MjcfPlant(...).params``) and cannot be swept.
    state_sd : (float, float) or None
        Planar models: standard deviations of a state estimate's errors in x [m] and ẋ [m/s],
        each >= 0. Each push then gets a seeded estimate and the probability that its
        controller's strategy suffices (``p_recovers``, docs/uncertainty.md).
    latency : float
        Planar models: the controller reacts this late [s], in [0, 1], the CoP held at the
        foot's middle until then (``run_many``'s ``latency``: the pushes run through the
        loop), and the probabilities take the same latency; with a ``state_sd`` or alone.
    """

    backend: str
    model: str
    controller: str
    params: BodyParams
    x0: Range
    xdot: Range | None = None
    impulse: Range | None = None
    sweeps: Mapping[str, Range] = field(default_factory=dict)
    samples: int | None = None
    seed: int = 0
    duration: float = 6.0
    batch_size: int | None = None
    push_timeout: float = DEFAULT_PUSH_TIMEOUT
    azimuths: tuple[float, ...] | None = None
    fraction: Range | None = None
    mjcf: MjcfSource | None = None
    state_sd: tuple[float, float] | None = None
    latency: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.backend, str) or self.backend not in BACKENDS:
            raise InvalidParameterError(
                f"backend must be one of {list(BACKENDS)}, got {self.backend!r}"
            )
        if self.model not in BACKENDS[self.backend]:
            raise InvalidParameterError(
                f"model must be one of {list(BACKENDS[self.backend])} on the {self.backend} "
                f"backend, got {self.model!r}"
            )
        object.__setattr__(self, "azimuths", check_spec3d(self))  # and the 2-D's controller
        if sum(p is not None for p in (self.xdot, self.impulse, self.fraction)) != 1:
            raise InvalidParameterError("give exactly one of xdot and impulse (the pushes)")
        # Every number of the body can be swept; a polygon cannot.
        fields = {f.name for f in dataclasses.fields(BodyParams)} - {"foot_polygon"}
        for name in self.sweeps:
            if name not in fields:
                raise InvalidParameterError(
                    f"unknown parameter {name!r}; sweepable: {sorted(fields)}"
                )
        for label, value in (
            ("samples", self.samples),
            ("seed", self.seed),
            ("batch_size", self.batch_size),
        ):
            if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
                raise InvalidParameterError(f"{label} must be an integer, got {value!r}")
        if self.samples is not None and not 1 <= self.samples <= MAX_PUSHES:
            raise InvalidParameterError(f"samples must be in [1, {MAX_PUSHES}], got {self.samples}")
        if self.seed < 0:
            raise InvalidParameterError(f"seed must be >= 0, got {self.seed}")
        if not (math.isfinite(self.duration) and self.duration > 0.0):
            raise InvalidParameterError(f"duration must be > 0 s, got {self.duration:g}")
        if not (
            isinstance(self.push_timeout, int | float)
            and not isinstance(self.push_timeout, bool)
            and 0.0 < self.push_timeout <= MAX_PUSH_TIMEOUT
        ):
            raise InvalidParameterError(
                f"push_timeout must be in (0, {MAX_PUSH_TIMEOUT:g}] s, got {self.push_timeout!r}"
            )
        if self.batch_size is not None and self.batch_size < 1:
            raise InvalidParameterError(f"batch_size must be >= 1, got {self.batch_size}")
        self._check_uncertainty()
        # Every range, every body it sweeps and the setup are checked now, before any
        # simulation and before anything is written.
        if self.samples is None:
            sweeps, x0s, _ = self._axes
            if self.size > MAX_PUSHES:
                raise InvalidParameterError(
                    f"the campaign has {self.size} pushes; at most {MAX_PUSHES}"
                )
            x0_ends = (float(x0s[0]), float(x0s[-1]))
            bodies = list(itertools.product(*sweeps))
        else:
            # The draws cover each whole interval; the constraints of a body are intervals or
            # linear (max_step_length < 2 leg_length): its corners stand for the whole box.
            corners = [_interval(f"--param {n}", r) for n, r in self.sweeps.items()]
            _interval(f"--{self.push_name}", self.push_range)
            x0_ends = _interval("--x0", self.x0)
            bodies = list(itertools.product(*corners))
        for values in bodies:
            body = self.body(values)
            for x0 in x0_ends:
                if not body.heel < x0 < body.toe:
                    raise InvalidParameterError(
                        f"x0 must lie on the foot, {body.heel:g} < x0 < {body.toe:g} m, got {x0:g}"
                    )
        self._check_setup()

    def _check_uncertainty(self) -> None:
        """Check ``state_sd`` and ``latency`` (planar models only)."""
        latency = bounded_float("latency", self.latency, 0.0, 1.0, "s")
        object.__setattr__(self, "latency", latency)
        if self.state_sd is None and latency == 0.0:
            return
        if self.is_3d:
            raise InvalidParameterError(
                "state_sd and latency apply to the planar models, not to the 3-D humanoids"
            )
        if self.state_sd is not None:
            if isinstance(self.state_sd, str) or len(self.state_sd) != 2:
                raise InvalidParameterError(
                    f"state_sd must be (sd of x [m], sd of xdot [m/s]), got {self.state_sd!r}"
                )
            sd = (
                non_negative_float("state_sd[0]", self.state_sd[0], "m"),
                non_negative_float("state_sd[1]", self.state_sd[1], "m/s"),
            )
            object.__setattr__(self, "state_sd", sd)

    @property
    def is_3d(self) -> bool:
        """Whether the model is a 3-D humanoid (the whole-body controller, azimuths)."""
        return self.model in MODELS_3D

    @property
    def source(self) -> str | MjcfSource:
        """What builds the model's plant: its name, or the MJCF file (``model`` ``mjcf``)."""
        return self.model if self.mjcf is None else self.mjcf

    @property
    def model_name(self) -> str:
        """The model's name in tables and figures: its name, or the MJCF file's stem."""
        return self.model if self.mjcf is None else self.mjcf.name

    @functools.cached_property
    def strategy(self) -> str:
        """The highest strategy the controller has: ankle, hip or step."""
        if self.is_3d:
            return WBC_CONTROLLERS[self.controller]
        return str(controller_class(self.controller).strategy)

    def _check_setup(self) -> None:
        """Check that the model, controller and duration work together (:func:`check_run`)."""
        if self.is_3d:  # the plant builds (the G1's extra is there, its params its own)
            standing_origin(self.source, self.push(0).params)
            return
        from pushrecovery.control.base import make_controller
        from pushrecovery.sim.registry import make_plant
        from pushrecovery.sim.simulate import check_run

        first = self.push(0)
        plant = make_plant(self.model, first.params, self.backend)
        controller = make_controller(self.controller, first.params)
        check_run(plant, controller, plant.reset(first.x0, 0.0), self.duration)

    # --- the pushes -----------------------------------------------------------------------
    @property
    def push_name(self) -> str:
        """``xdot``, ``impulse`` or ``fraction``: how the pushes are given."""
        if self.fraction is not None:
            return "fraction"
        return "xdot" if self.xdot is not None else "impulse"

    @property
    def push_range(self) -> Range:
        """The range of the pushes, in the unit of :attr:`push_name`."""
        push = self.xdot if self.xdot is not None else self.impulse
        push = self.fraction if self.fraction is not None else push
        assert push is not None  # checked in __post_init__
        return push

    @functools.cached_property
    def _axes(self) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
        """The grid's values: each swept parameter's, the starts' and the pushes'."""
        return (
            [value_range(f"--param {name}", r) for name, r in self.sweeps.items()],
            value_range("--x0", self.x0),
            value_range(f"--{self.push_name}", self.push_range),
        )

    @property
    def _directions(self) -> tuple[float, ...]:
        """The azimuths of a 3-D campaign (one axis of the grid); () on the 2-D models."""
        return self.azimuths or ()

    @functools.cached_property
    def size(self) -> int:
        """Number of pushes."""
        if self.samples is not None:
            return self.samples
        sweeps, x0s, pushes = self._axes
        # Python ints: no overflow however large the grid.
        turns = len(self._directions) if self.is_3d else 1
        return math.prod(len(v) for v in sweeps) * len(x0s) * turns * len(pushes)

    @property
    def batch(self) -> int:
        """Pushes per batch: ``batch_size``, else about a second of work (``DEFAULT_BATCH``).

        A compiled pair's default, min(largest, max(100, ⌈size / 16⌉)), keeps scheduling
        under 1 % of the work at scale (10⁶ pendulum pushes: 100 tasks of ~1.4 s, not 10,000
        of 12 ms) and a small campaign's batches as they were.
        """
        if self.batch_size:
            return self.batch_size
        usual = DEFAULT_BATCH[self.backend]
        largest = COMPILED_BATCH.get((self.model, self.controller), usual)
        if self.backend != "analytic" or largest == usual:
            return usual
        return min(largest, max(usual, -(-self.size // MIN_BATCHES)))

    @property
    def batches(self) -> int:
        """Number of batches."""
        return -(-self.size // self.batch)

    def body(self, swept: tuple[float, ...]) -> BodyParams:
        """Return the body of one combination of the swept values (checked as any BodyParams)."""
        if not self.sweeps:  # the spec's own body, checked when it was made
            return self.params
        changes: dict[str, Any] = dict(zip(self.sweeps, (float(v) for v in swept), strict=True))
        try:
            return dataclasses.replace(self.params, **changes)
        except InvalidParameterError as exc:
            raise InvalidParameterError(f"--param sweep: {exc}") from None

    def _push(
        self,
        index: int,
        swept: tuple[float, ...],
        x0: float,
        push: float,
        azimuth: float | None = None,
        bodies: dict[tuple[float, ...], BodyParams] | None = None,
    ) -> Push:
        body = bodies.get(swept) if bodies is not None else None
        if body is None:
            body = self.body(swept)
            if bodies is not None:
                bodies[swept] = body
        if not body.heel < x0 < body.toe:  # a bug, not input: the spec checked the box
            raise InvalidParameterError(f"x0 = {x0:g} m is off the foot of push {index}")
        values = tuple(float(v) for v in swept)
        if self.fraction is not None and azimuth is not None:  # J = f J*_ankle(ψ)
            impulse = float(push) * critical_impulse(
                body, standing_origin(self.source, body), float(azimuth)
            )
            return Push(index, body, values, float(x0), impulse / body.mass, float(azimuth),
                        float(push))  # fmt: skip
        xdot = push if self.xdot is not None else push / body.mass
        angle = None if azimuth is None else float(azimuth)
        return Push(index, body, values, float(x0), float(xdot), angle)

    def push(self, index: int) -> Push:
        """Push number ``index`` (0 <= index < size)."""
        if not 0 <= index < self.size:
            raise InvalidParameterError(f"index must be in [0, {self.size}), got {index}")
        return self._numbered(index, None)

    def _numbered(self, index: int, bodies: dict[tuple[float, ...], BodyParams] | None) -> Push:
        """Push number ``index``; ``bodies`` keeps the bodies of the swept values built so far."""
        if self.samples is not None:
            rng = np.random.default_rng([self.seed, index])
            ranges = [*self.sweeps.values(), self.x0, self.push_range]
            if self.is_3d:  # drawn between the push's start and its size
                turns = self._directions
                ranges.insert(-1, (min(turns), max(turns), 0.0))
            draws = [rng.uniform(r[0], r[1]) if r[1] > r[0] else r[0] for r in ranges]
            if self.is_3d:
                return self._push(index, tuple(draws[:-3]), draws[-3], draws[-1], draws[-2], bodies)
            return self._push(index, tuple(draws[:-2]), draws[-2], draws[-1], None, bodies)
        sweeps, x0s, pushes = self._axes
        turns = self._directions
        shape = [len(v) for v in sweeps] + [len(x0s), len(turns) or 1, len(pushes)]
        position = np.unravel_index(index, shape)
        swept = tuple(v[k] for v, k in zip(sweeps, position[:-3], strict=True))
        azimuth = turns[position[-2]] if self.is_3d else None
        return self._push(index, swept, x0s[position[-3]], pushes[position[-1]], azimuth, bodies)

    def pushes(self, batch: int) -> list[Push]:
        """Return the pushes of batch number ``batch``."""
        start = batch * self.batch
        stop = min(start + self.batch, self.size)
        bodies: dict[tuple[float, ...], BodyParams] = {}  # a grid's bodies repeat
        return [self._numbered(i, bodies) for i in range(start, stop)]

    def batch_indices(self) -> Iterator[int]:
        """Every batch number, in order."""
        return iter(range(self.batches))

    # --- storage ---------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """JSON form (``from_dict`` reads it back).

        ``azimuths``, ``fraction``: 3-D only; ``mjcf`` (the file and its bodies): model
        ``mjcf`` only.
        """
        extra: dict[str, Any] = {
            name: list(value)
            for name, value in (("azimuths", self.azimuths), ("fraction", self.fraction))
            if value is not None
        }
        if self.mjcf is not None:
            extra["mjcf"] = self.mjcf.to_dict()
        if self.state_sd is not None:
            extra["state_sd"] = list(self.state_sd)
        if self.latency:
            extra["latency"] = self.latency
        return extra | {
            "backend": self.backend,
            "model": self.model,
            "controller": self.controller,
            "params": self.params.to_dict(),
            "x0": list(self.x0),
            "xdot": None if self.xdot is None else list(self.xdot),
            "impulse": None if self.impulse is None else list(self.impulse),
            # Pairs, in order: the order of the sweeps is the order of the grid and the columns.
            "sweeps": [[name, list(r)] for name, r in self.sweeps.items()],
            "samples": self.samples,
            "seed": self.seed,
            "duration": self.duration,
            "batch_size": self.batch,
            "pushes": self.size,
            "push_timeout": self.push_timeout,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> CampaignSpec:
        """Read a spec written by :meth:`to_dict`."""
        try:
            return cls(
                backend=data["backend"],
                model=data["model"],
                controller=data["controller"],
                params=BodyParams(**data["params"]),
                x0=tuple(data["x0"]),
                xdot=None if data["xdot"] is None else tuple(data["xdot"]),
                impulse=None if data["impulse"] is None else tuple(data["impulse"]),
                sweeps={str(k): tuple(v) for k, v in data["sweeps"]},
                samples=data["samples"],
                seed=data["seed"],
                duration=data["duration"],
                batch_size=data["batch_size"],
                push_timeout=data.get("push_timeout", DEFAULT_PUSH_TIMEOUT),
                azimuths=None if data.get("azimuths") is None else tuple(data["azimuths"]),
                fraction=None if data.get("fraction") is None else tuple(data["fraction"]),
                mjcf=None if data.get("mjcf") is None else MjcfSource.from_dict(data["mjcf"]),
                state_sd=None if data.get("state_sd") is None else tuple(data["state_sd"]),
                latency=data.get("latency", 0.0),
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InvalidParameterError(f"malformed campaign spec: {exc}") from None
