"""What the report shows, as data: frozen dataclasses of numbers, table rows and figure paths.

Each section builder (``report/sections.py``, ``campaigns.py``, ``mujoco.py``, ``steps.py``)
returns one of the ``*Section`` classes below; ``report/render.py`` turns them into HTML through
the jinja2 templates in ``report/templates`` (autoescaped: no text here is trusted as markup).
Numbers are in SI units and kept as numbers; table cells are already formatted text (the
significant digits the table shows), the numbers behind them are fields of their own.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

__all__ = [
    "BoundsSection",
    "CampaignSection",
    "ConfusionMatrix",
    "CriticalSection",
    "Disagreements",
    "FailedSection",
    "FiguresSection",
    "Filmstrip",
    "FilmstripsSection",
    "Footer",
    "Humanoid3DSection",
    "MapSection",
    "Picture",
    "PlaneSection",
    "Report",
    "Section",
    "StepCounts",
    "StepsSection",
    "SweepSection",
    "Table",
    "Verdict",
    "VerdictCounts",
]


@dataclass(frozen=True)
class Table:
    """A table of formatted cells; the first ``text_columns`` columns are left-aligned text."""

    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    text_columns: int = 0
    ident: str | None = None


@dataclass(frozen=True)
class Picture:
    """An image file embedded in the page, its caption and the name shown as its source."""

    path: Path
    caption: str
    source: str | None = None


@dataclass(frozen=True)
class ConfusionMatrix:
    """Predicted strategy (rows) against the strategy used (columns) of a campaign.

    ``apart``: columns of their own beside the matrix, per predicted row: the runs neither
    recovered nor fallen (``undecided``, ``slipped``).
    """

    labels: tuple[str, ...]
    counts: tuple[tuple[int, ...], ...]
    ident: str
    apart: tuple[tuple[str, tuple[int, ...]], ...] = ()

    @property
    def row_totals(self) -> tuple[int, ...]:
        """Pushes per predicted strategy (the columns apart included)."""
        extra = [column for _, column in self.apart]
        return tuple(
            sum(row) + sum(column[i] for column in extra) for i, row in enumerate(self.counts)
        )

    @property
    def column_totals(self) -> tuple[int, ...]:
        """Pushes per strategy used, then per column apart."""
        columns = [*zip(*self.counts, strict=True), *(column for _, column in self.apart)]
        return tuple(sum(column) for column in columns)

    @property
    def total(self) -> int:
        """All pushes."""
        return sum(self.row_totals)


@dataclass(frozen=True)
class VerdictCounts:
    """The accuracy's own table: the surfaces' verdict (recovers or not) against the outcome.

    Accuracy = (``recovers_recovered`` + ``fails_not_recovered``) / ``total``.
    """

    recovers_recovered: int
    recovers_not_recovered: int
    fails_recovered: int
    fails_not_recovered: int
    ident: str

    @property
    def total(self) -> int:
        """All pushes."""
        return (
            self.recovers_recovered
            + self.recovers_not_recovered
            + self.fails_recovered
            + self.fails_not_recovered
        )

    @property
    def right(self) -> int:
        """Pushes whose verdict matched the outcome."""
        return self.recovers_recovered + self.fails_not_recovered


@dataclass(frozen=True)
class Disagreements:
    """The pushes whose outcome the surfaces got wrong, by kind."""

    fell_inside: int  # within the controller's strategy, yet fell or undecided
    recovered_beyond: int  # beyond it, yet recovered
    recovered_with_steps: int  # of those predicted to fall: recovered with two or more steps

    @property
    def wrong(self) -> int:
        """All wrong verdicts."""
        return self.fell_inside + self.recovered_beyond


@dataclass(frozen=True)
class StepCounts:
    """N-step predictions against the steps taken (a campaign summary's ``steps``)."""

    predicted: tuple[tuple[str, int], ...]  # ("0", n), ("1", n), ..., ("fall", n)
    taken: tuple[tuple[str, int], ...]
    exact: float | None  # fraction of recovered step pushes that took the predicted number


@dataclass(frozen=True)
class Section:
    """A section of the page; ``template`` names its file in ``report/templates``."""

    template: ClassVar[str]


@dataclass(frozen=True)
class FailedSection(Section):
    """A section that could not be computed (a missing optional dependency, a bad setting)."""

    template: ClassVar[str] = "failed.html.j2"
    error: str
    message: str


@dataclass(frozen=True)
class BoundsSection(Section):
    """The parameters, the capture-point bounds and the thresholds (``bounds --json``)."""

    template: ClassVar[str] = "bounds.html.j2"
    parameters: Table
    bounds: Table


@dataclass(frozen=True)
class MapSection(Section):
    """The strategy map of the sagittal (x, ẋ) plane."""

    template: ClassVar[str] = "map.html.j2"
    picture: Picture


@dataclass(frozen=True)
class PlaneSection(Section):
    """The capture-point plane and the per-direction thresholds on the ground plane."""

    template: ClassVar[str] = "plane.html.j2"
    picture: Picture
    thresholds: Table
    pitch_offset: float  # CMP offset of the pitch flywheel along x [m]
    roll_offset: float  # CMP offset of the roll flywheel along y [m]


@dataclass(frozen=True)
class StepsSection(Section):
    """Capture regions, the N-step strategy map and the N-step thresholds."""

    template: ClassVar[str] = "steps.html.j2"
    regions: Picture
    steps_map: Picture
    thresholds: Table
    max_step_length: float  # [m]
    min_step_time: float  # [s]
    max_steps: int
    sec4_backward: float  # Sec. IV's single-step threshold backward, as a speed [m/s]
    sec4_forward: float  # [m/s]


@dataclass(frozen=True)
class FiguresSection(Section):
    """The paper's figures, recomputed for the body."""

    template: ClassVar[str] = "figures.html.j2"
    pictures: tuple[Picture, ...]


@dataclass(frozen=True)
class CampaignSection(Section):
    """A push campaign against the surfaces' verdicts."""

    template: ClassVar[str] = "campaign.html.j2"
    key: str
    lead: str
    backend: str
    model: str
    controller: str
    pushes: int
    recovered: int
    fell: int
    undecided: int
    errors: int  # pushes without an outcome (physics diverged, worker died): not in accuracy
    accuracy: float | None  # None: no push has an outcome
    verdicts: VerdictCounts
    confusion: ConfusionMatrix
    disagreements: Disagreements
    step_counts: StepCounts | None
    outcome_map: Picture
    boundary: Table | None  # the grid's critical pushes; None when the grid has no boundary
    irregular: int  # boundary rows that are not monotone
    data_files: tuple[str, ...]  # relative to the page
    slipped: int = 0  # at rest on feet that slid (3-D): not recovered


@dataclass(frozen=True)
class SweepSection(Section):
    """The critical push of ``flywheel`` + ``mpc`` against one swept body parameter."""

    template: ClassVar[str] = "sweep.html.j2"
    parameter: str
    unit: str
    pushes: int
    accuracy: float | None  # None: no push has an outcome
    picture: Picture
    boundary: Table


@dataclass(frozen=True)
class CriticalSection(Section):
    """The MuJoCo critical-push table."""

    template: ClassVar[str] = "critical.html.j2"
    table: Table


@dataclass(frozen=True)
class Filmstrip:
    """One rendered MuJoCo run (``picture`` None when the body has no such model)."""

    strategy: str
    model: str
    caption: str
    impulse: float  # [N s]
    velocity: float  # impulse / mass [m/s]
    outcome: str | None
    picture: Picture | None


@dataclass(frozen=True)
class FilmstripsSection(Section):
    """One MuJoCo run per strategy, or why rendering is not available."""

    template: ClassVar[str] = "filmstrips.html.j2"
    strips: tuple[Filmstrip, ...]
    unavailable: str | None = None


@dataclass(frozen=True)
class Humanoid3DSection(Section):
    """The 3-D humanoids: the validation's polar plots and tables, and filmstrips.

    ``unavailable`` is the one line saying how to get the section (the ``robots`` extra) when
    it could not be computed; ``rendering`` says why there are no filmstrips (no OpenGL).
    """

    template: ClassVar[str] = "humanoid3d.html.j2"
    polar: tuple[Picture, ...] = ()
    tables: tuple[Table, ...] = ()
    strips: tuple[Filmstrip, ...] = ()
    unavailable: str | None = None
    rendering: str | None = None


@dataclass(frozen=True)
class Verdict:
    """The paragraph at the top: the body's forward thresholds and the campaigns' accuracy."""

    ankle: float  # [m/s], Eq. (4)
    hip: float  # [m/s], corrected Eq. (15)
    step: float  # [m/s], the N-step verdict
    scores: tuple[tuple[str, float | None, int], ...]  # (section title, accuracy, pushes)
    #: Sections that could not be computed: (key, title, why), named where the reader looks first.
    missing: tuple[tuple[str, str, str], ...] = ()


@dataclass(frozen=True)
class Footer:
    """Where and how long the page was computed."""

    version: str
    size: str
    where: str  # "2 local worker processes" or "the Dask scheduler ADDRESS"
    timings: tuple[tuple[str, float], ...]  # (section title, wall time [s]) in computed order
    total: float  # [s]


@dataclass(frozen=True)
class Report:
    """The whole page: sections by key in the page's order, with titles and notes."""

    size: str
    verdict: Verdict
    sections: tuple[tuple[str, str, Section], ...]  # (key, title, data)
    notes: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    footer: Footer | None = None

    def section(self, key: str) -> Section:
        """Return the data of the section ``key`` (KeyError if it was not computed)."""
        for name, _, data in self.sections:
            if name == key:
                return data
        raise KeyError(key)
