"""
One run of a campaign: the nodes' parameters, the offline engine, the example MEKF and a law.

A scenario is a ROS 2 parameters file's content (``{section: {'ros__parameters':
{...}}}``), the same file the nodes take: the sections ``/**`` and each node's own
(``attitude_simulator``, ``attitude_estimator``, ``attitude_controller``, with or
without ``/`` or ``/**/`` before the name) are merged per node as ROS merges
them. :func:`node_values` resolves and checks each node's values with the nodes'
own parameter tables, so a value the nodes refuse is refused here with the same
reason, and a name that no node declares is refused instead of ignored.

:func:`fly` runs one set of values as lockstep runs it (engine.lockstep): at each
control tick t_k the readings stamped up to t_k go to the estimator
(:class:`~rigid_body_dynamics.physics.mekf_fusion.MekfFusion`, as
attitude_estimator takes them), the law answers with a torque held over
[t_k, t_k+1), and the body integrates to the next tick. Nothing in it depends on
the wall clock, so a run's result is a function of its values, bit for bit,
whichever process runs it.
"""


import numpy as np

from ..engine import TorqueCommands
from ..nodes.controller import law_from, PARAMETERS as CONTROLLER
from ..nodes.estimator import fusion_from, PARAMETERS as ESTIMATOR
from ..nodes.simulator_parameters import body_from, PARAMETERS as SIMULATOR
from ..physics import quaternions as quat
from ..ros.parameters import ConfigurationError

#: The nodes a scenario configures, with their parameter tables.
NODES = {'attitude_simulator': SIMULATOR, 'attitude_estimator': ESTIMATOR,
         'attitude_controller': CONTROLLER}
#: The package's other nodes: their sections in a scenario are left alone (one file serves all).
OTHER_NODES = ('attitude_analyzer', 'poinsot_visualizer', 'attitude_fleet')
#: What the law flies on: the estimate (the MEKF's attitude and the gyro less its estimated
#: bias), the truth, or nothing (a free body: the estimator alone).
CONTROL_SOURCES = ('estimate', 'truth', 'none')
#: The controller modes a campaign flies (attitude_controller's mode).
MODES = ('slew', 'detumble')


def _sections_of(node):
    return ('/**', f'/**/{node}', node, f'/{node}')


def nodes_of(node, name):
    """Return the nodes a dispersion of ``name`` applies to: ``node``, or every declaring one."""
    return [node] if node else [n for n in NODES if name in NODES[n].params]


def node_values(scenario, node, extra=None):
    """
    Return ``node``'s raw parameter values in ``scenario`` (a parameters file's mapping).

    ``extra`` (name -> value) replaces them (a run's dispersed values). Names of the
    ``/**`` section that the node does not declare are left to the other nodes, as
    ROS does; a name in the node's own section that it does not declare is refused.
    """
    given, table = {}, NODES[node].params
    for key in _sections_of(node):
        section = scenario.get(key)
        if section is None:
            continue
        values = section.get('ros__parameters', {}) if isinstance(section, dict) else None
        if not isinstance(values, dict):
            raise ConfigurationError(f"scenario section {key!r} must hold 'ros__parameters:' "
                                     'and a mapping of parameter names to values')
        for name, value in values.items():
            if name in table:
                given[name] = value
            elif key != '/**':
                raise ConfigurationError(f'{node} has no parameter {name!r} (scenario section '
                                         f'{key!r})')
    given.update({k: v for k, v in (extra or {}).items() if k in table})
    return NODES[node].resolve(given)


def check_scenario(scenario):
    """Refuse scenario sections no node reads and ``/**`` names no node declares."""
    if not isinstance(scenario, dict):
        raise ConfigurationError('scenario must be a parameters file: a mapping of sections '
                                 "(e.g. '/**') to 'ros__parameters:'")
    known = {key for node in NODES for key in _sections_of(node)}
    others = {key for node in OTHER_NODES for key in _sections_of(node)}
    for key in scenario:
        if key not in known | others:
            raise ConfigurationError(f'scenario section {key!r} configures no node (a campaign '
                                     f'reads /**, {", ".join(NODES)}, and leaves '
                                     f'{", ".join(OTHER_NODES)} alone)')
    for node in NODES:
        node_values(scenario, node)       # a node section's names are the node's
    shared = (scenario.get('/**') or {}).get('ros__parameters', {}) or {}
    declared = set().union(*(table.params for table in NODES.values()))
    unknown = sorted(set(shared) - declared)
    if unknown:
        raise ConfigurationError(f'no node declares {", ".join(unknown)} (scenario section '
                                 "'/**')")


class Run:
    """
    One run's engine, estimator and law, made from validated values of the three nodes.

    ``simulator``, ``estimator``, ``controller``: each node's validated values
    (ParameterTable.validate). ``control_on``: one of CONTROL_SOURCES. The run is
    lockstep whatever the simulator's ``lockstep`` says: one command per
    ``control_period``.
    """

    def __init__(self, simulator, estimator, controller, control_on='estimate'):
        if control_on not in CONTROL_SOURCES:
            raise ConfigurationError(f'control_on must be one of {", ".join(CONTROL_SOURCES)}, '
                                     f'got {control_on!r}')
        if controller['mode'] not in MODES and control_on != 'none':
            raise ConfigurationError(f'a campaign flies attitude_controller mode '
                                     f'{" or ".join(MODES)}, got {controller["mode"]!r}')
        self.values = {'attitude_simulator': simulator, 'attitude_estimator': estimator,
                       'attitude_controller': controller}
        self.control_on = control_on
        self.every = simulator['control_every']
        self.body = body_from(simulator, publish_every=self.every)
        if not self.body.every('gyro') or not self.body.every('star_tracker'):
            raise ConfigurationError('the estimator needs the gyro (publish_imu) and the star '
                                     'tracker (star_tracker_rate > 0) of the simulator')
        self.fusion = fusion_from(estimator)
        # the law as attitude_controller makes it, from the inertia tensor's diagonal
        moments = tuple(float(m) for m in np.diag(self.body.inertia.tensor))
        self.law = None if control_on == 'none' else law_from(controller, moments)

    def fly(self, duration, record_period):
        """
        Fly ``duration`` s; record every ``record_period`` s (whole control periods) from 0.

        Returns a dict of arrays over the record times: ``t`` (s), ``q_true`` and
        ``q_estimate`` (N, 4; x, y, z, w, body -> world), ``covariance`` (N, 3, 3;
        rad^2, the estimate's attitude covariance about the world's axes),
        ``omega`` (N, 3; rad/s, body), ``bias_true`` and ``bias_estimate`` (N, 3;
        rad/s, body), ``torque`` (N, 3; N m, body, the command held from t), and the
        fusion's ``counts``.
        """
        body, fusion, law = self.body, self.fusion, self.law
        dt = body.dt * self.every
        ticks = int(round(duration / dt))
        record = int(round(record_period / dt))
        if ticks < 1 or record < 1 or abs(record * dt - record_period) > 1e-9 * record_period:
            raise ConfigurationError(f'duration and record_period must be whole control '
                                     f'periods ({dt:g} s), got {duration:g} and '
                                     f'{record_period:g} s')
        rows = {key: [] for key in ('t', 'q_true', 'q_estimate', 'covariance', 'omega',
                                    'bias_true', 'bias_estimate', 'torque')}
        bias = [(0.0, 0.0, 0.0)]
        with body.lock:
            items = body.first_items()
            for tick in range(ticks + 1):
                self._take(items, bias)
                q, omega = body.body_state()
                torque = (0.0, 0.0, 0.0)
                if law is not None:
                    if self.control_on == 'truth':
                        torque = law(q, omega)
                    else:
                        f = fusion.filter
                        rate = np.asarray(fusion.last_gyro[1]) - f.bias
                        torque = law(f.q, rate)
                    stamp = body.stamp_now()
                    body.hold(body.check(TorqueCommands.one(torque, False, 0, stamp)), 0, 1)
                if tick % record == 0:
                    f = fusion.filter
                    rows['t'].append(tick * dt)
                    rows['q_true'].append(q)
                    rows['q_estimate'].append(f.q)
                    rows['covariance'].append(f.attitude_covariance_world())
                    rows['omega'].append(omega)
                    rows['bias_true'].append(bias[0])
                    rows['bias_estimate'].append(f.bias)
                    rows['torque'].append(torque)
                if tick == ticks:
                    break
                items = []
                for _ in range(self.every):
                    body.advance(0, items)
        out = {key: np.array(value, dtype=float) for key, value in rows.items()}
        out['counts'] = dict(fusion.counts)
        return out

    def _take(self, items, bias):
        """Give the tick's readings to the estimator, in stamp order, gyro first at a stamp."""
        samples = sorted((item for item in items if hasattr(item, 'sensor')),
                         key=lambda s: (s.stamp_ns, s.sensor != 'gyro'))
        fusion = self.fusion
        for s in samples:
            r = s.reading
            if s.sensor == 'gyro':
                fusion.gyro(s.stamp_ns, np.array(r.omega_body))
                bias[0] = r.bias_body
            elif s.sensor == 'star_tracker':
                fusion.reading(s.stamp_ns, 'star_tracker', r.q)
            elif s.sensor == 'sun_sensor':
                fusion.reading(s.stamp_ns, 'sun_sensor', r.direction)
            elif s.sensor == 'magnetometer':
                fusion.reading(s.stamp_ns, 'magnetometer', r.field)


def _sensor(run, name):
    return next(sensor for _, sensor in run.body.sensors if sensor.name == name)


def _tracker_noise(run):
    """Return the estimator's star tracker sigmas (rad, tracker axes) from its covariance."""
    e = run.values['attitude_estimator']
    mount = np.asarray(quat.matrix(quat.normalize(np.asarray(e['star_tracker_orientation'],
                                                             dtype=float))))
    return np.sqrt(np.diag(mount.T @ run.fusion.tracker_covariance @ mount))


#: What each node made of a parameter, read back from the run's objects: a dispersed
#: parameter must have one, so that a draw that did not take is an error, not a default.
READBACK = {
    'attitude_simulator': {
        'inertia': lambda r: np.diag(r.body.inertia.tensor),
        'initial_orientation': lambda r: r.body.initial[0],
        'initial_angular_velocity': lambda r: r.body.initial[1],
        'noise_seed': lambda r: r.body.seed,
        'gyro_noise_density': lambda r: _sensor(r, 'gyro').errors.noise_density,
        'gyro_bias_random_walk': lambda r: _sensor(r, 'gyro').errors.bias_random_walk,
        'gyro_turn_on_bias': lambda r: _sensor(r, 'gyro').errors.turn_on_bias,
        'star_tracker_noise': lambda r: _sensor(r, 'star_tracker').noise,
        'star_tracker_orientation': lambda r: _sensor(r, 'star_tracker').orientation,
        'star_tracker_misalignment': lambda r: _sensor(r, 'star_tracker').misalignment,
        'magnetometer_noise': lambda r: _sensor(r, 'magnetometer').noise,
        'magnetometer_bias': lambda r: _sensor(r, 'magnetometer').bias,
        'sun_sensor_noise': lambda r: _sensor(r, 'sun_sensor').noise,
    },
    'attitude_estimator': {
        'gyro_noise_density': lambda r: r.fusion.noise_density,
        'gyro_bias_random_walk': lambda r: r.fusion.bias_walk,
        'initial_bias_sigma': lambda r: r.fusion.bias_sigma,
        'star_tracker_noise': _tracker_noise,
        'sun_sensor_noise': lambda r: r.fusion.sun_noise,
        'magnetometer_noise': lambda r: r.fusion.magnetometer_noise,
    },
    'attitude_controller': {
        'target_orientation': lambda r: r.law.target,
    },
}


def pointing_errors(q_true, target):
    """Return the angle (N,; rad) between each attitude q_true (N, 4) and ``target`` (4,)."""
    target = np.asarray(target, dtype=float)
    return quat.angle_between(target / np.linalg.norm(target), np.asarray(q_true, dtype=float))
