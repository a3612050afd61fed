"""Loaded at start-up by every Python process whose PYTHONPATH holds this folder (the command of
``test_killed_command_resumes``, or of ``test_study``'s killed study, and its pool workers).

Each worker runs its first simulation and then holds its next one until it is stopped, so the
signal the test sends once the first run is stored certainly finds the campaign unfinished, on
a machine of any speed. The resumed command runs without this folder.
"""

from __future__ import annotations

import time

import hexadyn.montecarlo.execution as execution

_real_simulate_run = execution.simulate_run
_runs_in_this_process = 0


def simulate_run(scenario, overrides, *entries):
    """The per-walk function of campaigns and studies (pickled by reference to this module for
    the workers)."""
    global _runs_in_this_process
    _runs_in_this_process += 1
    if _runs_in_this_process > 1:
        while True:
            time.sleep(1.0)
    return _real_simulate_run(scenario, overrides, *entries)


execution.simulate_run = simulate_run
