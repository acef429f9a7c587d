"""The receding-horizon controller: solve the QP each tick, apply the first input."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command, Controller, register
from pushrecovery.control.mpc.plan import Plan
from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.control.mpc.qp import CondensedQP
from pushrecovery.control.mpc.workspace import PRIMAL_TOL, DaqpWorkspace
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import FLYWHEEL_STATE
from pushrecovery.params import BodyParams

__all__ = ["MPCController"]


@register
class MPCController(Controller):
    """Receding-horizon CMP balancing (Eqs. 16-17), the paper's settings by default.

    Each tick solves the condensed QP (:class:`CondensedQP`) from the measured state
    ``[x, θ, ẋ, θ̇]`` and returns its first input. If the QP is infeasible (the flywheel cannot
    avoid its joint limit) the command is a saturated fallback, ``saturated=True``, and
    ``last_plan.feasible`` is False: CoP at the capture point clipped to the foot, full torque
    braking the flywheel. It never raises inside the loop.

    With the default ``daqp`` solver the QP lives in a DAQP workspace (:class:`DaqpWorkspace`,
    the attribute ``workspace``), set up once and warm-started from the previous tick's active
    set: the same solution up to rounding, roughly ten times faster than through qpsolvers.
    Other solvers, or ``workspace = None``, go through ``qpsolvers.solve_qp``.

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
        self.qp = CondensedQP(params, settings)
        self.workspace: DaqpWorkspace | None = None
        if settings.solver == "daqp":
            try:
                self.workspace = DaqpWorkspace(self.qp)
            except (ImportError, RuntimeError):
                pass  # an old daqp or a setup it rejects: qpsolvers' route still works
        self.last_plan: Plan | None = None

    @classmethod
    def option_names(cls) -> tuple[str, ...]:
        """Return ``settings`` and the fields of :class:`MPCSettings`."""
        return ("settings", *MPCSettings.__dataclass_fields__)

    def reset(self, state: NDArray[np.float64]) -> None:
        """Forget the last plan and the solver's warm start; the MPC is otherwise stateless."""
        self._check(state)
        self.last_plan = None
        if self.workspace is not None:
            self.workspace.reset()

    def plan(self, state: NDArray[np.float64]) -> Plan:
        """Solve the QP from ``state``; the fallback plan if it is infeasible."""
        qp = self.qp
        # Only the solvers' own failures mean "infeasible"; any other exception is a bug.
        if self.workspace is not None:
            solution = self.workspace.solve(state)
        else:
            solution = self._solve_qpsolvers(state)
        x0 = state.copy()  # the plan's own: the caller may reuse its array
        if solution is None or not np.isfinite(solution).all():
            fallback = self._fallback(x0)
            inputs = lambda: np.tile(fallback, (self.settings.horizon, 1))  # noqa: E731
            return Plan(fallback, False, inputs, lambda: qp.simulate(x0, inputs()))
        scaled = solution.copy()
        return Plan(
            qp.first_input(x0, scaled),
            True,
            lambda: qp.inputs(x0, scaled),
            lambda: qp.predict(x0, scaled),
        )

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
                qp.scaled_hessian,
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
        plan = self.plan(np.asarray(state, dtype=np.float64))
        self.last_plan = plan
        cop, torque = plan.first_input
        p = self.params
        # Clip what the solver's tolerance may leave a hair outside the limits.
        cop, torque = p.clip_cop(float(cop)), p.clip_hip_torque(float(torque))
        at_limit = cop in (p.heel, p.toe) or (
            p.torque_max > 0.0 and abs(torque) >= p.torque_max * (1 - 1e-9)
        )
        return Command(cop, torque, saturated=at_limit or not plan.feasible)

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
