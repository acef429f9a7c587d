"""The receding-horizon controller: solve the QP each tick, apply the first input."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.base import Command, Controller, register
from pushrecovery.control.mpc.plan import Plan, Status
from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.control.mpc.qp import CondensedQP
from pushrecovery.control.mpc.solvers.interior import InteriorPointSolver
from pushrecovery.control.mpc.solvers.riccati import RiccatiSolver
from pushrecovery.control.mpc.solvers.route import Route
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import FLYWHEEL_STATE
from pushrecovery.params import BodyParams

__all__ = ["MPCController"]

_INFEASIBLE = Status.INFEASIBLE  # a module global: an enum member through its class costs ~0.1 µs


@register
class MPCController(Controller):
    """Receding-horizon CMP balancing (Eqs. 16-17), the paper's settings by default.

    Each tick solves Eq. (17) exactly from the measured state ``[x, θ, ẋ, θ̇]`` and returns its
    first input. If the QP is infeasible (the flywheel cannot avoid its joint limit) the
    command is a saturated fallback, ``saturated=True``, and ``last_plan.feasible`` is False:
    CoP at the capture point clipped to the foot, full torque braking the flywheel. It never
    raises inside the loop.

    With ``realtime=True`` each tick's work is bounded by a fixed budget of passes and
    iterations; a tick it does not solve applies the last verified plan shifted by one stage per
    tick since (``last_plan.status`` is ``Status.SHIFTED``; ``Status.EXHAUSTED``, the fallback,
    when there is none). docs/mpc.md, "The real-time mode".

    Each tick is solved by :meth:`Route.solve <pushrecovery.control.mpc.solvers.route.Route.solve>`
    of the controller's route (the attribute ``route``: its solvers, the order they are tried
    in); docs/mpc.md describes it, docs/performance.md has its timings.

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    settings : MPCSettings, optional
        Horizon, weights, γ, dt, solver and the real-time mode; keyword overrides of the
        defaults may be passed instead (``dt=``, ``horizon=``, ``realtime=``, ...).
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
        if settings is not None:
            require_type("settings", settings, MPCSettings)
        settings = settings or MPCSettings(**overrides)
        from qpsolvers import available_solvers

        if settings.solver not in available_solvers:
            raise InvalidParameterError(
                f"solver must be one of {sorted(available_solvers)}, got {settings.solver!r}"
            )
        self.settings = settings
        self.control_period = settings.dt
        self.route = Route(params, settings)
        self.last_plan: Plan | None = None

    @property
    def qp(self) -> CondensedQP:
        """The condensed, pre-stabilised QP (built on first use)."""
        return self.route.qp

    @property
    def riccati(self) -> RiccatiSolver | None:
        """The Riccati passes of the route (None: not on this route)."""
        return self.route.riccati

    @property
    def interior(self) -> InteriorPointSolver | None:
        """The interior point of the route (None: not on this route)."""
        return self.route.interior

    @classmethod
    def option_names(cls) -> tuple[str, ...]:
        """Return ``settings`` and the fields of :class:`MPCSettings`."""
        return ("settings", *MPCSettings.__dataclass_fields__)

    def reset(self, state: NDArray[np.float64]) -> None:
        """Forget the last plan and the solvers' warm starts; the MPC is otherwise stateless."""
        self._check(state)
        self.last_plan = None
        self.route.reset()

    def plan(self, state: NDArray[np.float64]) -> Plan:
        """Solve the QP from ``state``; the fallback plan if it is infeasible."""
        return self.route.solve(state, self.last_plan)

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """First input of the plan from ``state`` (δ [m], τ [N m])."""
        state = np.asarray(state, dtype=np.float64)
        plan = self.last_plan = self.route.solve(state, self.last_plan)  # as plan(), inlined
        cop, torque = plan.first_input.tolist()
        p = self.params
        # Clip what the solver's tolerance may leave a hair outside the limits (as
        # BodyParams.clip_cop and clip_hip_torque, inlined: this is the tick's hot path).
        heel, toe, limit = p.heel, p.toe, p.torque_max
        cop = min(toe, max(heel, cop))
        torque = min(limit, max(-limit, torque))
        at_limit = cop == heel or cop == toe or (limit > 0.0 and abs(torque) >= limit * (1 - 1e-9))
        # Saturated: at a limit, or the fallback of an infeasible QP.
        return Command(cop, torque, at_limit or plan.status is _INFEASIBLE)

    def _check(self, state: NDArray[np.float64]) -> None:
        if np.shape(state) != (4,):
            raise InvalidParameterError(
                f"the mpc controller needs the flywheel state [x, theta, xdot, theta_dot], "
                f"got shape {np.shape(state)}"
            )
