"""Figures: the only package that imports matplotlib.

It draws on ``matplotlib.figure.Figure`` objects outside pyplot, so it never changes the
caller's backend (no ``matplotlib.use``) and leaves nothing to close.
"""
