"""
The simulators users would otherwise pick, on the same free body and steps.

Optional: needs ``mujoco`` and ``bsk`` (Basilisk) from the registry,
``.venv/bin/pip install -r benchmarks/requirements-peers.txt``. Not run in CI.

Case: tennis racket I = (1, 2, 3) kg m^2, omega0 = (0.01, 2, 0.01)
rad/s body, 10 ms steps, 200 s. Reported: largest relative energy error,
final attitude error against our exact solution, wall time per simulated
second and its ratio to our rk4 measured in the same run.
"""

import time

from common import errors, fmt
import numpy as np
from rigid_body_dynamics.physics import FreeRigidBody, make_integrator, quaternions
from scipy.spatial.transform import Rotation

MOMENTS = (1.0, 2.0, 3.0)
OMEGA0 = (0.01, 2.0, 0.01)
Q0 = (0.0, 0.0, 0.0, 1.0)
DT, DURATION = 0.01, 200.0
STEPS = int(round(DURATION / DT))


def ours(name):
    """(seconds per simulated second, samples t, q, omega) for one of our integrators."""
    stepper = make_integrator(name, MOMENTS, DT, Q0, OMEGA0)
    t, q, w = [0.0], [Q0], [OMEGA0]
    start = time.perf_counter()
    for k in range(STEPS):
        stepper.step()
        if (k + 1) % 10 == 0:
            t.append(stepper.time)
            q.append(stepper.q)
            w.append(stepper.omega)
    return (time.perf_counter() - start) / DURATION, np.array(t), np.array(q), np.array(w)


def mujoco_body(moments, omega0, dt, integrator):
    """(mujoco, model, data): one free body, zero gravity, diagonal inertia, body rate omega0."""
    import mujoco
    xml = f"""
    <mujoco>
      <option gravity="0 0 0" timestep="{dt}" integrator="{integrator}"/>
      <worldbody><body><freejoint/>
        <inertial pos="0 0 0" mass="1" diaginertia="{moments[0]} {moments[1]} {moments[2]}"/>
      </body></worldbody>
    </mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qvel[3:6] = omega0
    return mujoco, model, data


def basilisk_body(moments, omega0, dt, integrator):
    """(sim, craft): a Basilisk hub (MRP attitude) at rest attitude, body rate omega0."""
    from Basilisk.simulation import spacecraft, svIntegrators
    from Basilisk.utilities import macros, SimulationBaseClass
    sim = SimulationBaseClass.SimBaseClass()
    process = sim.CreateNewProcess('dynamics')
    process.addTask(sim.CreateNewTask('step', macros.sec2nano(dt)))
    craft = spacecraft.Spacecraft()
    craft.hub.mHub = 1.0
    craft.hub.IHubPntBc_B = [[moments[0], 0, 0], [0, moments[1], 0], [0, 0, moments[2]]]
    craft.hub.sigma_BNInit = [[0.0], [0.0], [0.0]]
    craft.hub.omega_BN_BInit = [[c] for c in omega0]
    craft.setIntegrator(getattr(svIntegrators, integrator)(craft))
    return sim, craft


def basilisk_in_orbit(moments, omega0, q0, r0, v0, mu, dt, integrator):
    """
    (sim, craft, earth): a Basilisk hub on an orbit about a point-mass Earth of ``mu``.

    ``q0`` (x-y-z-w, body -> world) and ``omega0`` (rad/s, body) the attitude; ``r0``
    (m) and ``v0`` (m/s) the orbit's state at t = 0, world frame; ``dt`` (s) the task
    step and ``integrator`` the name of one of Basilisk's svIntegrators.
    """
    from Basilisk.simulation import spacecraft
    from Basilisk.utilities import simIncludeGravBody
    sim, craft = basilisk_body(moments, omega0, dt, integrator)
    gravity = simIncludeGravBody.gravBodyFactory()
    earth = gravity.createEarth()
    earth.isCentralBody = True
    earth.mu = mu
    craft.hub.r_CN_NInit = [[c] for c in r0]
    craft.hub.v_CN_NInit = [[c] for c in v0]
    # Basilisk's attitude: MRPs of B relative to N (N -> B); ours q is body -> world
    craft.hub.sigma_BNInit = [[c] for c in Rotation.from_quat(q0).as_mrp()]
    craft.gravField.gravBodies = spacecraft.GravBodyVector(list(gravity.gravBodies.values()))
    return sim, craft, earth


def basilisk_attitude(craft):
    """Return (q x-y-z-w body -> world, omega rad/s body) from a Basilisk craft's state."""
    from Basilisk.utilities import RigidBodyKinematics
    from scipy.spatial.transform import Rotation
    msg = craft.scStateOutMsg.read()
    rot = np.array(RigidBodyKinematics.MRP2C(msg.sigma_BN)).T
    return tuple(Rotation.from_matrix(rot).as_quat()), tuple(msg.omega_BN_B)


def mujoco_run(integrator):
    """Run MuJoCo: free joint, zero gravity, diagonal inertia; qvel[3:6] is the body rate."""
    mujoco, model, data = mujoco_body(MOMENTS, OMEGA0, DT, integrator)
    t, q, w = [0.0], [Q0], [OMEGA0]
    start = time.perf_counter()
    for k in range(STEPS):
        mujoco.mj_step(model, data)
        if (k + 1) % 10 == 0:
            t.append(data.time)
            wq = data.qpos[3:7]
            q.append((wq[1], wq[2], wq[3], wq[0]))
            w.append(tuple(data.qvel[3:6]))
    return (time.perf_counter() - start) / DURATION, np.array(t), np.array(q), np.array(w)


def basilisk_run(integrator):
    """Run a Basilisk spacecraft hub (MRP attitude) with an RK4 or RKF78 integrator."""
    from Basilisk.utilities import macros, RigidBodyKinematics
    sim, craft = basilisk_body(MOMENTS, OMEGA0, DT, integrator)
    sim.AddModelToTask('step', craft)
    recorder = craft.scStateOutMsg.recorder(macros.sec2nano(10 * DT))
    sim.AddModelToTask('step', recorder)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(DURATION))
    start = time.perf_counter()
    sim.ExecuteSimulation()
    cost = (time.perf_counter() - start) / DURATION
    t = recorder.times() * 1e-9
    q = np.array([Rotation.from_matrix(np.array(RigidBodyKinematics.MRP2C(s)).T).as_quat()
                  for s in recorder.sigma_BN])
    return cost, t, q, np.array(recorder.omega_BN_B)


def measure():
    """Rows for the peer table, ours first; a peer that is not installed is said so."""
    runs = [('rigid_body_dynamics exact', lambda: ours('exact')),
            ('rigid_body_dynamics rk4', lambda: ours('rk4')),
            ('MuJoCo, default (Euler)', lambda: mujoco_run('Euler')),
            ('MuJoCo, RK4', lambda: mujoco_run('RK4')),
            ('MuJoCo, implicitfast', lambda: mujoco_run('implicitfast')),
            ('Basilisk, RK4', lambda: basilisk_run('svIntegratorRK4')),
            ('Basilisk, RKF78', lambda: basilisk_run('svIntegratorRKF78'))]
    rows, base = [], None
    for label, run in runs:
        try:
            cost, t, q, w = run()
        except ImportError as err:
            rows.append([label, f'not installed ({err.name})', '', '', '', ''])
            continue
        energy, _, direction, _ = errors(MOMENTS, OMEGA0, Q0, t, q, w)
        q_exact, _ = FreeRigidBody(MOMENTS, OMEGA0, Q0).state_at(t[-1])
        final = float(quaternions.angle_between(q[-1], q_exact))
        if label.endswith('rk4'):
            base = cost
        rows.append([label, fmt(energy), fmt(direction), fmt(final), f'{cost * 1e3:.2f}', cost])
    for row in rows:
        if isinstance(row[-1], float):
            row[-1] = f'{row[-1] / base:.2f}' if base else 'n/a'
    return rows
