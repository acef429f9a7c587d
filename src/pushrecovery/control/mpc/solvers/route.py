"""The route of a tick: which solver solves it, in what order (docs/mpc.md, "How a tick is solved").

:meth:`Route.solve` is the controller's one entry. With ``solver="daqp"`` (the default), each
step only if the previous one did not give a plan: the warm Riccati passes
(:class:`~pushrecovery.control.mpc.solvers.riccati.RiccatiSolver`); the exact feasibility test
(:class:`~pushrecovery.control.mpc.feasibility.FlywheelFeasibility`), beyond every solver's
tolerance the fallback at once; inside the viable set the interior point
(:class:`~pushrecovery.control.mpc.solvers.interior.InteriorPointSolver`), whose active set the
passes verify, and on its boundary full braking held with the passes started from a problem
with θmax :data:`RELAXED` larger; the condensed QP in a warm DAQP workspace
(:class:`~pushrecovery.control.mpc.solvers.daqp.DaqpSolver`); last the saturated fallback
(INFEASIBLE). Other solvers, or ``daqp`` without its workspace, solve the condensed QP through
``qpsolvers.solve_qp`` at every tick
(:class:`~pushrecovery.control.mpc.solvers.solve_qp.SolveQpSolver`), then the fallback.

The real-time mode (``MPCSettings(realtime=True)``) takes the same route within a fixed budget
of work, counted in passes and iterations (deterministic: the same states give the same plans
on any machine): at most :data:`REALTIME_PASS_STAGES` / N warm passes and
:data:`REALTIME_ITERATION_STAGES` / N interior-point iterations, no DAQP. A tick the budget
does not solve applies the last plan that solved Eq. (17) shifted by one stage per tick since
(SHIFTED), and the next tick's passes start from its active set, shifted once more; with no such
plan (none since the last reset, or older than the horizon) the first input of the interior
point's unfinished iterate, which the next tick continues, or the saturated fallback where there
is none (EXHAUSTED).

Over 400 lines on purpose: the route is one decision (which solver ends a tick), its default and
real-time budgets two settings of it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.mpc.feasibility import BAND, BOUNDARY, FlywheelFeasibility
from pushrecovery.control.mpc.plan import Plan, Status
from pushrecovery.control.mpc.problem import MPCSettings, SparseQP
from pushrecovery.control.mpc.qp import CondensedQP, shared_qp
from pushrecovery.control.mpc.solvers.base import Guess
from pushrecovery.control.mpc.solvers.daqp import DaqpSolver
from pushrecovery.control.mpc.solvers.interior import InteriorPointSolver
from pushrecovery.control.mpc.solvers.riccati import MAX_PASSES, POLISH_PASSES, RiccatiSolver
from pushrecovery.control.mpc.solvers.solve_qp import SolveQpSolver
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams

__all__ = [
    "INTERIOR_MARGIN",
    "PASSES_AFTER_FAILURE",
    "REALTIME_ITERATION_STAGES",
    "REALTIME_PASS_STAGES",
    "RELAXED",
    "RELAXED_GUIDE_CENTRE",
    "Route",
]

FloatArray = NDArray[np.float64]

#: Warm passes on the tick after one whose warm passes failed (docs/mpc.md, "The route's
#: constants").
PASSES_AFTER_FAILURE = 2
#: Relative widening of θmax for the interior point on the viable set's boundary: enough for
#: an interior, small enough that its active set is the problem's (with full braking held).
RELAXED = 1e-3
#: The relaxed interior point's warm start: the last verified set's rows start with s z at
#: this × dual scale × range (docs/mpc.md, "The route's constants").
RELAXED_GUIDE_CENTRE = 10.0
#: The interior point is not asked within this relative margin of S_N's boundary (the
#: boundary's own margin, BOUNDARY): there the feasible set has no interior and its iterates
#: stall; the passes with full braking held decide, then DAQP.
INTERIOR_MARGIN = BOUNDARY
#: The real-time mode's budget of warm Riccati passes, in stages: at most this / N passes
#: (and at most MAX_PASSES), a pass costing O(N) (docs/mpc.md, "The real-time mode").
REALTIME_PASS_STAGES = 1000
#: The real-time mode's budget of interior-point iterations, in stages: at most this / N
#: iterations (20 at N = 50, 5 at N = 200), each O(N) (docs/mpc.md, "The real-time mode").
REALTIME_ITERATION_STAGES = 1000

_WARM = Guess()
_VERIFIED = Status.VERIFIED  # a module global: an enum member through its class costs ~0.1 µs
_SHIFTED = Status.SHIFTED
_WARM_PASSES = Guess(budget=MAX_PASSES)
_PASSES_AFTER_FAILURE = Guess(budget=PASSES_AFTER_FAILURE)


class Route:
    """The route of one body and settings: its solvers, their order, what it keeps between ticks.

    The sparse solvers (Riccati passes, interior points) are built at once when the route is
    DAQP's (``settings.solver == "daqp"``) and every bound has a range
    (:meth:`~pushrecovery.control.mpc.solvers.riccati.RiccatiSolver.applies`); the condensed
    QP, its solver and the feasibility test on the first tick that needs them.

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    settings : MPCSettings
        Horizon, weights, γ, dt and solver.

    Attributes
    ----------
    riccati : RiccatiSolver or None
        The Riccati passes (None: not on this route).
    interior : InteriorPointSolver or None
        The interior point, polished by ``riccati``.
    relaxed : InteriorPointSolver or None
        The interior point on θmax :data:`RELAXED` larger, for the viable set's boundary.
    feasibility : FlywheelFeasibility or None
        The exact feasibility test (built on the first tick that needs it).
    use_daqp : bool
        Whether the condensed QP goes to the DAQP workspace (else ``qpsolvers.solve_qp``).
    passes_failed : bool
        Whether the last tick's warm passes failed.
    boundary : bool
        Whether the last tick was solved on S_N's boundary.
    held : Plan or None
        Real-time mode: the last plan that solved Eq. (17), shifted on the ticks since.
    age : int
        Real-time mode: the ticks since ``held`` was solved.
    realtime_passes, realtime_iterations : int
        Real-time mode: the warm passes (:data:`REALTIME_PASS_STAGES` / N, at most
        ``MAX_PASSES``) and interior-point iterations (:data:`REALTIME_ITERATION_STAGES` / N)
        allowed per tick, at least 1.

    Raises
    ------
    InvalidParameterError
        If ``settings.realtime`` and the sparse solvers do not apply (a bound without a
        range, e.g. τmax = 0).
    """

    def __init__(self, params: BodyParams, settings: MPCSettings) -> None:
        self.params, self.settings = params, settings
        sparse = self._sparse_qp = SparseQP(params, settings)
        self.riccati: RiccatiSolver | None = None
        self.interior: InteriorPointSolver | None = None
        self.relaxed: InteriorPointSolver | None = None
        if settings.solver == "daqp" and RiccatiSolver.applies(params):
            self.riccati = RiccatiSolver(sparse)
            self.interior = InteriorPointSolver(sparse, polish=self.riccati)
            wider = params.flywheel_angle_max * (1.0 + RELAXED)
            self.relaxed = InteriorPointSolver(
                SparseQP(dataclasses.replace(params, flywheel_angle_max=wider), settings),
                polish=self.riccati, guide_centre=RELAXED_GUIDE_CENTRE,
            )  # fmt: skip
        self._qp: CondensedQP | None = None
        self._daqp: DaqpSolver | None = None
        self._solve_qp: SolveQpSolver | None = None
        self.use_daqp = settings.solver == "daqp"
        self.feasibility: FlywheelFeasibility | None = None  # built on first need
        self.passes_failed = False
        self.boundary = False
        self.realtime = settings.realtime
        self.held: Plan | None = None
        self.age = 0
        self._unfinished: InteriorPointSolver | None = None  # the iterate to go on with
        n = settings.horizon
        self.realtime_passes = max(1, min(MAX_PASSES, REALTIME_PASS_STAGES // n))
        self.realtime_iterations = max(1, REALTIME_ITERATION_STAGES // n)
        if self.realtime:
            if self.riccati is None or not FlywheelFeasibility.applies(params):
                raise InvalidParameterError(
                    "realtime=True needs every bound with a range (heel < toe, torque_max > 0, "
                    "flywheel_angle_max > 0): the sparse solvers' route"
                )
            self.gauge(np.zeros(4))  # build the feasibility test now, not on a tick

    @property
    def qp(self) -> CondensedQP:
        """The condensed, pre-stabilised QP (built on first use, shared: :func:`shared_qp`)."""
        if self._qp is None:
            self._qp = shared_qp(self.params, self.settings)
        return self._qp

    @property
    def daqp(self) -> DaqpSolver | None:
        """The DAQP workspace of :attr:`qp` (built on first use); None: qpsolvers' route."""
        if self._daqp is None and self.use_daqp:
            try:
                self._daqp = DaqpSolver(self.qp)
            except (ImportError, RuntimeError):
                self.use_daqp = False  # an old daqp, or a setup it rejects
        return self._daqp

    @property
    def solve_qp(self) -> SolveQpSolver:
        """The condensed QP through ``qpsolvers.solve_qp`` (built on first use)."""
        if self._solve_qp is None:
            self._solve_qp = SolveQpSolver(self.qp, self.settings.solver)
        return self._solve_qp

    def gauge(self, x0: FloatArray) -> float:
        """Return the gauge of (θ, θ̇) of x0 in S_N (:class:`FlywheelFeasibility`).

        0 where the test does not apply (no interior): the solvers decide.
        """
        feasibility = self.feasibility
        if feasibility is None:
            if not FlywheelFeasibility.applies(self.params):
                return 0.0
            feasibility = self.feasibility = FlywheelFeasibility(self.params, self.settings)
        return feasibility.gauge(x0)

    def reset(self) -> None:
        """Forget the warm starts: the next tick starts from the empty active set."""
        self.passes_failed = self.boundary = False
        self.held, self.age, self._unfinished = None, 0, None
        if self._daqp is not None:
            self._daqp.reset()
        if self.riccati is not None:
            self.riccati.reset()

    def solve(self, x0: FloatArray, last: Plan | None) -> Plan:
        """Solve one tick from ``x0`` = [x, θ, ẋ, θ̇] by the route (module docstring).

        Parameters
        ----------
        x0 : ndarray, shape (4,)
            The measured state [m, rad, m/s, rad/s].
        last : Plan or None
            The last tick's plan: the interior point's warm start.

        Returns
        -------
        Plan
            The plan; INFEASIBLE (the fallback) if the QP has no solution. Only the solvers' own
            failures mean "infeasible": any other exception is a bug and propagates. Real-time
            mode: also SHIFTED or EXHAUSTED (module docstring).
        """
        if self.realtime:
            return self._solve_realtime(x0, last)
        riccati = self.riccati
        # Whether the previous tick was verified by the passes: DAQP did not solve it, and
        # riccati.active holds its optimal set (kept by a failed solve) to start DAQP from.
        previous_verified = riccati is not None and riccati.verified
        # After a tick the warm passes failed, the next one's usually fail too: a few passes,
        # then the interior point (PASSES_AFTER_FAILURE).
        warm: Guess | None = _PASSES_AFTER_FAILURE if self.passes_failed else _WARM_PASSES
        gauge = -1.0
        if self.boundary:
            # The last tick was on S_N's boundary, where the passes without full braking held
            # rarely verify the next tick (docs/mpc.md, "The route's constants"): when this one is
            # too, its route at once.
            gauge = self.gauge(x0)
            if gauge >= 1.0 - INTERIOR_MARGIN:
                warm = None
        if riccati is not None and warm is not None:
            plan = riccati.solve(x0, warm)
            if plan.status is _VERIFIED:
                self.passes_failed = self.boundary = False
                return plan
        self.passes_failed = riccati is not None
        x0 = x0.copy()  # the plan's own: the caller may reuse its array
        if gauge < 0.0:
            gauge = self.gauge(x0)
        self.boundary = gauge >= 1.0 - INTERIOR_MARGIN
        if self.use_daqp and gauge > 1.0 + BAND:
            # DAQP would fail, warm and then cold (up to ~1000 iterations): leave both solvers
            # as that failure would (cold next tick) without asking it.
            if self._daqp is not None:
                self._daqp.reset()
            if riccati is not None:
                riccati.reset()
            return self._fallback(x0)
        if riccati is not None:
            inputs = last.inputs if last is not None and last.feasible else None
            sparse = self._sparse(riccati, x0, gauge, previous_verified, inputs)
            if sparse is not None:
                return sparse
        daqp = self.daqp
        if daqp is not None:
            # As warm as if DAQP had solved the previous tick itself (it ends there).
            guess = Guess(riccati.active) if riccati is not None and previous_verified else _WARM
            plan = daqp.solve(x0, guess)
            if riccati is not None:
                # The next tick's passes start from DAQP's active set, or the empty one.
                if plan.active is not None:
                    riccati.seed(plan.active)
                else:
                    riccati.reset()
        else:
            plan = self.solve_qp.solve(x0, _WARM)
        return plan if plan.feasible else self._fallback(x0)

    def _sparse(
        self,
        riccati: RiccatiSolver,
        x0: FloatArray,
        gauge: float,
        previous_verified: bool,
        warm: FloatArray | None,
        budget: int | None = None,
    ) -> Plan | None:
        """Solve a tick the warm passes did not verify, on the sparse QP; None: DAQP decides.

        Inside S_N: the interior point, whose iterates' active sets the passes are offered to
        verify (its own solution if none verifies, e.g. the cycling late-horizon torques). On its
        boundary (γ ≥ 1 − BOUNDARY), where the feasible set has no interior: full braking held
        (:meth:`FlywheelFeasibility.forced_braking`), the passes from the active sets of the
        interior point on the problem with θmax 0.1 % larger (:data:`RELAXED`), which has an
        interior, then from the last tick's set. ``warm``: the last tick's inputs (the interior
        point's warm start); ``budget``: its iterations (None: its own maximum).
        """
        interior = self.interior
        unfinished, self._unfinished = self._unfinished, None  # continued this tick or never
        if gauge < 1.0 - INTERIOR_MARGIN:
            if interior is None:
                return None
            forced = (0, 0)
        else:
            if self.feasibility is None or self.relaxed is None:
                return None
            forced = self.feasibility.forced_braking(x0)
            if not forced[0]:
                return None
            # The passes from the last set come after the relaxed interior point, not before:
            # tried first they rarely verify a boundary tick and cost time on each (docs/mpc.md,
            # "The route's constants").
            interior = self.relaxed
        # Warm from the last tick's plan (its inputs computed if they were left lazy) and, if
        # the passes verified it, its active set (the failed warm passes leave it in place).
        start = riccati.active.copy()  # the last tick's set (the failed passes keep it)
        guide = start if warm is not None and previous_verified else None
        # Real-time mode: the last tick's interior point, out of its budget, goes on.
        resume = budget is not None and interior is unfinished
        plan = interior.solve(x0, Guess(guide, True, warm, forced, budget, resume))
        self._unfinished = interior if budget is not None and interior.resumable else None
        if plan.status is Status.VERIFIED:
            return plan
        if (
            plan.status is Status.CONVERGED
            and interior is self.interior
            and plan.active is not None
        ):
            riccati.seed(plan.active)  # the next tick's start
            return plan
        if forced[0]:  # on the boundary: the passes from the last tick's set, braking held
            plan = riccati.solve(x0, Guess(start, True, None, forced, POLISH_PASSES))
            if plan.status is Status.VERIFIED:
                return plan
        riccati.reset()
        return None

    def _solve_realtime(self, x0: FloatArray, last: Plan | None) -> Plan:
        """Solve one tick within the real-time budget (module docstring); as :meth:`solve`."""
        riccati = self.riccati
        assert riccati is not None  # checked at construction
        previous_verified = riccati.verified
        passes = min(PASSES_AFTER_FAILURE, self.realtime_passes) if self.passes_failed else None
        warm: Guess | None = Guess(budget=self.realtime_passes if passes is None else passes)
        gauge = -1.0
        if self.boundary:
            gauge = self.gauge(x0)
            if gauge >= 1.0 - INTERIOR_MARGIN:
                warm = None
        if warm is not None:
            plan = riccati.solve(x0, warm)
            if plan.status is _VERIFIED:
                self.passes_failed = self.boundary = False
                self.held, self.age, self._unfinished = plan, 0, None
                return plan
        self.passes_failed = True
        x0 = x0.copy()  # the plan's own: the caller may reuse its array
        if gauge < 0.0:
            gauge = self.gauge(x0)
        self.boundary = gauge >= 1.0 - INTERIOR_MARGIN
        if gauge > 1.0 + BAND:  # exactly infeasible: the fallback, as the default route
            riccati.reset()
            self.held, self.age, self._unfinished = None, 0, None
            return self._fallback(x0)
        inputs = (
            last.inputs if last is not None and (last.feasible or last.status is _SHIFTED) else None
        )
        solved = self._sparse(
            riccati, x0, gauge, previous_verified, inputs, self.realtime_iterations
        )
        if solved is not None:
            self.held, self.age = solved, 0
            return solved
        return self._shifted(x0)

    def _shifted(self, x0: FloatArray) -> Plan:
        """Return the held plan shifted by one more stage (SHIFTED), or EXHAUSTED.

        Its inputs from x0 on (the last stage's repeated), states on demand; the passes of the
        next tick start from its active set (shifted once more by them). With no plan held (or
        one older than the horizon), EXHAUSTED: the inputs of the interior point's unfinished
        iterate, which the next tick continues (the plant then follows the iterate the
        interior point goes on from), or where there is none the saturated fallback.
        """
        held, riccati = self.held, self.riccati
        assert riccati is not None
        self.age += 1
        n = self.settings.horizon
        if held is None or self.age >= n:
            self.held, self.age = None, 0
            riccati.reset()
            unfinished = self._unfinished
            if unfinished is None:
                return self._fallback(x0, Status.EXHAUSTED)
            iterate = unfinished.iterate_inputs()
            sparse = self._sparse_qp
            return Plan(Status.EXHAUSTED, iterate[0], iterate, lambda: sparse.simulate(x0, iterate))
        age = self.age
        inputs = np.empty((n, 2))
        inputs[: n - age] = held.inputs[age:]
        inputs[n - age :] = held.inputs[-1]
        active = held.active
        if active is not None:
            shifted = np.empty_like(active)
            shifted[: n - age] = active[age:]
            shifted[n - age :] = active[-1]
            riccati.seed(shifted)
            active = shifted
        else:
            riccati.reset()
        sparse = self._sparse_qp
        return Plan(_SHIFTED, inputs[0], inputs, lambda: sparse.simulate(x0, inputs), active)

    def _fallback(self, x0: FloatArray, status: Status = Status.INFEASIBLE) -> Plan:
        """Return the fallback plan from ``x0`` (INFEASIBLE, or EXHAUSTED), states on demand."""
        p = self.params
        cop = p.clip_cop(x0[0] + x0[2] / p.omega)  # the capture point
        rate = x0[3]
        torque = -math.copysign(p.torque_max, rate) if rate != 0.0 else 0.0
        first = np.array([cop, torque])
        inputs = np.tile(first, (self.settings.horizon, 1))
        sparse = self._sparse_qp
        return Plan(status, first, inputs, lambda: sparse.simulate(x0, inputs))
