"""Analyse a measured trial: per-frame capture point, margins, strategy and step, and a summary.

The pipeline (docs/analysis.md):

1. Force-plate signals (ground reaction force, CoP): short gaps interpolated, zero-lag
   Butterworth low-pass at ``force_cutoff`` (:mod:`~pushrecovery.analysis.signals`).
2. CoM: from the file (markers or CSV columns), gaps repaired, low-pass at ``cutoff`` and
   differentiated; or, with force plates only, by zero-point-to-zero-point integration of the
   horizontal force (:mod:`~pushrecovery.analysis.zero_point`), at the force-plate rate.
3. Base of support per frame: from foot markers, from CSV columns, or two fixed feet
   (:mod:`~pushrecovery.analysis.recording`).
4. Per axis (ap, ml): capture point, CoP / CMP / step margins, strategy, time to leave the
   regions, recommended step (:mod:`~pushrecovery.analysis.margins`); the frame's strategy is
   the more demanding of the two axes.
"""

from pushrecovery.analysis.trial.pipeline import analyze
from pushrecovery.analysis.trial.settings import AnalysisSettings, TrialAnalysis, body_for
from pushrecovery.analysis.trial.summary import TrialSummary

__all__ = [
    "AnalysisSettings",
    "TrialAnalysis",
    "TrialSummary",
    "analyze",
    "body_for",
]
