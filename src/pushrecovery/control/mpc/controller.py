"""The receding-horizon controller: solve the QP each tick, apply the first input."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command, Controller, register
from pushrecovery.control.mpc.feasibility import BAND, BOUNDARY, FlywheelFeasibility
from pushrecovery.control.mpc.interior import InteriorPointSolver
from pushrecovery.control.mpc.plan import Plan
from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.control.mpc.qp import CondensedQP, shared_qp
from pushrecovery.control.mpc.riccati import MAX_PASSES, RiccatiSolver
from pushrecovery.control.mpc.workspace import PRIMAL_TOL, DaqpWorkspace
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import FLYWHEEL_STATE
from pushrecovery.params import BodyParams

__all__ = ["MPCController"]

#: Riccati passes allowed to verify an interior-point iterate's active set.
POLISH_PASSES = 3
#: Warm passes on the tick after one whose warm passes failed (see plan()).
PASSES_AFTER_FAILURE = 2
#: Relative widening of θmax for the interior point on the viable set's boundary: enough for
#: an interior, small enough that its active set is the problem's (with full braking held).
RELAXED = 1e-3
#: The relaxed interior point's warm start: the last verified set's rows start with s z at
#: this × dual scale × range (the other's 3.0, GUIDE_CENTRE); set by ``make bench``'s boundary
#: ticks (docs/mpc.md, "The route's constants").
RELAXED_GUIDE_CENTRE = 10.0
#: The interior point is not asked within this relative margin of S_N's boundary (the
#: boundary's own margin, BOUNDARY): there the feasible set has no interior and its iterates
#: stall; the passes with full braking held decide, then DAQP.
INTERIOR_MARGIN = BOUNDARY


@register
class MPCController(Controller):
    """Receding-horizon CMP balancing (Eqs. 16-17), the paper's settings by default.

    Each tick solves Eq. (17) exactly from the measured state ``[x, θ, ẋ, θ̇]`` and returns its
    first input. If the QP is infeasible (the flywheel cannot avoid its joint limit) the
    command is a saturated fallback, ``saturated=True``, and ``last_plan.feasible`` is False:
    CoP at the capture point clipped to the foot, full torque braking the flywheel. It never
    raises inside the loop.

    The default route (``solver="daqp"``), each step only if the previous did not verify:
    Riccati passes on the sparse QP from the last tick's active set (:class:`RiccatiSolver`);
    the exact feasibility test (:class:`FlywheelFeasibility`: beyond every solver's tolerance,
    the fallback); inside the flywheel's viable set, the interior point
    (:class:`InteriorPointSolver`) whose active set the passes verify; on its boundary, the
    passes with full braking held; last, the condensed QP (:class:`CondensedQP`, built on
    first need) in a warm-started DAQP workspace (the attribute ``workspace``). docs/mpc.md
    describes the route, docs/performance.md has its timings. Other solvers, or
    ``workspace = None``, go through ``qpsolvers.solve_qp`` on the condensed QP.

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    settings : MPCSettings, optional
        Horizon, weights, γ, dt and solver; keyword overrides of the defaults may be passed
        instead (``dt=``, ``horizon=``, ...).
    """

    name = "mpc"
    strategy = "hip"
    state_labels = FLYWHEEL_STATE
    fixed_period = True
    #: The paper's prediction step [s].
    default_dt = MPCSettings().dt

    def __init__(
        self, params: BodyParams, settings: MPCSettings | None = None, **overrides: Any
    ) -> None:
        super().__init__(params)
        settings = settings or MPCSettings(**overrides)
        from qpsolvers import available_solvers

        if settings.solver not in available_solvers:
            raise InvalidParameterError(
                f"solver must be one of {sorted(available_solvers)}, got {settings.solver!r}"
            )
        self.settings = settings
        self.control_period = settings.dt
        # The default route: the sparse QP by Riccati passes (O(N), set up in ~0.1 ms), the
        # condensed QP in DAQP when they do not verify an optimum. The condensed QP and its
        # workspace (~4 ms at N = 50) are built on the first tick that needs them.
        self.riccati: RiccatiSolver | None = (
            RiccatiSolver(params, settings)
            if settings.solver == "daqp" and RiccatiSolver.applies(params)
            else None
        )
        # The ticks the passes do not verify: an interior point with Riccati steps, as fast
        # and as well conditioned at any horizon (DAQP on the condensed QP is the last resort).
        self.interior: InteriorPointSolver | None = None
        # On the flywheel's viable-set boundary, the same on θmax 0.1 % larger (see plan()).
        self._relaxed: InteriorPointSolver | None = None
        if self.riccati is not None:
            self.interior = InteriorPointSolver(params, settings)
            wider = params.flywheel_angle_max * (1.0 + RELAXED)
            self._relaxed = InteriorPointSolver(
                dataclasses.replace(params, flywheel_angle_max=wider), settings,
                guide_centre=RELAXED_GUIDE_CENTRE,
            )  # fmt: skip
        self._qp: CondensedQP | None = None
        self._workspace: DaqpWorkspace | None = None
        self._use_workspace = settings.solver == "daqp"
        # The exact feasibility test, built (cached per flywheel, dt and N) on first need.
        self._feasibility: FlywheelFeasibility | None = None
        self.last_plan: Plan | None = None
        self._passes_failed = False  # whether the last tick's warm passes failed
        self._boundary = False  # whether the last tick was solved on S_N's boundary

    @property
    def qp(self) -> CondensedQP:
        """The condensed, pre-stabilised QP (built on first use)."""
        if self._qp is None:
            self._qp = shared_qp(self.params, self.settings)  # immutable, shared
        return self._qp

    @property
    def workspace(self) -> DaqpWorkspace | None:
        """The DAQP workspace of :attr:`qp` (built on first use); None: qpsolvers' route.

        Setting it to None routes every tick through ``qpsolvers.solve_qp`` (no Riccati
        passes either).
        """
        if self._workspace is None and self._use_workspace:
            try:
                self._workspace = DaqpWorkspace(self.qp)
            except (ImportError, RuntimeError):
                self._use_workspace = False  # an old daqp, or a setup it rejects
        return self._workspace

    @workspace.setter
    def workspace(self, value: DaqpWorkspace | None) -> None:
        self._workspace = value
        self._use_workspace = value is not None
        if value is None:
            self.riccati = None
            self.interior = self._relaxed = None

    @classmethod
    def option_names(cls) -> tuple[str, ...]:
        """Return ``settings`` and the fields of :class:`MPCSettings`."""
        return ("settings", *MPCSettings.__dataclass_fields__)

    def reset(self, state: NDArray[np.float64]) -> None:
        """Forget the last plan and the solver's warm start; the MPC is otherwise stateless."""
        self._check(state)
        self.last_plan = None
        self._passes_failed = self._boundary = False
        if self._workspace is not None:
            self._workspace.reset()
        if self.riccati is not None:
            self.riccati.reset()

    def plan(self, state: NDArray[np.float64]) -> Plan:
        """Solve the QP from ``state``; the fallback plan if it is infeasible."""
        riccati = self.riccati
        # Whether the previous tick was verified by the passes: DAQP did not solve it, and
        # riccati.active holds its optimal set (kept by a failed solve) to start DAQP from.
        previous_verified = riccati is not None and riccati.verified
        # After a tick the warm passes failed, the next one's usually fail too: a few passes,
        # then the interior point (PASSES_AFTER_FAILURE; docs/mpc.md, "The route's constants").
        passes = PASSES_AFTER_FAILURE if self._passes_failed else MAX_PASSES
        gauge = -1.0
        if self._boundary:
            # The last tick was on S_N's boundary, where the passes without full braking held
            # rarely verify the next tick (docs/mpc.md, "The route's constants"): when this one is
            # too, its route at once.
            gauge = self._gauge(state)
            if gauge >= 1.0 - INTERIOR_MARGIN:
                passes = 0
        self._passes_failed = riccati is not None and (
            passes == 0 or not riccati.solve(state, max_passes=passes)
        )
        if riccati is not None and not self._passes_failed:
            # Fresh arrays each verified solve: the plan keeps them as they are.
            self._boundary = False
            inputs = riccati.inputs
            return Plan(inputs[0], True, inputs, riccati.states)
        x0 = state.copy()  # the plan's own: the caller may reuse its array
        if gauge < 0.0:
            gauge = self._gauge(x0)
        self._boundary = gauge >= 1.0 - INTERIOR_MARGIN
        if self._use_workspace and gauge > 1.0 + BAND:
            # DAQP would fail, warm and then cold (up to ~1000 iterations): leave both solvers
            # as that failure would (cold next tick) without asking it.
            if self._workspace is not None:
                self._workspace.reset()
            if riccati is not None:
                riccati.reset()
            return self._fallback_plan(x0)
        if riccati is not None:
            plan = self._sparse_plan(riccati, x0, gauge, previous_verified)
            if plan is not None:
                return plan
        # Only the solvers' own failures mean "infeasible"; any other exception is a bug.
        workspace = self.workspace
        if workspace is not None:
            if riccati is not None and previous_verified:
                # As warm as if DAQP had solved the previous tick itself (it ends there).
                workspace.seed(riccati.active)
            solution = workspace.solve(state)
            active = workspace.active_set()
            if riccati is not None:
                # The next tick's passes start from DAQP's active set, or the empty one.
                if active is not None:
                    riccati.seed(active)
                else:
                    riccati.reset()
        else:
            solution = self._solve_qpsolvers(state)
        if solution is None or not np.isfinite(solution).all():
            return self._fallback_plan(x0)
        qp = self.qp
        scaled = solution.copy()
        return Plan(
            qp.first_input(x0, scaled),
            True,
            lambda: qp.inputs(x0, scaled),
            lambda: qp.predict(x0, scaled),
        )

    def _sparse_plan(
        self,
        riccati: RiccatiSolver,
        x0: NDArray[np.float64],
        gauge: float,
        previous_verified: bool,
    ) -> Plan | None:
        """Solve a tick the passes did not verify from their warm start, on the sparse QP.

        Inside S_N: the interior point, whose iterates' active sets the passes are offered to
        verify (its own solution if none verifies, e.g. the cycling late-horizon torques). On
        its boundary (γ ≥ 1 − BOUNDARY), where the feasible set has no interior: full braking
        held (:meth:`FlywheelFeasibility.forced_braking`), the passes from the active sets of
        the interior point on the problem with θmax 0.1 % larger (:data:`RELAXED`), which has
        an interior, then from the last tick's set. None: DAQP decides.
        """
        interior = self.interior
        if gauge < 1.0 - INTERIOR_MARGIN:
            if interior is None:
                return None
            forced = (0, 0)
        else:
            if self._feasibility is None or self._relaxed is None:
                return None
            forced = self._feasibility.forced_braking(x0)
            if not forced[0]:
                return None
            # The passes from the last set come after the relaxed interior point, not before:
            # tried first they rarely verify a boundary tick and cost time on each (docs/mpc.md,
            # "The route's constants").
            interior = self._relaxed

        def verify(active: NDArray[np.int8]) -> bool:
            riccati.seed(active)
            return riccati.solve(x0, shift=False, max_passes=POLISH_PASSES, forced=forced)

        # Warm from the last tick's plan (its inputs computed if they were left lazy) and, if
        # the passes verified it, its active set (the failed warm passes leave it in place).
        last = self.last_plan
        warm = last.inputs if last is not None and last.feasible else None
        start = riccati.active.copy()  # the last tick's set (the failed passes keep it)
        guide = start if warm is not None and previous_verified else None
        if interior.solve(x0, verify, warm, guide):
            if interior.verified:
                return Plan(riccati.inputs[0], True, riccati.inputs, riccati.states)
            if interior is self.interior:
                riccati.seed(interior.active_set())  # the next tick's start
                return Plan(interior.inputs[0], True, interior.inputs, interior.states)
        if forced[0]:  # on the boundary: the passes from the last tick's set, braking held
            riccati.seed(start)
            if riccati.solve(x0, max_passes=POLISH_PASSES, forced=forced):
                return Plan(riccati.inputs[0], True, riccati.inputs, riccati.states)
        riccati.reset()
        return None

    def _gauge(self, x0: NDArray[np.float64]) -> float:
        """Return the gauge of (θ, θ̇) of x0 in S_N (:class:`FlywheelFeasibility`).

        0 where the test does not apply (no interior): the solvers decide.
        """
        feasibility = self._feasibility
        if feasibility is None:
            if not FlywheelFeasibility.applies(self.params):
                return 0.0
            feasibility = self._feasibility = FlywheelFeasibility(self.params, self.settings)
        return feasibility.gauge(x0)

    def _fallback_plan(self, x0: NDArray[np.float64]) -> Plan:
        """Return the infeasible tick's plan: the fallback over the horizon, states on demand."""
        fallback = self._fallback(x0)
        inputs = np.tile(fallback, (self.settings.horizon, 1))
        return Plan(fallback, False, inputs, lambda: self.qp.simulate(x0, inputs))

    def _solve_qpsolvers(self, state: NDArray[np.float64]) -> NDArray[np.float64] | None:
        from qpsolvers import solve_qp
        from qpsolvers.exceptions import ProblemError, SolverError

        qp = self.qp
        q, lower, upper = qp.vectors(state)
        rows = qp.scaled_inequality
        # The workspace's tolerance for DAQP here too: its default (1e-6) is not exact.
        options: dict[str, Any] = (
            {"primal_tol": PRIMAL_TOL} if self.settings.solver == "daqp" else {}
        )
        try:
            solution: NDArray[np.float64] | None = solve_qp(
                np.array(qp.scaled_hessian),  # writable: quadprog refuses read-only buffers
                q,
                np.vstack([rows, -rows]),
                np.concatenate([upper, -lower]),
                solver=self.settings.solver,
                **options,
            )
        except (ProblemError, SolverError):
            return None
        return solution

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """First input of the plan from ``state`` (δ [m], τ [N m])."""
        plan = self.last_plan = self.plan(np.asarray(state, dtype=np.float64))
        cop, torque = plan.first_input.tolist()
        p = self.params
        # Clip what the solver's tolerance may leave a hair outside the limits (as
        # BodyParams.clip_cop and clip_hip_torque, inlined: this is the tick's hot path).
        heel, toe, limit = p.heel, p.toe, p.torque_max
        cop = min(toe, max(heel, cop))
        torque = min(limit, max(-limit, torque))
        at_limit = cop == heel or cop == toe or (limit > 0.0 and abs(torque) >= limit * (1 - 1e-9))
        return Command(cop, torque, at_limit or not plan.feasible)

    def _fallback(self, state: NDArray[np.float64]) -> NDArray[np.float64]:
        p = self.params
        capture = state[0] + state[2] / p.omega
        cop = p.clip_cop(capture)
        rate = state[3]
        torque = -math.copysign(p.torque_max, rate) if rate != 0.0 else 0.0
        return np.array([cop, torque])

    def _check(self, state: NDArray[np.float64]) -> None:
        if np.shape(state) != (4,):
            raise InvalidParameterError(
                f"the mpc controller needs the flywheel state [x, theta, xdot, theta_dot], "
                f"got shape {np.shape(state)}"
            )
