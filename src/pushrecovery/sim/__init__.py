"""Simulators: plants (the models behind one small protocol), pushes, outcomes, campaigns."""
