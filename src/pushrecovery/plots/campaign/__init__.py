"""Plots of a push campaign: the outcome map over the swept plane, critical push vs a parameter.

The outcome map draws one marker per push at (x0, ẋ), coloured by the strategy the run used,
over the analytic boundaries: the capture-point lines x0 + ẋ/ω = edge of the CoP region (Eq. 4)
and of the CMP region (corrected Eq. 15), and the single-step limit of Sec. IV.
"""

from pushrecovery.plots.campaign.maps import plot_outcome_map, plot_strategy_map
from pushrecovery.plots.campaign.style import STEP_COLOUR, STRATEGY_COLOURS, UNITS, step_limit_curve
from pushrecovery.plots.campaign.sweeps import plot_critical_vs_parameter

__all__ = [
    "STEP_COLOUR",
    "STRATEGY_COLOURS",
    "UNITS",
    "plot_critical_vs_parameter",
    "plot_outcome_map",
    "plot_strategy_map",
    "step_limit_curve",
]
