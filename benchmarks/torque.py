"""
Under a held torque (a controller's zero-order hold): accuracy against cost.

Two cases, torque updated every HOLD = 10 ms and held in
between, 20 s:

- T1 open loop: tau(t_k) = (0.3 sin 0.7 t_k, 0.2 cos 1.3 t_k, 0.25 sin(0.4 t_k + 1)) N m
  body frame; I = (1, 2, 3) kg m^2, omega0 = (0.3, 1.5, -0.4) rad/s.
- T2 closed loop: PD on the quaternion error to a fixed target attitude,
  vector-saturated at 0.5 N m, computed every 10 ms from each method's own
  state; I = (0.8, 1.1, 1.7) kg m^2, omega0 = (0.5, -0.8, 1.2) rad/s.

The reference is scipy's DOP853 at rtol 2.5e-14 restarted at every hold
(closing its own loop in T2), sampled at the holds. Errors are the largest
over the holds: attitude (rad, angle of q_ref^-1 q) and |omega - omega_ref|
relative to the run's largest |omega_ref| (T2 settles to rest, where a
pointwise relative error means nothing). Cost is wall time per simulated
second, also as a ratio to a plain pure-Python RK4 (``plain_rk4``, the
textbook code a user would write) at 1 ms measured in the same run, the unit
of cost; each cost is the least of five runs (two for the peers). The
balance column is max |T - T0 - W| / T0 of our steppers (W is the stepper's
quadrature of omega . tau, not a by-construction quantity).

Peers (optional, ``--peers``): MuJoCo RK4 (``qfrc_applied[3:6]`` is the
body-frame torque of a free joint; ``qvel[3:6]`` the body rate) and
Basilisk RKF78 and RK4 (an ``ExtForceTorque`` effector on the hub, its
``extTorquePntB_B`` set from Python before each hold is executed).
"""

import math
import time

from common import best_of, fmt
import numpy as np
from peers import basilisk_attitude, basilisk_body, mujoco_body
from rigid_body_dynamics.physics import make_integrator, quaternions, simulate
from rigid_body_dynamics.physics.control import QuaternionPD
from rigid_body_dynamics.physics.dynamics.reference import zoh_reference

HOLD = 0.01
DURATION = 20.0
STEPS_PER_RUN = int(round(DURATION / HOLD))
DTS = (1e-3, 2e-3, 5e-3, 1e-2)
Q0 = (0.0, 0.0, 0.0, 1.0)


def _t1(k, _q, _w):
    t = k * HOLD
    return (0.3 * math.sin(0.7 * t), 0.2 * math.cos(1.3 * t), 0.25 * math.sin(0.4 * t + 1.0))


T2_MOMENTS = (0.8, 1.1, 1.7)
#: target attitude (a 2 rad turn about (1, 1, 1)), wn 0.8 rad/s, zeta 0.7, 0.5 N m
_T2_LAW = QuaternionPD(T2_MOMENTS, quaternions.from_axis_angle(np.ones(3) / math.sqrt(3.0), 2.0),
                       natural_frequency=0.8, damping_ratio=0.7, max_torque=0.5)

#: case -> (moments kg m^2, omega0 rad/s, command(k, q, omega) -> body torque N m)
CASES = {
    'T1 open loop': ((1.0, 2.0, 3.0), (0.3, 1.5, -0.4), _t1),
    'T2 closed loop': (T2_MOMENTS, (0.5, -0.8, 1.2), lambda _k, q, w: _T2_LAW(q, w)),
}


def reference(case):
    """(q, omega) at every hold from DOP853 at rtol 2.5e-14, restarted at each hold."""
    moments, omega0, command = CASES[case]
    return zoh_reference(moments, omega0, Q0, HOLD, STEPS_PER_RUN, command)


def _errors(ref, q, w):
    """Largest attitude error (rad) and omega error relative to the run's largest |omega_ref|."""
    q_ref, w_ref = ref
    attitude = quaternions.angle_between(np.asarray(q), q_ref)
    omega = np.linalg.norm(np.asarray(w) - w_ref, axis=1)
    return float(attitude.max()), float(omega.max() / np.linalg.norm(w_ref, axis=1).max())


def run_ours(name, case, dt):
    """(s per simulated s, q, omega at the holds, energy balance) for one of our integrators."""
    moments, omega0, command = CASES[case]
    stepper = make_integrator(name, moments, dt, Q0, omega0)
    per_hold = int(round(HOLD / dt))
    t0 = stepper.kinetic_energy
    qs, ws, balance = [stepper.q], [stepper.omega], 0.0
    start = time.perf_counter()
    for k in range(STEPS_PER_RUN):
        tau = command(k, stepper.q, stepper.omega)
        for _ in range(per_hold):
            stepper.step(tau)
        qs.append(stepper.q)
        ws.append(stepper.omega)
        balance = max(balance, abs(stepper.kinetic_energy - t0 - stepper.work))
    cost = (time.perf_counter() - start) / DURATION
    return cost, qs, ws, balance / t0


def plain_rk4(case, dt=1e-3):
    """Run the cost unit: textbook RK4 in plain Python (lists, a derivative function), 1 ms."""
    moments, omega0, command = CASES[case]
    i1, i2, i3 = moments

    def f(s, tau):
        w1, w2, w3, x, y, z, q4 = s
        return [((i2 - i3) * w2 * w3 + tau[0]) / i1, ((i3 - i1) * w3 * w1 + tau[1]) / i2,
                ((i1 - i2) * w1 * w2 + tau[2]) / i3,
                0.5 * (q4 * w1 + y * w3 - z * w2), 0.5 * (q4 * w2 + z * w1 - x * w3),
                0.5 * (q4 * w3 + x * w2 - y * w1), -0.5 * (x * w1 + y * w2 + z * w3)]

    s = list(omega0) + list(Q0)
    per_hold = int(round(HOLD / dt))
    qs, ws = [tuple(Q0)], [tuple(omega0)]
    start = time.perf_counter()
    for k in range(STEPS_PER_RUN):
        tau = command(k, tuple(s[3:]), tuple(s[:3]))
        for _ in range(per_hold):
            k1 = f(s, tau)
            k2 = f([a + 0.5 * dt * b for a, b in zip(s, k1)], tau)
            k3 = f([a + 0.5 * dt * b for a, b in zip(s, k2)], tau)
            k4 = f([a + dt * b for a, b in zip(s, k3)], tau)
            s = [a + dt / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4)
                 for a, b1, b2, b3, b4 in zip(s, k1, k2, k3, k4)]
            n = math.sqrt(sum(c * c for c in s[3:]))
            s[3:] = [c / n for c in s[3:]]
        qs.append(tuple(s[3:]))
        ws.append(tuple(s[:3]))
    return (time.perf_counter() - start) / DURATION, qs, ws


def run_simulate(case, dt=1e-2):
    """Run the public API: simulate() with a callable torque held over each hold."""
    moments, omega0, command = CASES[case]
    per_hold = int(round(HOLD / dt))
    held = {}

    def torque(t, q, w):
        k = int(round(t / HOLD)) if per_hold == 1 else int(math.floor(t / HOLD + 1e-9))
        if k not in held:
            held.clear()
            held[k] = command(k, tuple(q), tuple(w))
        return held[k]

    start = time.perf_counter()
    run = simulate(moments, omega0, Q0, duration=DURATION, dt=dt, torque=torque, every=per_hold)
    cost = (time.perf_counter() - start) / DURATION
    return cost, run.q, run.omega


def run_mujoco(case, dt, integrator='RK4'):
    """Run MuJoCo: free joint, zero gravity; body torque in qfrc_applied[3:6]."""
    moments, omega0, command = CASES[case]
    mujoco, model, data = mujoco_body(moments, omega0, dt, integrator)
    per_hold = int(round(HOLD / dt))

    def state():
        wq = data.qpos[3:7]
        return (float(wq[1]), float(wq[2]), float(wq[3]), float(wq[0])), tuple(data.qvel[3:6])

    q, w = state()
    qs, ws = [q], [w]
    start = time.perf_counter()
    for k in range(STEPS_PER_RUN):
        data.qfrc_applied[3:6] = command(k, q, w)
        for _ in range(per_hold):
            mujoco.mj_step(model, data)
        q, w = state()
        qs.append(q)
        ws.append(w)
    return (time.perf_counter() - start) / DURATION, qs, ws


def run_basilisk(case, dt, integrator='svIntegratorRKF78'):
    """Basilisk hub with an ExtForceTorque effector; the torque set before each hold."""
    from Basilisk.simulation import extForceTorque
    from Basilisk.utilities import macros
    moments, omega0, command = CASES[case]
    sim, craft = basilisk_body(moments, omega0, dt, integrator)
    effector = extForceTorque.ExtForceTorque()
    craft.addDynamicEffector(effector)
    # the hub first (higher priority), then the effector: the torque set
    # before a hold acts over that hold, not one step early
    sim.AddModelToTask('step', craft, None, 2)
    sim.AddModelToTask('step', effector, None, 1)
    sim.InitializeSimulation()
    effector.extTorquePntB_B = [[0.0], [0.0], [0.0]]
    sim.ConfigureStopTime(0)
    sim.ExecuteSimulation()
    q, w = basilisk_attitude(craft)
    qs, ws = [q], [w]
    start = time.perf_counter()
    for k in range(STEPS_PER_RUN):
        effector.extTorquePntB_B = [[c] for c in command(k, q, w)]
        sim.ConfigureStopTime(macros.sec2nano((k + 1) * HOLD))
        sim.ExecuteSimulation()
        q, w = basilisk_attitude(craft)
        qs.append(q)
        ws.append(w)
    return (time.perf_counter() - start) / DURATION, qs, ws


def measure(peers=False, repeats=5, progress=print):
    """
    Measure both cases; returns {case: rows}.

    Row: method, dt (ms), attitude error, omega error, ms per simulated s,
    cost / plain RK4, energy balance.
    """
    tables = {}
    for case in CASES:
        progress(f'torque {case}: reference ...')
        ref = reference(case)
        unit, q, w = best_of(lambda: plain_rk4(case), repeats)
        rows = []

        def add(label, dt, cost, q, w, balance=None):
            attitude, omega = _errors(ref, q, w)
            rows.append([label, f'{dt * 1e3:g}', fmt(attitude), fmt(omega),
                         f'{cost * 1e3:.2f}', f'{cost / unit:.2f}',
                         'n/a' if balance is None else fmt(balance)])

        add('plain pure-Python RK4 (the cost unit)', 1e-3, unit, q, w)
        for name in ('exact', 'rk4'):
            for dt in DTS:
                progress(f'torque {case}: {name} at {dt * 1e3:g} ms')
                add(f'ours `{name}`', dt, *best_of(lambda: run_ours(name, case, dt), repeats))
        add('ours `exact` through simulate(callable torque)', 1e-2,
            *best_of(lambda: run_simulate(case), repeats))
        if peers:
            for label, run in (('MuJoCo 4.0.0 RK4', run_mujoco),
                               ('Basilisk 2.12.1 RKF78', run_basilisk),
                               ('Basilisk 2.12.1 RK4', lambda c, dt: run_basilisk(
                                   c, dt, 'svIntegratorRK4'))):
                for dt in DTS:
                    progress(f'torque {case}: {label} at {dt * 1e3:g} ms')
                    try:
                        add(label, dt, *best_of(lambda: run(case, dt), min(repeats, 2)))
                    except ImportError as err:
                        rows.append([label, f'{dt * 1e3:g}', f'not installed ({err.name})',
                                     '', '', '', ''])
                        break
        tables[case] = rows
    return tables
