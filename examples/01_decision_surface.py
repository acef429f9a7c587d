"""Classify CoM states with Eq. (4): one state, then a million at once."""

import numpy as np

from pushrecovery import load_params
from pushrecovery.surfaces.classify import classify
from pushrecovery.surfaces.cop import cop_margin, critical_velocity

params = load_params()  # the built-in "paper" preset: 72 kg, L = 1 m, foot [-0.05, 0.15] m

# One state: CoM above the ankle, moving forward at 0.3 m/s.
print(classify(0.0, 0.3, params).to_dict())

# The largest forward and backward velocity the ankle alone can absorb from x = 0 (Eq. 4).
print("critical velocities [m/s]:", critical_velocity(0.0, [1.0, -1.0], params))

# A million states: signed margins [m], positive inside the CoP-balancing region.
rng = np.random.default_rng(0)
x = rng.uniform(params.heel, params.toe, 1_000_000)
xdot = rng.normal(0.0, 0.3, 1_000_000)
margin = cop_margin(x, xdot, params)
print(f"fraction recoverable by the ankle strategy: {np.mean(margin > 0):.3f}")
