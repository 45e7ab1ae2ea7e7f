"""
A campaign's results: the runs' records gathered, judged as an ensemble, written as tables.

:func:`gather` stacks the records of the runs that flew; :func:`judge` runs the
ensemble analysis of ``physics/analysis/ensemble.py`` on them; :func:`write`
puts ``runs.csv`` (one row per run: status, error, drawn values, final
pointing error, settling time, mean NEES), ``ensemble.csv`` (one row per record
time: ANEES and its bounds, the RMS error against the mean reported sigma,
the pointing error's percentiles) and ``report.html`` in the campaign's folder.
"""

from dataclasses import dataclass
import glob
import math
import os

import numpy as np

from .runner import load_record
from ..physics.analysis import ensemble


@dataclass
class Ensemble:
    """The records of a campaign: ``records`` (all, by index) and stacked arrays of the flown."""

    records: list
    t: np.ndarray
    arrays: dict

    @property
    def flown(self):
        """Return the records of the runs that flew."""
        return [r for r in self.records if r['status'] == 'ok']

    @property
    def failed(self):
        """Return the records of the runs that failed."""
        return [r for r in self.records if r['status'] != 'ok']


def gather(output):
    """Return the :class:`Ensemble` of the records in the campaign folder ``output``."""
    paths = sorted(glob.glob(os.path.join(output, 'runs', 'run_*.npz')))
    records = [load_record(p) for p in paths]
    flown = [r for r in records if r['status'] == 'ok']
    arrays = {}
    if flown:
        for key in ('covariance', 'errors', 'nees', 'pointing'):
            arrays[key] = np.stack([r[key] for r in flown])
    return Ensemble(records, flown[0]['t'] if flown else np.zeros(0), arrays)


@dataclass
class Judgement:
    """The ensemble's findings (times from ``judge_from``) and per-run figures."""

    anees: object
    times: np.ndarray
    rms: np.ndarray
    sigma: np.ndarray
    pointing: dict
    settling: np.ndarray
    settling_percentiles: dict


def judge(campaign, ens):
    """Return the :class:`Judgement` of ``ens`` by the campaign's keys (needs >= 2 flown runs)."""
    if len(ens.flown) < 2:
        raise ValueError(f'{len(ens.flown)} runs flew: the ensemble needs at least 2')
    t = ens.t
    keep = t >= campaign.judge_from - 1e-9
    a = ens.arrays
    found = ensemble.anees(a['nees'][:, keep], campaign.anees_level, 3,
                           campaign.anees_min_share)
    rms, sigma = ensemble.error_against_sigma(a['errors'], a['covariance'])
    q = campaign.percentiles
    settling = ensemble.settling_times(t, a['pointing'], campaign.settling_band) \
        if campaign.settling_band > 0 else np.full(len(ens.flown), math.nan)
    return Judgement(found, t[keep], rms, sigma, ensemble.percentiles(a['pointing'], q),
                     settling, ensemble.percentiles(settling, q) if campaign.settling_band > 0
                     else {})


def write(campaign, ens, judgement):
    """Write runs.csv, ensemble.csv and report.html into the campaign's folder; return paths."""
    import pandas as pd
    out = campaign.output
    rows, settled = [], dict(zip((r['index'] for r in ens.flown), judgement.settling))
    keep = ens.t >= campaign.judge_from - 1e-9
    for r in ens.records:
        row = {'run': r['index'], 'status': r['status'], 'error': r['error'],
               'wall_s': r['wall']}
        for name, value in r['drawn'].items():
            if isinstance(value, list):
                row.update({f'{name}[{i}]': c for i, c in enumerate(value)})
            else:
                row[name] = value
        if r['status'] == 'ok':
            row['final_pointing_error_rad'] = float(r['pointing'][-1])
            row['settling_time_s'] = settled[r['index']]
            row['mean_nees'] = float(np.mean(r['nees'][keep]))
        rows.append(row)
    runs_csv = os.path.join(out, 'runs.csv')
    pd.DataFrame(rows).to_csv(runs_csv, index=False)
    table = {'t_s': ens.t, 'rms_error_rad': judgement.rms, 'mean_sigma_rad': judgement.sigma}
    anees = np.full(ens.t.size, math.nan)
    anees[keep] = judgement.anees.anees
    table.update({'anees': anees, 'anees_low': judgement.anees.low,
                  'anees_high': judgement.anees.high})
    table.update({f'pointing_p{p:g}_rad': v for p, v in judgement.pointing.items()})
    ensemble_csv = os.path.join(out, 'ensemble.csv')
    pd.DataFrame(table).to_csv(ensemble_csv, index=False)
    page = _report(campaign, ens, judgement)
    return runs_csv, ensemble_csv, page


def summary_lines(campaign, ens, judgement):
    """Return the lines a person reads at the end of a campaign."""
    a = judgement.anees
    lines = [f'campaign: {len(ens.flown)} of {len(ens.records)} runs flew, '
             f'{len(ens.failed)} failed',
             f'  estimator: {a.message}']
    if campaign.control_on == 'none':
        return lines
    final = {p: float(v[-1]) for p, v in judgement.pointing.items()}
    lines.append('  pointing error at the end: ' + ', '.join(
        f'p{p:g} {v:.3g} rad' for p, v in final.items()))
    if judgement.settling_percentiles:
        unsettled = int(np.sum(np.isnan(judgement.settling)))
        lines.append(f'  settling time (inside {campaign.settling_band:g} rad): ' + ', '.join(
            f'p{p:g} {v:.4g} s' for p, v in judgement.settling_percentiles.items())
            + f'; {unsettled} runs did not settle')
    return lines


def _report(campaign, ens, judgement):
    """Write report.html (plotly, plotly.min.js beside it); return its path."""
    try:
        from plotly.subplots import make_subplots
        import plotly.graph_objects as go
    except ImportError:
        return None
    from ..tools.report_page import write as write_figures
    a = judgement.anees
    fig = make_subplots(rows=3, cols=1, shared_xaxes=True, subplot_titles=(
        f'ANEES over {a.runs} runs and its {100 * a.level:g} % bounds ({a.verdict})',
        'attitude error: RMS over runs against the mean reported sigma',
        'pointing error percentiles'))
    fig.add_trace(go.Scatter(x=judgement.times, y=a.anees, name='ANEES'), 1, 1)
    for bound in (a.low, a.high):
        fig.add_trace(go.Scatter(x=judgement.times, y=np.full(judgement.times.size, bound),
                                 name='bound', line={'dash': 'dash', 'color': 'gray'},
                                 showlegend=bound == a.low), 1, 1)
    fig.add_trace(go.Scatter(x=ens.t, y=judgement.rms, name='RMS error (rad)'), 2, 1)
    fig.add_trace(go.Scatter(x=ens.t, y=judgement.sigma, name='mean sigma (rad)'), 2, 1)
    for p, v in judgement.pointing.items():
        fig.add_trace(go.Scatter(x=ens.t, y=v, name=f'pointing p{p:g} (rad)'), 3, 1)
    fig.update_yaxes(type='log', row=2, col=1)
    fig.update_yaxes(type='log', row=3, col=1)
    fig.update_xaxes(title_text='t (s)', row=3, col=1)
    body = write_figures(campaign.output, {'campaign': fig})
    text = '<br>'.join(summary_lines(campaign, ens, judgement))
    path = os.path.join(campaign.output, 'report.html')
    with open(path, 'w', encoding='utf-8') as f:
        f.write('<!DOCTYPE html><html><head><meta charset="utf-8"><title>campaign</title>'
                '<script src="plotly.min.js"></script></head><body>'
                f'<h1>Monte Carlo campaign</h1><p>{text}</p>{body}</body></html>')
    return path
