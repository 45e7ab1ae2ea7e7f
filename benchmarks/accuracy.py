"""
Accuracy against cost for the free rigid body: our integrators and scipy's solve_ivp.

Case: I = (1, 2, 3) kg m^2, m0 = (1, 1, 18), so
omega0 = (1, 0.5, 6) rad/s and |omega| h = 6e-3 at 1 kHz. Errors are the
largest over samples every 1000 steps against the exact solution evaluated
in one shot from t = 0.
"""

import time

from common import errors, fmt
import numpy as np
from rigid_body_dynamics.physics import make_integrator
from rigid_body_dynamics.physics.dynamics.equations import state_rhs
from scipy.integrate import solve_ivp

MOMENTS = (1.0, 2.0, 3.0)
OMEGA0 = (1.0, 0.5, 6.0)
Q0 = (0.0, 0.0, 0.0, 1.0)


def run_stepper(name, dt, steps, sample=1000):
    """Run one of our integrators; returns (seconds per step, errors)."""
    stepper = make_integrator(name, MOMENTS, dt, Q0, OMEGA0)
    n_samples = steps // sample + 1
    t = np.empty(n_samples)
    q = np.empty((n_samples, 4))
    w = np.empty((n_samples, 3))
    t[0], q[0], w[0] = 0.0, Q0, OMEGA0
    elapsed = 0.0
    for k in range(1, n_samples):
        start = time.perf_counter()
        for _ in range(sample):
            stepper.step()
        elapsed += time.perf_counter() - start
        t[k], q[k], w[k] = stepper.time, stepper.q, stepper.omega
    return elapsed / (sample * (n_samples - 1)), errors(MOMENTS, OMEGA0, Q0, t, q, w)


def run_solve_ivp(method, rtol, atol, duration, sample_dt):
    """One solve_ivp call over the span; returns (seconds per simulated second, errors)."""
    t_eval = np.arange(0.0, duration + 0.5 * sample_dt, sample_dt)
    y0 = np.concatenate([OMEGA0, Q0])
    start = time.perf_counter()
    sol = solve_ivp(lambda _t, y: state_rhs(MOMENTS, y), (0.0, t_eval[-1]), y0, method=method,
                    rtol=rtol, atol=atol, t_eval=t_eval)
    elapsed = time.perf_counter() - start
    q = sol.y[3:].T / np.linalg.norm(sol.y[3:].T, axis=1)[:, None]
    return elapsed / duration, errors(MOMENTS, OMEGA0, Q0, sol.t, q, sol.y[:3].T)


def measure(steps):
    """All rows of the accuracy table; ``steps`` at 1 kHz (1e6 for the full run)."""
    rows = []
    duration = steps * 1e-3
    ref_cost, ref_err = run_solve_ivp('RK45', 1e-3, 1e-6, duration, 1.0)
    for name in ('exact', 'rk4'):
        per_step, err = run_stepper(name, 1e-3, steps)
        per_step_10, _ = run_stepper(name, 1e-2, max(steps // 100, 2000))
        rows.append((name, per_step * 1e6, per_step * 1e3, per_step_10 * 1e2, err))
    table_rows = []
    for name, us, sec1, sec10, err in rows:
        sec10 = 'n/a' if sec10 is None else f'{sec10:.5f}'
        table_rows.append([name, f'{us:.1f}', f'{sec1:.4f}', sec10, f'{sec1 / ref_cost:.2f}']
                          + [fmt(e) for e in err])
    scipy_runs = (('scipy solve_ivp RK45 (default tol)', 'RK45', 1e-3, 1e-6),
                  ('scipy solve_ivp DOP853 rtol 1e-9', 'DOP853', 1e-9, 1e-12),
                  ('scipy solve_ivp DOP853 rtol 1e-12', 'DOP853', 1e-12, 1e-15))
    for label, method, rtol, atol in scipy_runs:
        cost, err = (ref_cost, ref_err) if method == 'RK45' else run_solve_ivp(
            method, rtol, atol, duration, 1.0)
        table_rows.append([label, 'adaptive', f'{cost:.4f}', f'{cost:.4f}',
                           f'{cost / ref_cost:.2f}'] + [fmt(e) for e in err])
    return table_rows
