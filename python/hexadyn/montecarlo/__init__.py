"""Monte Carlo campaigns over the joint friction uncertainty (thesis Section 6.5, Table 6.7,
Table 6.8, Fig. 6.20)::

    from hexadyn.montecarlo import run_campaign
    table = run_campaign("results/mc", runs_per_velocity=50)   # resumes if interrupted
    table[["variant", "velocity_m_s", "specific_resistance_mean", "specific_resistance_std"]]
    run_campaign("results/mc_phantomx", "phantomx_montecarlo", runs_per_velocity=50)   # the PhantomX

Modules: :mod:`~hexadyn.montecarlo.sampling` (truncated Gaussian draws per run),
:mod:`~hexadyn.montecarlo.storage` (``campaign.json`` and the SQLite database of runs),
:mod:`~hexadyn.montecarlo.execution` (process pool or Ray), :mod:`~hexadyn.montecarlo.tables`
(Table 6.8 and Fig. 6.20) and :mod:`~hexadyn.montecarlo.campaign` (the campaign itself).
"""

from hexadyn.montecarlo.campaign import DEFAULT_SCENARIO, DEFAULT_SCENARIOS, VARIANTS, Campaign, run_campaign, study_tables
from hexadyn.montecarlo.sampling import FrictionDistributions, draw_friction
from hexadyn.montecarlo.storage import CampaignStore, RunKey

__all__ = [
    "DEFAULT_SCENARIO",
    "DEFAULT_SCENARIOS",
    "VARIANTS",
    "Campaign",
    "CampaignStore",
    "FrictionDistributions",
    "RunKey",
    "draw_friction",
    "run_campaign",
    "study_tables",
]
