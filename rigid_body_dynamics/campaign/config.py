"""
A campaign's configuration file: its keys, their defaults, and the checks on them.

``KEYS`` is the reference table of the manual (doc/generate.py writes it from
here). :func:`load` reads a YAML file, refuses an unknown key, a scenario that
no node would take and a dispersion that cannot be checked, with the reason,
and returns a :class:`Campaign`.
"""

from dataclasses import dataclass
import hashlib
import json
import os

import yaml

from .dispersions import Dispersion
from .scenario import check_scenario, CONTROL_SOURCES, node_values, NODES, nodes_of, READBACK
from ..ros.parameters import ConfigurationError


@dataclass(frozen=True)
class Key:
    """One configuration key: ``name``, ``default`` (None: required or unset), ``meaning``."""

    name: str
    default: object
    meaning: str


#: The keys of a campaign file, in the manual's order.
KEYS = (
    Key('scenario', None, "The nodes' parameters, as a ROS 2 parameters file has them: "
        "sections ('/**', 'attitude_simulator', 'attitude_estimator', "
        "'attitude_controller') of 'ros__parameters:'. Or the path of such a file "
        '(relative to the campaign file): one file serves the nodes and the campaign.'),
    Key('runs', None, 'The number of runs (>= 2). Raised later, only the new runs fly: a '
        "run's record does not depend on how many there are."),
    Key('seed', 0, "The campaign's seed: with the run index and the parameter's name it "
        "seeds every draw, so a run's values do not depend on the other runs."),
    Key('duration', None, 'Simulated time of each run (s), a whole number of the '
        "simulator's control_period."),
    Key('record_period', 1.0, 'Time between two recorded samples (s), a whole number of '
        'control periods; the ensemble is judged at these times.'),
    Key('judge_from', 0.0, 'Judge the estimator from this time on (s): the start-up '
        'transient is left out of the ANEES verdict.'),
    Key('control_on', 'estimate', "What the controller flies on: estimate (the MEKF's "
        'attitude and the gyro less the estimated bias), truth, or none (a free body).'),
    Key('dispersions', {}, 'Parameter name -> {distribution: one of normal, uniform, '
        'rotation, direction, seed; its keys; node: (optional) the one node it applies to, '
        'else every node that declares the parameter}.'),
    Key('anees_level', 0.99, 'Two-sided confidence of the ANEES bounds at each time.'),
    Key('anees_min_share', 0.95, 'Share of times inside the bounds that a consistent '
        'verdict needs.'),
    Key('settling_band', 0.0, 'Pointing error (rad) inside which a run counts as settled '
        '(0: no settling times).'),
    Key('percentiles', [50.0, 95.0, 99.0], 'Percentiles of the pointing error and '
        'settling time reported.'),
    Key('output', None, "Folder of the results (default: the campaign file's name "
        "without .yaml, plus '_results', beside it)."),
)
_DEFAULTS = {k.name: k.default for k in KEYS}


@dataclass
class Campaign:
    """A checked campaign: the keys' values, the scenario and the dispersions."""

    values: dict
    scenario: dict
    dispersions: list
    output: str
    digest: str

    def __getattr__(self, name):
        """Return the value of the configuration key ``name``."""
        try:
            return self.__dict__['values'][name]
        except KeyError:
            raise AttributeError(name) from None


def _nominal(scenario, name, node):
    """Return the scenario's value of ``name`` (a dispersion's default), from the first node."""
    for n in ([node] if node else NODES):
        if name in NODES[n].params:
            return node_values(scenario, n)[name]
    raise ConfigurationError(f'no node declares {name!r}: it cannot be dispersed')


def build(values, base='.'):
    """Return the :class:`Campaign` of ``values`` (a mapping of keys; paths under ``base``)."""
    if not isinstance(values, dict):
        raise ConfigurationError('a campaign file is a mapping of keys: '
                                 + ', '.join(k.name for k in KEYS))
    unknown = sorted(set(values) - set(_DEFAULTS))
    if unknown:
        raise ConfigurationError(f'unknown key(s) {", ".join(unknown)}; the keys are '
                                 + ', '.join(k.name for k in KEYS))
    v = {**_DEFAULTS, **values}
    for name in ('scenario', 'runs', 'duration'):
        if v[name] is None:
            raise ConfigurationError(f'{name} is required')
    scenario = v['scenario']
    if isinstance(scenario, str):
        path = os.path.join(base, scenario)
        try:
            with open(path, encoding='utf-8') as f:
                scenario = yaml.safe_load(f)
        except (OSError, yaml.YAMLError) as err:
            raise ConfigurationError(f'scenario {path}: {err}') from None
    check_scenario(scenario)
    if not isinstance(v['runs'], int) or v['runs'] < 2:
        raise ConfigurationError(f'runs must be an integer >= 2, got {v["runs"]!r}')
    if not isinstance(v['seed'], int) or v['seed'] < 0:
        raise ConfigurationError(f'seed must be an integer >= 0, got {v["seed"]!r}')
    for name in ('duration', 'record_period'):
        if not isinstance(v[name], (int, float)) or not v[name] > 0:
            raise ConfigurationError(f'{name} must be a number of seconds > 0, got {v[name]!r}')
    if v['control_on'] not in CONTROL_SOURCES:
        raise ConfigurationError(f'control_on must be one of {", ".join(CONTROL_SOURCES)}, '
                                 f'got {v["control_on"]!r}')
    if not 0.0 < v['anees_level'] < 1.0 or not 0.0 < v['anees_min_share'] <= 1.0:
        raise ConfigurationError('anees_level must be inside (0, 1) and anees_min_share in '
                                 '(0, 1]')
    if not isinstance(v['dispersions'], dict):
        raise ConfigurationError('dispersions must map parameter names to their dispersion')
    dispersions = []
    for name, spec in v['dispersions'].items():
        node = spec.get('node') if isinstance(spec, dict) else None
        if node is not None and node not in NODES:
            raise ConfigurationError(f'dispersion of {name}: node must be one of '
                                     f'{", ".join(NODES)}, got {node!r}')
        d = Dispersion(name, spec, _nominal(scenario, name, node))
        for n in nodes_of(node, name):
            if name not in READBACK[n]:
                raise ConfigurationError(
                    f'{name} cannot be dispersed on {n}: the campaign cannot read it back '
                    'from the run to check that the drawn value took (give node: to '
                    'disperse it on another node only)')
        dispersions.append(d)
    # what a run's record depends on: not the number of runs (a campaign can grow) nor the
    # folder it is stored in
    kept = {k: val for k, val in values.items() if k not in ('runs', 'output')}
    text = json.dumps({'values': kept, 'scenario': scenario}, sort_keys=True, default=str)
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    return Campaign(v, scenario, dispersions, v['output'], digest)


def load(path):
    """Read and check the campaign file ``path`` (YAML); ConfigurationError says why not."""
    try:
        with open(path, encoding='utf-8') as f:
            values = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as err:
        raise ConfigurationError(f'{path}: {err}') from None
    campaign = build(values, os.path.dirname(os.path.abspath(path)))
    if campaign.output is None:
        stem = os.path.splitext(os.path.abspath(path))[0]
        campaign.output = stem + '_results'
    return campaign


def reference_markdown():
    """Return the manual's table of the campaign file's keys (Markdown)."""
    rows = ['| key | default | meaning |', '| --- | --- | --- |']
    for k in KEYS:
        default = 'required' if k.default is None and k.name != 'output' else (
            'beside the file' if k.name == 'output' else f'`{k.default}`')
        rows.append(f'| `{k.name}` | {default} | {k.meaning} |')
    return '\n'.join(rows)
