"""
A Monte Carlo campaign's throughput on Dask: 1000 runs against the ideal of one run's cost.

doc/examples/campaign.yaml: the example MEKF of doc/examples/estimator.yaml (gyro at 20 Hz,
star tracker at 5 Hz, the body integrated at 100 Hz), 600 s simulated per run, the initial
attitude, rate and noise seed dispersed. One run's cost: the mean of 20 runs flown one after
another in one process, nothing else running. Then 1000 runs on a LocalCluster of 2
single-threaded worker processes (rigid_body_campaign's default here: one per core), from
its start to the last record stored; the ideal is one run's cost times 1000 over 2 cores.
The records of the first 20 runs of the campaign are compared with the serial ones, bit for
bit. ``./dev bench --only campaign``.
"""

import os
import shutil
import tempfile
import time

import numpy as np
from rigid_body_dynamics.campaign import gather, judge, load, run_campaign
from rigid_body_dynamics.campaign.runner import job_of, load_record, run_one, run_path

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLE = os.path.join(HERE, '..', 'doc', 'examples', 'campaign.yaml')
RUNS, SERIAL, WORKERS = 1000, 20, 2


def measure():
    """Return RESULTS.md lines: one run's cost, the campaign's wall time and efficiency."""
    folder = tempfile.mkdtemp(prefix='campaign-bench-')
    try:
        campaign = load(EXAMPLE)
        campaign.values['runs'] = RUNS
        campaign.output = os.path.join(folder, 'out')
        job = job_of(campaign)
        start = time.perf_counter()
        serial = [run_one(job, i) for i in range(SERIAL)]
        one = (time.perf_counter() - start) / SERIAL
        start = time.perf_counter()
        run_campaign(campaign, workers=WORKERS, say=lambda line: None)
        wall = time.perf_counter() - start
        ens = gather(campaign.output)
        same = all(np.array_equal(load_record(run_path(campaign.output, i))[key], serial[i][key])
                   for i in range(SERIAL) for key in ('q_true', 'q_estimate', 'covariance'))
        found = judge(campaign, ens).anees
        ideal = one * RUNS / WORKERS
        return [
            '| quantity | value |', '| --- | --- |',
            f'| one run flown alone (mean of {SERIAL}) | {one:.3f} s |',
            f'| {RUNS} runs on a LocalCluster of {WORKERS} workers | {wall:.1f} s |',
            f'| ideal ({RUNS} x one run / {WORKERS} cores) | {ideal:.1f} s |',
            f'| efficiency (ideal / measured) | {100.0 * ideal / wall:.1f} % |',
            f'| runs flown / failed | {len(ens.flown)} / {len(ens.failed)} |',
            f'| first {SERIAL} records equal to the serial runs, bit for bit | '
            f'{"yes" if same else "NO"} |',
            f'| ANEES verdict ({found.runs} runs, from {campaign.judge_from:g} s) | '
            f'{found.verdict}, {100.0 * found.share_inside:.1f} % of times inside the '
            f'{100.0 * found.level:g} % bounds |']
    finally:
        shutil.rmtree(folder, ignore_errors=True)
