"""Experiments: runs of the simulator that figures, the report and validation need."""
