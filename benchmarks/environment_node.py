"""
attitude_simulator in orbit: CPU at 1 kHz, free against the space environment.

The asymmetric body I = (2, 3, 1.2) kg m^2 tumbling at omega0 = (0.3, -0.5, 0.8) rad/s, 1 kHz
steps, 100 Hz publishing, real time: free (no orbit), on a 500 km circular orbit with nothing
acting (the exact torque-free flow still serves), with the gravity gradient, and with the
gravity gradient, the dipole field, a residual dipole and a magnetometer at 10 Hz (every stage
evaluates the orbit, the field and the torques); the engine's step also with the IGRF-14 to
degree 13 instead of the dipole (interpolated along the orbit), on the Kepler orbit and on the
ISS's TLE (SGP4, epoch 2019-12-09T20:42:00Z); and the whole mission model: the orbit
integrated under J2, the IGRF-14 to degree 13, the gravity gradient, the residual dipole, and
drag (Vallado's exponential air, and again NRLMSIS 2.1's at F10.7 150, Ap 4) and solar
pressure (the Almanac's Sun from the epoch, the conical shadow) on a 3U CubeSat's six faces.
CPU is the simulator's share of one core over 8 s after 3 s of warm-up, each case three times,
alternating. Then the engine's step alone (``BodySimulation.advance`` on a fake clock, the
least of five runs of 20000 steps, in five rounds over all the cases), free, under a constant
torque, and in the same environments, the body alone and with four pyramid wheels (J = 0.01 kg
m^2, Coulomb 1e-4 N m and viscous 1e-6 N m s friction, spinning at (40, -25, 10, 0.5) rad/s,
motors idle: without the orbit's torques, their steps between two reads of the state, every
10, are one span); in orbit each twice: with the models' statements in the generated stages
(as the package runs) and with the models called at every stage (``SpaceEnvironment(...,
stages=False)``, the path of a model without statements). ``./dev bench --only
environment-node``.
"""

import statistics
import time

from diagnostic_msgs.msg import DiagnosticArray
from nodes import measure_cpu, Probe, sim
from rigid_body_dynamics.engine import BodySimulation, Disturbances
from rigid_body_dynamics.physics import Inertia
from rigid_body_dynamics.physics.dynamics.gyrostat import Wheels
from rigid_body_dynamics.physics.environment import (DipoleField, EARTH_RATE,
                                                     ExponentialAtmosphere, Facets, IgrfField,
                                                     KeplerOrbit, MsisAtmosphere,
                                                     SpaceEnvironment, Sun,
                                                     TleOrbit, unix_time, ZonalOrbit)
from rigid_body_dynamics.physics.environment.facets import box

ROUNDS = 3
#: Rounds of the engine's steps over every case (the least of each case's is kept).
ROUNDS_STEP = 5
BODY = ('inertia:=[2.0, 3.0, 1.2]', 'initial_angular_velocity:=[0.3, -0.5, 0.8]')
ORBIT = ('orbit_elements:=[6878137.0, 0.0, 1.0, 0.3, 0.0, 0.0]',)
#: The ISS (NORAD 25544) on 2019-12-09: the public TLE of the sgp4 library's README.
ISS = ('1 25544U 98067A   19343.69339541  .00001764  00000-0  38792-4 0  9991',
       '2 25544  51.6439 211.2001 0007417  17.6667  85.6398 15.50103472202482')
EPOCH = '2019-12-09T20:42:00Z'
MISSION = ('J2 orbit, IGRF-14 to degree 13, gravity gradient, residual dipole, drag, solar '
           'pressure')
MISSION_MSIS = f'{MISSION}, the air NRLMSIS 2.1'


def measure():
    """Return RESULTS.md lines: the simulator's CPU free and in orbit."""
    probe = Probe('bench_environment')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    cases = {
        'free body': sim(*BODY),
        'in orbit, no torque model': sim(*BODY, *ORBIT),
        'in orbit, gravity gradient': sim(*BODY, *ORBIT, 'gravity_gradient:=true'),
        'gravity gradient, field, residual dipole, magnetometer at 10 Hz': sim(
            *BODY, *ORBIT, 'gravity_gradient:=true', 'magnetic_field_model:=dipole',
            'residual_dipole:=[0.01, -0.02, 0.005]', 'magnetometer_rate:=10.0'),
    }
    found = {name: [] for name in cases}
    try:
        for _ in range(ROUNDS):
            for name, cmd in cases.items():
                cpu, diag = measure_cpu(cmd, probe)
                rtf = float(diag[1]['achieved real-time factor']) if diag else float('nan')
                found[name].append((cpu, rtf))
                print(f'{name}: {cpu:.3f} of a core, achieved {rtf:.3f}', flush=True)
    finally:
        probe.close()
    base = statistics.median(c for c, _r in found['free body'])
    lines = ['| simulator | CPU (share of one core, each run) | / free body | achieved '
             'real-time factor |', '|---|---|---|---|']
    for name, runs in found.items():
        median = statistics.median(c for c, _r in runs)
        lines.append(f'| {name} | {", ".join(f"{c:.3f}" for c, _r in runs)} (median '
                     f'{median:.3f}) | {median / base:.1f} | '
                     f'{", ".join(f"{r:.3f}" for _c, r in runs)} |')
    return lines + [''] + engine_steps()


def engine_steps(steps=20000):
    """
    Return RESULTS.md lines: the engine's cost per 1 ms step in each environment (us).

    Each environment twice: its models' statements in the generated stages (as the
    package runs) and the same models called at each stage (``stages=False``: how it
    ran before the statements), the plain body and with four friction wheels.
    """
    orbit = KeplerOrbit([6878137.0, 0.0, 1.0, 0.3, 0.0, 0.0])
    cases = {'free body (the exact flow)': Disturbances(),
             'constant body torque 1e-3 N m': Disturbances(body=(1e-3, 0.0, 0.0)),
             'in orbit, gravity gradient': Disturbances(orbit=orbit, gravity_gradient=True),
             'gravity gradient, field, residual dipole': Disturbances(
                 orbit=orbit, field=DipoleField(), gravity_gradient=True,
                 residual_dipole=(0.01, -0.02, 0.005)),
             'gravity gradient, IGRF-14 to degree 13, residual dipole': Disturbances(
                 orbit=orbit, field=IgrfField(orbit, unix_time(EPOCH), 13, 0.0, EARTH_RATE),
                 gravity_gradient=True, residual_dipole=(0.01, -0.02, 0.005))}
    tle = TleOrbit(*ISS, epoch=EPOCH)
    cases['the same on the ISS TLE (SGP4)'] = Disturbances(
        orbit=tle, field=IgrfField(tle, unix_time(EPOCH), 13, 0.0, EARTH_RATE),
        gravity_gradient=True, residual_dipole=(0.01, -0.02, 0.005))
    zonal = ZonalOrbit([6878137.0, 0.0, 1.0, 0.3, 0.0, 0.0], 2)
    for name, air in ((MISSION, ExponentialAtmosphere(EARTH_RATE)),
                      (MISSION_MSIS, MsisAtmosphere(zonal, unix_time(EPOCH), 150.0, 150.0, 4.0,
                                                    0.0, EARTH_RATE))):
        cases[name] = Disturbances(
            orbit=zonal, field=IgrfField(zonal, unix_time(EPOCH), 13, 0.0, EARTH_RATE),
            gravity_gradient=True, residual_dipole=(0.01, -0.02, 0.005), sun=Sun(EPOCH),
            shadow_model='conical',
            facets=Facets(box((0.1, 0.1, 0.34), (0.0, 0.0, 0.02), 0.3, 0.1)),
            solar_pressure=True, atmosphere=air, drag=True)
    pyramid = [c / 3 ** 0.5 for g in ((1, 1, 1), (-1, 1, 1), (-1, -1, 1), (1, -1, 1)) for c in g]
    wheels = Wheels(pyramid, (0.01,) * 4, coulomb=(1e-4,) * 4, viscous=(1e-6,) * 4)
    lines = ['| engine step (1 ms, I = (2, 3, 1.2) kg m^2) | wheels | us per step, models in '
             'the stages | us per step, models called at each stage |', '|---|---|---|---|']
    found = {(name, with_wheels): {} for name in cases for with_wheels in (False, True)}
    for _ in range(ROUNDS_STEP):         # rounds over all cases: a slower spell hits them all
        for name, disturbances in cases.items():
            for with_wheels in (False, True):
                best = found[name, with_wheels]
                for called in (False, True):
                    if called and disturbances.orbit is None:
                        continue
                    cost = _engine_step(disturbances, with_wheels and wheels, called, steps)
                    best[called] = min(best.get(called, cost), cost)
    for name, disturbances in cases.items():
        for with_wheels in (False, True):
            best = found[name, with_wheels]
            lines.append(f'| {name} | {"four, friction" if with_wheels else "none"} | '
                         f'{best[False] * 1e6:.1f} | '
                         + (f'{best[True] * 1e6:.1f} |' if True in best else '- |'))
    torqued = found['constant body torque 1e-3 N m', False][False]
    ratios = [(name, found[name, False][False] / torqued, found[name, False][True] / torqued)
              for name in list(cases)[2:]]
    dipole = found['gravity gradient, field, residual dipole', False][False]
    mission, msis = found[MISSION, False][False], found[MISSION_MSIS, False][False]
    return lines + ['', 'The body alone, over its step under a constant torque: ' + '; '.join(
        f'{name} {inlined:.1f}x in the stages, {called:.1f}x called'
        for name, inlined, called in ratios) + f'. The whole mission model costs '
        f'{mission / dipole:.2f}x the step with the gravity gradient, the dipole field and '
        f'the residual dipole ({mission * 1e6:.1f} against {dipole * 1e6:.1f} us, this run); '
        f'with NRLMSIS 2.1 for the air {msis / dipole:.2f}x ({msis * 1e6:.1f} us). '
        'What the statements leave: the world quantities at the 5 distinct nodes of an '
        'order-6 step (they depend on time alone; one call per step reads them from the '
        'table the environment computes 500 steps at a time with numpy), and the turn of '
        'the position, the field, the Sun and the flow into the attitude of each stage. '
        'The CPU of the node moves from run to run and day to day on this 2-core '
        'virtual machine (the free body alone measured 0.034 to 0.064 of a core in three '
        'runs on 2026-12-03), so the step of the engine is the steadier figure.']


def _engine_step(disturbances, wheels, called, steps):
    """Return the seconds per step of BodySimulation.advance over ``steps`` steps."""
    body = BodySimulation(Inertia((2.0, 3.0, 1.2)), 'exact', 1000.0,
                          ((0.0, 0.0, 0.0, 1.0), (0.3, -0.5, 0.8)), publish_every=10,
                          disturbances=disturbances, wheels=wheels or None,
                          wheel_speeds=(40.0, -25.0, 10.0, 0.5) if wheels else None)
    field = body.plant.field
    if called and field is not None:
        body.plant.field = SpaceEnvironment(field.orbit, field.field, field.models, field.epoch,
                                            stages=False, sun=field.sun, shadow=field.shadow,
                                            planet_radius=field.planet_radius,
                                            atmosphere=field.atmosphere)
    outbox = []
    start = time.perf_counter()
    with body.lock:
        for _ in range(steps):
            body.advance(0, outbox)
    return (time.perf_counter() - start) / steps


if __name__ == '__main__':
    print('\n'.join(measure()))
