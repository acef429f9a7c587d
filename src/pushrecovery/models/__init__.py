"""Dynamics of the simple balance models, with their closed forms (no simulator code here)."""
