"""Push a nonlinear pendulum under saturated PD ankle control; find its critical push."""

import numpy as np

from pushrecovery import load_params
from pushrecovery.control import make_controller
from pushrecovery.sim.critical import critical_push
from pushrecovery.sim.push import Push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate

params = load_params()
push = Push.from_impulse(25.0, params.mass)  # a 25 N s shove forward at the CoM
result = simulate(
    make_plant("pendulum", params),
    make_controller("ankle-pd", params),
    np.array([0.0, push.delta_velocity]),
)
print(result.outcome.value, f"after {result.time[-1]:.2f} s, peak CoP {result.cops.max():.3f} m")

found = critical_push(params, "pendulum", "ankle-pd", 0.0, "forward")
print(
    f"critical push: {found.velocity:.4f} m/s ({params.mass * found.velocity:.1f} N s), "
    f"Eq. (4) predicts {found.predicted_velocity:.4f} m/s ({found.relative_error():+.2%})"
)
