"""Push campaigns: sweeps of pushes over starts, push sizes and body parameters, at scale.

:class:`CampaignSpec` says what to push (:mod:`.spec`), :func:`run_campaign` runs it on this
process, local processes or a Dask cluster with resumable per-batch files (:mod:`.execute`),
each push recorded as one row (:mod:`.pushes`) and summarised (:mod:`.summary`).
"""

from pushrecovery.campaign.execute import (
    CampaignError,
    CampaignResult,
    missing_batches,
    read_spec,
    run_campaign,
)
from pushrecovery.campaign.spec import CampaignSpec, Push, value_range
from pushrecovery.campaign.summary import summarize

__all__ = [
    "CampaignError",
    "CampaignResult",
    "CampaignSpec",
    "Push",
    "missing_batches",
    "read_spec",
    "run_campaign",
    "summarize",
    "value_range",
]
