"""
Reaction wheels side by side with Basilisk: accuracy against DOP853 and cost.

Two cases, each against scipy's DOP853 of the gyrostat at rtol 2.5e-14,
restarted at every 10 ms hold (``physics.dynamics.reference.gyrostat_zoh_reference``):

- W1 torque-free gyrostat: I = (1, 2, 3) kg m^2 (wheels locked in), three wheels on the
  principal axes, J = 0.05 kg m^2 each, spinning at (100, -50, 20) rad/s with no motor
  torque, omega0 = (0.3, 1.5, -0.4) rad/s, 20 s.
- W2 the PD slew (30 degrees about x from rest, wn 0.5 rad/s, zeta 0.7) allocated to four
  pyramid wheels (J = 0.01 kg m^2) by ``WheelAllocator`` every 10 ms, each method closing
  the loop on its own state; I = (1, 1, 1.5) kg m^2, 20 s.

No friction and no limits (Basilisk's friction model differs). Errors are the largest
over the holds: attitude (rad), omega relative to the run's largest |omega|, wheel speeds
relative to the largest speed. Cost is wall time per simulated second, the least of three
runs. Ours: the gyrostat integrator (``exact``: Butcher's order-6 formula, or DOP853's
order-8 one when the body's fastest rate times the step exceeds 0.01; ``rk4``). Basilisk
2.12.1: a spacecraft hub with ``reactionWheelStateEffector`` (BalancedWheels, wheels at the
hub's centre of mass), the hub's inertia I itself: with BalancedWheels Basilisk takes the
hub's inertia as the whole body's with the wheels locked, as this package does (measured:
taking each wheel's Js g g^T + Jt (1 - g g^T) out of the hub made Basilisk differ from the
reference by 0.2 rad in 2 s at every step and method, with I unchanged it agrees to 3e-15).
RK4 and RKF78 at the same step, the motor torques written to the effector's command message
before each hold.

Then the step's cost beside the plain body's: microseconds per 1 ms step (the least of
five runs of 2000 steps) of the plain body's ``exact`` under a held body torque, and of
the gyrostat with the four pyramid wheels (J = 0.01 kg m^2, speeds (40, -25, 10, 0.5)
rad/s, motor torques (0.01, -0.02, 0.005, 0) N m) without external torque and under the
same held torque, without and with friction (wheels.yaml's Coulomb 1e-4 N m and viscous
1e-6 N m s); the asymmetric body I = (1, 2, 3) kg m^2, omega0 = (0.3, 1.5, -0.4) rad/s.

``./dev bench --only wheels`` (Basilisk installed: ``pip install bsk==2.12.1``).
"""

import math
import time

from common import best_of, fmt
import numpy as np
from rigid_body_dynamics.physics import quaternions
from rigid_body_dynamics.physics.control import QuaternionPD, WheelAllocator
from rigid_body_dynamics.physics.dynamics.gyrostat import GyrostatIntegrator, Wheels
from rigid_body_dynamics.physics.dynamics.integrators import make_integrator
from rigid_body_dynamics.physics.dynamics.reference import gyrostat_zoh_reference

HOLD = 0.01
DURATION = 20.0
HOLDS = int(round(DURATION / HOLD))
REPEATS = 3
_PYRAMID = tuple(tuple(c / math.sqrt(3.0) for c in g) for g in
                 ((1, 1, 1), (-1, 1, 1), (-1, -1, 1), (1, -1, 1)))
_TARGET = tuple(quaternions.from_axis_angle(np.array([1.0, 0.0, 0.0]), math.radians(30.0)))


def _no_motors(wheels):
    return lambda _k, _q, _w, _s: ((0.0,) * wheels.count, (0.0, 0.0, 0.0))


def _slew(moments, wheels):
    law = QuaternionPD(moments, _TARGET, 0.5, 0.7)
    alloc = WheelAllocator(wheels)

    def command(_k, q, w, speeds):
        u, _dump = alloc.allocate(law(q, w), w, speeds)
        return u, (0.0, 0.0, 0.0)
    return command


#: case -> (moments, Wheels, omega0, speeds0, command factory)
CASES = {
    'W1 torque-free gyrostat': ((1.0, 2.0, 3.0), Wheels(((1, 0, 0), (0, 1, 0), (0, 0, 1)),
                                                        (0.05,) * 3),
                                (0.3, 1.5, -0.4), (100.0, -50.0, 20.0), _no_motors),
    'W2 PD slew on four pyramid wheels': ((1.0, 1.0, 1.5), Wheels(_PYRAMID, (0.01,) * 4),
                                          (0.0, 0.0, 0.0), (0.0,) * 4, _slew),
}


def _run_ours(case, dt, method):
    moments, wheels, omega0, speeds0, factory = CASES[case]
    command = factory(moments, wheels) if factory is _slew else factory(wheels)
    body = GyrostatIntegrator(moments, wheels, dt, omega0=omega0, speeds0=speeds0,
                              method=method)
    per_hold = int(round(HOLD / dt))
    qs, ws, ss = [body.q], [body.omega], [body.speeds]
    start = time.perf_counter()
    for k in range(HOLDS):
        u, tau = command(k, body.q, body.omega, body.speeds)
        body.command_motors(u)
        for _ in range(per_hold):
            body.step(tau)
        qs.append(body.q)
        ws.append(body.omega)
        ss.append(body.speeds)
    return (time.perf_counter() - start) / DURATION, qs, ws, ss


def _run_basilisk(case, dt, integrator):
    from Basilisk.architecture import messaging
    from Basilisk.simulation import reactionWheelStateEffector, spacecraft, svIntegrators
    from Basilisk.utilities import macros, RigidBodyKinematics, SimulationBaseClass
    from Basilisk.utilities import simIncludeRW
    from scipy.spatial.transform import Rotation
    moments, wheels, omega0, speeds0, factory = CASES[case]
    command = factory(moments, wheels) if factory is _slew else factory(wheels)
    sim = SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess('dynamics').addTask(sim.CreateNewTask('step', macros.sec2nano(dt)))
    craft = spacecraft.Spacecraft()
    craft.hub.mHub = 1.0
    hub = np.diag(moments).astype(float)
    factory_rw = simIncludeRW.rwFactory()
    for g, j, s in zip(wheels.axes, wheels.inertia, speeds0):
        # the hub's inertia stays the locked body's: see the module docstring
        factory_rw.create('custom', list(g), Js=float(j), Omega=float(s * 60.0 / (2 * math.pi)),
                          RWModel=reactionWheelStateEffector.BalancedWheels,
                          useRWfriction=False, useMaxTorque=False)
    craft.hub.IHubPntBc_B = hub.tolist()
    craft.hub.sigma_BNInit = [[0.0], [0.0], [0.0]]
    craft.hub.omega_BN_BInit = [[c] for c in omega0]
    effector = reactionWheelStateEffector.ReactionWheelStateEffector()
    factory_rw.addToSpacecraft('wheels', effector, craft)
    motor_msg = messaging.ArrayMotorTorqueMsg()
    effector.rwMotorCmdInMsg.subscribeTo(motor_msg)
    craft.setIntegrator(getattr(svIntegrators, integrator)(craft))
    sim.AddModelToTask('step', effector, None, 2)
    sim.AddModelToTask('step', craft, None, 1)
    payload = messaging.ArrayMotorTorqueMsgPayload()
    payload.motorTorque = [0.0] * wheels.count
    motor_msg.write(payload)
    sim.InitializeSimulation()

    def state():
        msg = craft.scStateOutMsg.read()
        rot = np.array(RigidBodyKinematics.MRP2C(msg.sigma_BN)).T
        speeds = tuple(effector.rwSpeedOutMsg.read().wheelSpeeds[:wheels.count])
        return tuple(Rotation.from_matrix(rot).as_quat()), tuple(msg.omega_BN_B), speeds
    sim.ConfigureStopTime(0)
    sim.ExecuteSimulation()
    q, w, s = state()
    qs, ws, ss = [q], [w], [s]
    start = time.perf_counter()
    for k in range(HOLDS):
        u, _tau = command(k, q, w, s)
        payload.motorTorque = list(u)
        motor_msg.write(payload)
        sim.ConfigureStopTime(macros.sec2nano((k + 1) * HOLD))
        sim.ExecuteSimulation()
        q, w, s = state()
        qs.append(q)
        ws.append(w)
        ss.append(s)
    return (time.perf_counter() - start) / DURATION, qs, ws, ss


def _errors(ref, qs, ws, ss):
    q_ref, w_ref, s_ref = ref
    attitude = float(np.max(quaternions.angle_between(np.array(qs), q_ref)))
    omega = float(np.max(np.linalg.norm(np.array(ws) - w_ref, axis=1))
                  / np.max(np.linalg.norm(w_ref, axis=1)))
    speeds = float(np.max(np.abs(np.array(ss) - s_ref)) / max(np.max(np.abs(s_ref)), 1e-300))
    return attitude, omega, speeds


#: The step-cost case: body, wheels' speeds and motor torques, the held external torque.
STEP_MOMENTS, STEP_OMEGA = (1.0, 2.0, 3.0), (0.3, 1.5, -0.4)
STEP_SPEEDS, STEP_MOTORS = (40.0, -25.0, 10.0, 0.5), (0.01, -0.02, 0.005, 0.0)
STEP_TORQUE = (0.01, -0.02, 0.005)


def _us_per_step(stepper, torque, steps=2000, repeats=5):
    """Return the least wall time (us) of one ``stepper.step(torque)`` over ``repeats`` runs."""
    def run():
        start = time.perf_counter()
        for _ in range(steps):
            stepper.step(torque)
        return ((time.perf_counter() - start) / steps,)
    return best_of(run, repeats)[0] * 1e6


def step_cost():
    """Return the lines of the step-cost table (see the module docstring)."""
    plain = _us_per_step(make_integrator('exact', STEP_MOMENTS, 1e-3, omega0=STEP_OMEGA),
                         STEP_TORQUE)
    rows = [f'| plain body `exact` | held body torque | {plain:.1f} | 1.00 |']
    for friction in (False, True):
        wheels = Wheels(_PYRAMID, (0.01,) * 4, coulomb=(1e-4,) * 4 if friction else None,
                        viscous=(1e-6,) * 4 if friction else None)
        for torque in ((0.0, 0.0, 0.0), STEP_TORQUE):
            body = GyrostatIntegrator(STEP_MOMENTS, wheels, 1e-3, omega0=STEP_OMEGA,
                                      speeds0=STEP_SPEEDS)
            body.command_motors(STEP_MOTORS)
            cost = _us_per_step(body, torque)
            rows.append(f'| four wheels{", friction" if friction else ""} `exact` | '
                        f'{"held body torque" if any(torque) else "none"} | {cost:.1f} | '
                        f'{cost / plain:.2f} |')
    return ['### The step beside the plain body', '',
            '| body | external torque | us per 1 ms step | / plain body under torque |',
            '|---|---|---|---|'] + rows + ['']


def measure(progress=print):
    """Return RESULTS.md lines: one table per case, ours and Basilisk's; the step's cost."""
    lines = []
    for case, (moments, wheels, omega0, speeds0, factory) in CASES.items():
        progress(f'wheels {case}: reference ...')
        command = factory(moments, wheels) if factory is _slew else factory(wheels)
        ref = gyrostat_zoh_reference(moments, wheels, (0.0, 0.0, 0.0, 1.0), omega0, speeds0,
                                     HOLD, HOLDS, command)
        rows = []
        runs = [(f'ours `{m}`', dt, lambda m=m, dt=dt: _run_ours(case, dt, m))
                for m in ('exact', 'rk4') for dt in (1e-3, 1e-2)]
        runs += [(f'Basilisk 2.12.1 {label}', dt,
                  lambda i=i, dt=dt: _run_basilisk(case, dt, i))
                 for label, i in (('RK4', 'svIntegratorRK4'), ('RKF78', 'svIntegratorRKF78'))
                 for dt in (1e-3, 1e-2)]
        for label, dt, run in runs:
            progress(f'wheels {case}: {label} at {dt * 1e3:g} ms')
            try:
                cost, qs, ws, ss = best_of(run, REPEATS)
            except ImportError as err:
                rows.append(f'| {label} | {dt * 1e3:g} | not installed ({err.name}) | | | |')
                continue
            attitude, omega, speeds = _errors(ref, qs, ws, ss)
            rows.append(f'| {label} | {dt * 1e3:g} | {fmt(attitude)} | {fmt(omega)} | '
                        f'{fmt(speeds)} | {cost * 1e3:.2f} |')
        lines += [f'### {case}', '', '| method | dt (ms) | attitude error (rad) | omega error '
                  '(rel.) | wheel speed error (rel.) | ms per simulated s |',
                  '|---|---|---|---|---|---|'] + rows + ['']
    progress('wheels: the step beside the plain body')
    return lines + step_cost()


if __name__ == '__main__':
    print('\n'.join(measure()))
