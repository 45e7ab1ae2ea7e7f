"""
Judging an ensemble of runs: ANEES with its chi-square bounds, errors against sigmas, spreads.

Bar-Shalom, Li and Kirubarajan, *Estimation with Applications to Tracking and
Navigation*, section 5.4.2: over R independent runs of a consistent estimator,
the average NEES at one time, ANEES_k = (1/R) sum_r e_rk^T P_rk^-1 e_rk, is
chi-square with n R degrees of freedom over R (n = 3 for an attitude error).
The runs are independent by construction, so this test needs no guess of the
errors' autocorrelation, unlike one run's time average. At level 1 - a, a
consistent estimator's ANEES falls outside the two-sided bounds at a share a of
the times; :func:`false_failure_rate` says how likely it is that more than an
allowed share of times falls outside.

Arrays are over runs and times: (R, T) for the NEES and pointing errors,
(R, T, 3) for errors (rad, world frame), (R, T, 3, 3) for covariances (rad^2).
"""

from dataclasses import dataclass
import math

import numpy as np
from scipy import stats


@dataclass(frozen=True)
class AneesFindings:
    """
    The ANEES over runs at each time, its bounds and the verdict.

    ``anees`` (T,); ``low``, ``high``: the bounds at ``level``; ``inside`` (T,)
    bool; ``share_inside``: the share of times inside; ``runs``, ``dof`` (per
    run and time); ``verdict``: 'consistent' when ``share_inside`` is at least
    ``min_share``, else 'overconfident' (the mean ANEES above ``high``),
    'pessimistic' (below ``low``) or 'inconsistent' (outside both ways);
    ``message`` a line for a person.
    """

    anees: np.ndarray
    low: float
    high: float
    inside: np.ndarray
    share_inside: float
    runs: int
    dof: int
    level: float
    min_share: float
    verdict: str
    message: str


def anees_bounds(runs, level=0.99, dof=3):
    """Return (low, high): the two-sided ``level`` interval of ANEES over ``runs`` runs."""
    if not 0.0 < level < 1.0:
        raise ValueError(f'level must be inside (0, 1), not {level!r}')
    total = dof * runs
    return (stats.chi2.ppf((1.0 - level) / 2.0, total) / runs,
            stats.chi2.isf((1.0 - level) / 2.0, total) / runs)


def anees(nees, level=0.99, dof=3, min_share=0.95):
    """
    Judge the NEES ``nees`` (R, T) of R runs at T times: :class:`AneesFindings`.

    ``level``: the bounds' two-sided confidence at each time; ``min_share``: the
    share of times inside the bounds that a consistent verdict needs.
    """
    nees = np.asarray(nees, dtype=float)
    if nees.ndim != 2 or nees.shape[0] < 2 or nees.shape[1] < 1:
        raise ValueError(f'nees must be (runs >= 2, times >= 1), got shape {nees.shape}')
    runs = nees.shape[0]
    low, high = anees_bounds(runs, level, dof)
    average = nees.mean(axis=0)
    inside = (average >= low) & (average <= high)
    share = float(inside.mean())
    mean = float(average.mean())
    if share >= min_share:
        verdict = 'consistent'
    elif np.all(average[~inside] > high):
        verdict = 'overconfident'
    elif np.all(average[~inside] < low):
        verdict = 'pessimistic'
    else:
        verdict = 'inconsistent'
    message = (f'{verdict}: ANEES inside its {100.0 * level:.4g} % bounds '
               f'[{low:.3g}, {high:.3g}] at {100.0 * share:.1f} % of {average.size} times '
               f'(needs {100.0 * min_share:.4g} %), {runs} runs; mean ANEES {mean:.3g} for '
               f'{dof} expected')
    return AneesFindings(average, float(low), float(high), inside, share, runs, dof,
                         float(level), float(min_share), verdict, message)


def false_failure_rate(times, level=0.99, min_share=0.95):
    """
    Return the probability that a consistent estimator's verdict is not 'consistent'.

    ``times``: the number of independent times judged (times spaced wider than
    the errors' correlation). Each falls outside its bounds with probability
    1 - ``level``, so the count outside is binomial, and the verdict fails when
    more than (1 - ``min_share``) ``times`` are outside.
    """
    allowed = math.floor((1.0 - min_share) * times + 1e-9)
    return float(stats.binom.sf(allowed, int(times), 1.0 - level))


def error_against_sigma(errors, covariances):
    """
    Return (rms (T,), sigma (T,)): the errors' RMS over runs and the mean reported sigma.

    ``rms`` = sqrt(mean over runs of |e|^2) (rad); ``sigma`` = sqrt(mean over runs
    of trace P) (rad): for a consistent estimator the two agree.
    """
    e = np.asarray(errors, dtype=float)
    p = np.asarray(covariances, dtype=float)
    return (np.sqrt(np.mean(np.sum(e * e, axis=-1), axis=0)),
            np.sqrt(np.mean(np.trace(p, axis1=-2, axis2=-1), axis=0)))


def settling_times(t, errors, band):
    """
    Return each run's settling time (R,; s): the first time after which its error stays <= band.

    ``t`` (T,) s; ``errors`` (R, T), in the unit of ``band``. NaN for a run that
    does not settle by its last sample, 0 for one inside from the start.
    """
    e = np.asarray(errors, dtype=float)
    t = np.asarray(t, dtype=float)
    out = np.full(e.shape[0], math.nan)
    for r, row in enumerate(e):
        above = np.flatnonzero(row > band)
        if not above.size:
            out[r] = t[0]
        elif above[-1] + 1 < t.size:
            out[r] = t[above[-1] + 1]
    return out


def percentiles(values, q=(50.0, 95.0, 99.0), axis=0):
    """Return {q: percentile along ``axis``} of ``values``, NaN ignored (numpy's linear rule)."""
    values = np.asarray(values, dtype=float)
    return {float(p): np.nanpercentile(values, p, axis=axis) for p in q}
