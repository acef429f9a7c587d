"""Figures. The only package that imports matplotlib (always with the Agg backend)."""
