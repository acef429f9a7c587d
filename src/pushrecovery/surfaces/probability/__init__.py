"""The strategy a state needs, as probabilities: an uncertain state, latency and body.

:mod:`.inputs` (a Gaussian state estimate), :mod:`.latency` (the capture point moving on
during a loop's latency), :mod:`.body` (a spread of the body's parameters), :mod:`.regions`
(the verdict regions and a Gaussian's masses on them), :mod:`.results` (the typed results),
:mod:`.verdicts` (the probability of each verdict: exact Gaussian masses of the regions,
averaged over the body by quasi-Monte Carlo), :mod:`.margins` (quantiles of the CoP and CMP
margins), :mod:`.monitor` (the probabilities tick after tick) and :mod:`.scores`
(reliability and Brier score against outcomes).
docs/uncertainty.md derives and checks them.
"""

from pushrecovery.surfaces.probability.body import TRUNCATION, BodySpread
from pushrecovery.surfaces.probability.inputs import StateGaussian, check_states
from pushrecovery.surfaces.probability.latency import (
    LATENCY_NODES,
    MAX_LATENCY_GROWTH,
    delayed_capture_point,
    latency_growth,
    latency_nodes,
)
from pushrecovery.surfaces.probability.margins import SIDES, MarginQuantiles, margin_quantiles
from pushrecovery.surfaces.probability.monitor import MonitorProbabilities, ProbabilityMonitor
from pushrecovery.surfaces.probability.results import ProbabilityTable, VerdictProbabilities
from pushrecovery.surfaces.probability.scores import brier_score, reliability
from pushrecovery.surfaces.probability.verdicts import (
    ankle_probability,
    verdict_probabilities,
    verdict_probability_table,
)

__all__ = [
    "LATENCY_NODES",
    "MAX_LATENCY_GROWTH",
    "SIDES",
    "TRUNCATION",
    "BodySpread",
    "MarginQuantiles",
    "MonitorProbabilities",
    "ProbabilityMonitor",
    "ProbabilityTable",
    "StateGaussian",
    "VerdictProbabilities",
    "ankle_probability",
    "brier_score",
    "check_states",
    "delayed_capture_point",
    "latency_growth",
    "latency_nodes",
    "margin_quantiles",
    "reliability",
    "verdict_probabilities",
    "verdict_probability_table",
]
