"""
Running a campaign: one task per run on Dask's distributed scheduler, resumable, on record.

Each run is a task (:func:`run_one`) that draws its values, checks each took,
flies and returns its record; the caller's process stores each record as it
comes (``runs/run_NNNNNN.npz``, written to a temporary name and renamed, so a
killed campaign leaves whole files only). Started again with the same file, a
campaign runs only the runs that have no record; records of another
configuration in the same folder are refused. A run that raises is recorded
with its error and its drawn values, and the campaign goes on.

Where: ``workers=N`` starts a ``distributed.LocalCluster`` of N single-threaded
worker processes on this machine (the default: one per core);
``scheduler='tcp://host:port'`` uses a running cluster's scheduler, whose workers
must have this package installed; ``workers=0`` runs in this process without
Dask (tests, debugging). A LocalCluster listens on loopback only, its
dashboard on a free port. Dask rather than Ray: Dask's distributed is pure
Python, packaged by Debian and Ubuntu (python3-distributed), starts a
LocalCluster in a second, and needs nothing but its scheduler's address to
move to a cluster.
"""

import json
import math
import os
import time
import traceback

import numpy as np

from .config import build
from .dispersions import same_value
from .scenario import node_values, NODES, nodes_of, pointing_errors, READBACK, Run
from ..optional import require
from ..physics.analysis.motion import attitude_nees
from ..ros.parameters import ConfigurationError

#: The record's arrays of one run (over the record times), besides ``t``.
ARRAYS = ('q_true', 'q_estimate', 'covariance', 'omega', 'bias_true', 'bias_estimate',
          'torque', 'errors', 'nees', 'pointing')
#: Seconds between two progress lines.
PROGRESS_EVERY = 10.0


class DispersionNotApplied(RuntimeError):
    """A run's engine does not hold the value its dispersion drew."""


def job_of(campaign):
    """Return what a task needs to rebuild the campaign: its keys, the scenario inline."""
    return dict(campaign.values, scenario=campaign.scenario, output=None)


def draws(campaign, index):
    """Return run ``index``'s drawn values: {(node or None, name): value}."""
    return {(d.node, d.name): d.draw(campaign.seed, index) for d in campaign.dispersions}


def _label(node, name):
    return name if node is None else f'{node}.{name}'


def run_one(job, index):
    """
    Draw, check and fly run ``index`` of the campaign ``job`` (:func:`job_of`).

    Returns the run's record: ``index``, ``status`` ('ok' or 'failed'),
    ``error`` (the reason, or ''), ``drawn`` {label: value} and ``applied``
    (the values read back from the run), ``wall`` (s), and, when it flew, the
    arrays of ARRAYS and ``t``. Never raises for a run's own failure.
    """
    start = time.perf_counter()
    campaign = build(job)
    drawn = draws(campaign, index)
    record = {'index': int(index), 'status': 'failed', 'error': '',
              'drawn': {_label(*k): v for k, v in drawn.items()}, 'applied': {}}
    try:
        run = _make_run(campaign, drawn)
        for (node, name), value in drawn.items():
            for n in nodes_of(node, name):
                applied = READBACK[n][name](run)
                applied = int(applied) if isinstance(value, int) else \
                    [float(c) for c in np.atleast_1d(applied)]
                record['applied'][f'{n}.{name}'] = applied
                if not same_value(value, applied[0] if isinstance(value, float) else applied):
                    raise DispersionNotApplied(
                        f'{name} on {n}: drew {value!r}, the run holds {applied!r}')
        flown = run.fly(campaign.duration, campaign.record_period)
        flown['errors'], flown['nees'] = attitude_nees(flown['q_true'], flown['q_estimate'],
                                                       flown['covariance'])
        flown['pointing'] = pointing_errors(
            flown['q_true'], run.values['attitude_controller']['target_orientation'])
        record['counts'] = flown.pop('counts')
        record.update(flown)
        record['status'] = 'ok'
    except Exception as err:    # a run's failure is recorded, and the campaign goes on
        record['error'] = f'{type(err).__name__}: {err}'
        if not isinstance(err, (ConfigurationError, DispersionNotApplied)):
            record['traceback'] = traceback.format_exc()
    record['wall'] = time.perf_counter() - start
    return record


def _make_run(campaign, drawn):
    """Return the Run of the scenario with run's drawn values in place."""
    extra = {n: {} for n in NODES}
    for (node, name), value in drawn.items():
        for n in nodes_of(node, name):
            extra[n][name] = value
    extra['attitude_simulator']['lockstep'] = True
    values = {n: NODES[n].validate(node_values(campaign.scenario, n, extra[n])) for n in NODES}
    return Run(values['attitude_simulator'], values['attitude_estimator'],
               values['attitude_controller'], campaign.control_on)


# ---------------------------------------------------------------------------- storage
def run_path(output, index):
    """Return the path of run ``index``'s record in the folder ``output``."""
    return os.path.join(output, 'runs', f'run_{index:06d}.npz')


def save(output, record):
    """Store one run's record (npz: its arrays, and 'meta' as JSON); whole or not at all."""
    path = run_path(output, record['index'])
    meta = {k: v for k, v in record.items() if k not in ARRAYS and k != 't'}
    arrays = {k: record[k] for k in ('t',) + ARRAYS if k in record}
    tmp = path + '.part'
    with open(tmp, 'wb') as f:
        np.savez(f, meta=np.array(json.dumps(meta, sort_keys=True)), **arrays)
    os.replace(tmp, path)


def load_record(path):
    """Return a stored record (the dict :func:`run_one` returned)."""
    with np.load(path) as data:
        record = json.loads(str(data['meta']))
        record.update({k: data[k] for k in data.files if k != 'meta'})
    return record


def _prepare(campaign):
    """Make the output folder; refuse one that holds another campaign's runs."""
    out = campaign.output
    os.makedirs(os.path.join(out, 'runs'), exist_ok=True)
    manifest = os.path.join(out, 'campaign.json')
    if os.path.exists(manifest):
        with open(manifest, encoding='utf-8') as f:
            digest = json.load(f).get('digest')
        if digest != campaign.digest:   # (the number of runs may differ: a campaign grows)
            raise ConfigurationError(
                f'{out} holds the runs of another campaign (its configuration differs): give '
                'another output, or remove the folder to start again')
    else:
        with open(manifest, 'w', encoding='utf-8') as f:
            json.dump({'digest': campaign.digest, 'runs': campaign.runs,
                       'configuration': job_of(campaign)}, f, indent=1, sort_keys=True,
                      default=str)


def missing_runs(campaign):
    """Return the indices of the runs that have no record yet."""
    return [i for i in range(campaign.runs) if not os.path.exists(run_path(campaign.output, i))]


# ---------------------------------------------------------------------------- running
class Progress:
    """Lines of progress: runs done and failed, the rate and the time left."""

    def __init__(self, total, done, say=print, every=PROGRESS_EVERY, clock=time.monotonic):
        self.total, self.done, self.failed = total, done, 0
        self.new = 0
        self.say, self.every, self.clock = say, every, clock
        self.start = self._last = clock()

    def add(self, record):
        """Count a finished run; say a line every ``every`` s and at the last run."""
        self.done += 1
        self.new += 1
        if record['status'] != 'ok':
            self.failed += 1
            self.say(f'campaign: run {record["index"]} failed: {record["error"]}')
        now = self.clock()
        if now - self._last >= self.every or self.done == self.total:
            self._last = now
            self.say(self.line(now))

    def line(self, now=None):
        """Return the progress line now."""
        elapsed = (now if now is not None else self.clock()) - self.start
        rate = self.new / elapsed if elapsed > 0 else math.nan
        left = (self.total - self.done) / rate if rate > 0 else math.nan
        eta = '' if self.done == self.total or not math.isfinite(left) else \
            f', about {left:.0f} s left'
        return (f'campaign: {self.done}/{self.total} runs done ({self.failed} failed), '
                f'{rate:.2f} runs/s{eta}')


def run_campaign(campaign, workers=None, scheduler=None, say=print):
    """
    Run the runs of ``campaign`` that have no record; store each as it comes.

    ``workers``: local worker processes (None: one per core; 0: in this process,
    without Dask); ``scheduler``: a Dask scheduler's address instead. Returns the
    number of runs that ran now.
    """
    _prepare(campaign)
    todo = missing_runs(campaign)
    if len(todo) < campaign.runs:
        say(f'campaign: {campaign.runs - len(todo)} of {campaign.runs} runs already recorded in '
            f'{campaign.output}; running the {len(todo)} missing')
    progress = Progress(campaign.runs, campaign.runs - len(todo), say)
    job = job_of(campaign)
    if not todo:
        return 0
    if workers == 0 and scheduler is None:
        for index in todo:
            record = run_one(job, index)
            save(campaign.output, record)
            progress.add(record)
        return len(todo)
    require('distributed')
    from distributed import as_completed, Client, LocalCluster
    cluster = None
    # a LocalCluster sets its workers' environment (OMP_NUM_THREADS, PYTHONHASHSEED, ...) in
    # this process's os.environ: the caller's is put back afterwards
    environment = dict(os.environ)
    if scheduler is None:
        n = workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               host='127.0.0.1', dashboard_address='127.0.0.1:0')
        client = Client(cluster)
        say(f'campaign: {len(todo)} runs on a local Dask cluster of {n} worker processes')
    else:
        client = Client(scheduler)
        say(f'campaign: {len(todo)} runs on the Dask scheduler at {scheduler} '
            f'({len(client.scheduler_info()["workers"])} workers)')
    try:
        futures = {client.submit(run_one, job, index, key=f'run-{campaign.digest}-{index}',
                                 pure=False): index for index in todo}
        for future in as_completed(futures):
            index = futures[future]
            try:
                record = future.result()
            except Exception as err:   # the worker died: record it, go on
                record = {'index': index, 'status': 'failed', 'drawn': {}, 'applied': {},
                          'error': f'the task failed on its worker: {type(err).__name__}: '
                                   f'{err}', 'wall': math.nan}
            save(campaign.output, record)
            progress.add(record)
            future.release()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
        os.environ.clear()
        os.environ.update(environment)
    return len(todo)
