"""What a push campaign sweeps: the grid (or random sample) of pushes, and its checks.

A campaign is one model + controller on one backend, pushed from every CoM position x0 with
every push (a velocity ẋ [m/s] or an impulse J [N s], J = m ẋ) for every combination of the
swept body parameters. Push ``i`` is fully defined by the spec and ``i``: the grid order is
parameters (outermost, in the order given), then x0, then the push; a random campaign
(``samples``) draws push ``i`` from ``numpy.random.default_rng([seed, i])``, so that no result
depends on how the pushes are split into batches or spread over workers.
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

from pushrecovery.control.base import controller_class
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.params import BodyParams

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
    "mujoco": ("foot", "torso", "biped"),
}
#: Largest campaign accepted [pushes].
MAX_PUSHES = 1_000_000
#: Wall time a push may take by default, and at most [s].
DEFAULT_PUSH_TIMEOUT = 120.0
MAX_PUSH_TIMEOUT = 3600.0
#: Pushes per batch when the spec does not say: about a second of work per batch.
DEFAULT_BATCH = {"analytic": 100, "mujoco": 10}

Range = tuple[float, float, float]


def value_range(name: str, triple: Range, limit: int = MAX_PUSHES) -> np.ndarray:
    """START, START + STEP, ... up to STOP inclusive; STEP > 0, START <= STOP, finite.

    Raises
    ------
    InvalidParameterError
        Naming ``name`` when the range is empty, not finite or longer than ``limit``.
    """
    if len(triple) != 3:
        raise InvalidParameterError(f"{name} needs START STOP STEP, got {triple!r}")
    start, stop, increment = (float(v) for v in triple)
    if not all(math.isfinite(v) for v in (start, stop, increment)):
        raise InvalidParameterError(f"{name} must be finite, got {start:g} {stop:g} {increment:g}")
    if increment <= 0.0 or stop < start:
        raise InvalidParameterError(
            f"{name} needs START <= STOP and STEP > 0, got {start:g} {stop:g} {increment:g}"
        )
    count = int(np.floor((stop - start) / increment + 1e-9)) + 1
    if count > limit:
        raise InvalidParameterError(f"{name} gives {count} values; at most {limit}")
    # Rounded to 12 digits: 0.1 * 3 is 0.3 in the results, not 0.30000000000000004; never
    # beyond STOP.
    return np.minimum(np.round(start + increment * np.arange(count), 12), stop)


def _interval(name: str, triple: Range) -> tuple[float, float]:
    """START and STOP of a range whose STEP is not used (random samples): finite, ordered."""
    if len(triple) != 3:
        raise InvalidParameterError(f"{name} needs START STOP STEP, got {triple!r}")
    start, stop = float(triple[0]), float(triple[1])
    if not (math.isfinite(start) and math.isfinite(stop)) or stop < start:
        raise InvalidParameterError(f"{name} needs finite START <= STOP, got {start:g} {stop:g}")
    return start, stop


@dataclass(frozen=True, slots=True)
class Push:
    """One push of a campaign: its index, the body, the CoM start and the push."""

    index: int
    params: BodyParams
    swept: tuple[float, ...]
    x0: float
    xdot: float

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
        Plant (``BACKENDS[backend]``) and controller registry names.
    params : BodyParams
        The body; swept parameters replace their field.
    x0 : (start, stop, step)
        CoM positions before the push, relative to the ankle [m], strictly on the foot.
    xdot, impulse : (start, stop, step)
        The pushes, as the CoM velocity they give [m/s] or as impulses [N s] (exactly one).
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
        Pushes per task sent to a worker; ``None``: 100 analytic, 10 MuJoCo.
    push_timeout : float
        Wall time one push may take [s], in (0, 3600] (default 120): a push that takes longer
        is an ``error`` row, and a worker that stops answering is stopped
        (:mod:`~pushrecovery.campaign.isolation`).
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

    def __post_init__(self) -> None:
        if self.backend not in BACKENDS:
            raise InvalidParameterError(
                f"backend must be one of {list(BACKENDS)}, got {self.backend!r}"
            )
        if self.model not in BACKENDS[self.backend]:
            raise InvalidParameterError(
                f"model must be one of {list(BACKENDS[self.backend])} on the {self.backend} "
                f"backend, got {self.model!r}"
            )
        controller_class(self.controller)  # raises, naming the controllers
        if (self.xdot is None) == (self.impulse is None):
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

    def _check_setup(self) -> None:
        """Check that the model, controller and duration work together (:func:`check_run`)."""
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
        """``xdot`` or ``impulse``: how the pushes are given."""
        return "xdot" if self.xdot is not None else "impulse"

    @property
    def push_range(self) -> Range:
        """The range of the pushes, in the unit of :attr:`push_name`."""
        push = self.xdot if self.xdot is not None else self.impulse
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

    @functools.cached_property
    def size(self) -> int:
        """Number of pushes."""
        if self.samples is not None:
            return self.samples
        sweeps, x0s, pushes = self._axes
        # Python ints: no overflow however large the grid.
        return math.prod(len(v) for v in sweeps) * len(x0s) * len(pushes)

    @property
    def batch(self) -> int:
        """Pushes per batch."""
        return self.batch_size or DEFAULT_BATCH[self.backend]

    @property
    def batches(self) -> int:
        """Number of batches."""
        return -(-self.size // self.batch)

    def body(self, swept: tuple[float, ...]) -> BodyParams:
        """Return the body of one combination of the swept values (checked as any BodyParams)."""
        changes: dict[str, Any] = dict(zip(self.sweeps, (float(v) for v in swept), strict=True))
        try:
            return dataclasses.replace(self.params, **changes)
        except InvalidParameterError as exc:
            raise InvalidParameterError(f"--param sweep: {exc}") from None

    def _push(self, index: int, swept: tuple[float, ...], x0: float, push: float) -> Push:
        body = self.body(swept)
        if not body.heel < x0 < body.toe:  # a bug, not input: the spec checked the box
            raise InvalidParameterError(f"x0 = {x0:g} m is off the foot of push {index}")
        xdot = push if self.xdot is not None else push / body.mass
        return Push(index, body, tuple(float(v) for v in swept), float(x0), float(xdot))

    def push(self, index: int) -> Push:
        """Push number ``index`` (0 <= index < size)."""
        if not 0 <= index < self.size:
            raise InvalidParameterError(f"index must be in [0, {self.size}), got {index}")
        if self.samples is not None:
            rng = np.random.default_rng([self.seed, index])
            ranges = [*self.sweeps.values(), self.x0, self.push_range]
            draws = [rng.uniform(r[0], r[1]) if r[1] > r[0] else r[0] for r in ranges]
            return self._push(index, tuple(draws[:-2]), draws[-2], draws[-1])
        sweeps, x0s, pushes = self._axes
        shape = [len(v) for v in sweeps] + [len(x0s), len(pushes)]
        position = np.unravel_index(index, shape)
        swept = tuple(v[k] for v, k in zip(sweeps, position[:-2], strict=True))
        return self._push(index, swept, x0s[position[-2]], pushes[position[-1]])

    def pushes(self, batch: int) -> list[Push]:
        """Return the pushes of batch number ``batch``."""
        start = batch * self.batch
        return [self.push(i) for i in range(start, min(start + self.batch, self.size))]

    def batch_indices(self) -> Iterator[int]:
        """Every batch number, in order."""
        return iter(range(self.batches))

    # --- storage ---------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """JSON form (``from_dict`` reads it back)."""
        return {
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
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InvalidParameterError(f"malformed campaign spec: {exc}") from None
