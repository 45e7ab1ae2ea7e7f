"""
Thresholds for the suite's statistical checks, derived from one false-failure budget.

A statistical test draws noise, so a correct model fails it with some
probability. Each test here spends at most ``FALSE_FAILURE`` (1e-4) per run,
split evenly among its checks (Bonferroni: the union of the checks' failures
is no more likely than the sum of theirs), and every bound below is the exact
or the moment-matched sampling distribution of its statistic at that share.
``test_stat_checks.py`` runs the same bounds at a nominal 5 % over hundreds of
seeds and holds the share that fails to 5 %, so that no seed carries a check.
"""

import math

import numpy as np
from rigid_body_dynamics.physics.analysis import autocorrelation_time
from scipy import stats

#: The probability that a correct model fails one test, all its checks together.
FALSE_FAILURE = 1e-4


def share(checks, budget=FALSE_FAILURE):
    """Return each of ``checks`` checks' share of the test's false-failure ``budget``."""
    return budget / checks


def mean_bound(sigma, n, alpha):
    """
    Return the half-width of the two-sided interval of a mean of n N(0, sigma^2) samples.

    The mean of independent samples is N(0, sigma^2 / n): it falls outside
    +-z sigma / sqrt(n), z the 1 - alpha / 2 quantile, with probability alpha.
    """
    return stats.norm.isf(alpha / 2.0) * np.asarray(sigma) / math.sqrt(n)


def variance_interval(n, alpha, dof_per_sample=1.0, ddof=0):
    """
    Return (low, high): the two-sided interval of a mean square over its expectation.

    For n independent samples each chi-square with ``dof_per_sample`` degrees of
    freedom over that number (a squared N(0, 1): 1; a 2-D pointing error's
    angle^2 over 2 sigma^2: 2), the sum is chi-square with
    n dof_per_sample - ddof degrees of freedom. Outside with probability alpha.
    """
    dof = n * dof_per_sample - ddof
    return (stats.chi2.ppf(alpha / 2.0, dof) / dof, stats.chi2.isf(alpha / 2.0, dof) / dof)


def correlated_mean_square_interval(x, sigma, alpha):
    """
    Return (low, high, n_eff) for the mean of x^2 (N,) of a correlated N(0, sigma^2) series.

    The mean square of n correlated samples has the variance of n / tau
    independent ones, tau the autocorrelation time of x^2 (Geyer's estimator,
    :func:`autocorrelation_time`); the bounds are chi-square with n / tau
    degrees of freedom over n / tau (moment-matched), times sigma^2.
    """
    x = np.asarray(x, dtype=float)
    n_eff = len(x) / autocorrelation_time(x * x)
    low, high = variance_interval(n_eff, alpha)
    return low * sigma ** 2, high * sigma ** 2, n_eff


def binomial_count_interval(trials, p_low, p_high, alpha=FALSE_FAILURE):
    """
    Return (low, high): the failure counts over ``trials`` runs a rate in [p_low, p_high] gives.

    A count below ``low`` has probability <= alpha / 2 at the rate p_low, one
    above ``high`` <= alpha / 2 at p_high.
    """
    return (int(stats.binom.ppf(alpha / 2.0, trials, p_low)),
            int(stats.binom.isf(alpha / 2.0, trials, p_high)))
