"""
Named bodies with documented physical meaning.

Each preset gives principal moments (kg m^2, body = principal frame), an
initial angular velocity (rad/s, body frame), an initial attitude (x, y, z, w)
and the rates that show its motion well: ``integration_rate`` (Hz),
``publish_rate`` (Hz), ``real_time_factor`` and a ``duration`` (s) that covers
a few periods of what it teaches. The simulator's ``preset`` parameter and the
offline demo read them; explicit parameters override them.
"""

from dataclasses import dataclass
import math

from .analysis.theory import SIDEREAL_DAY


@dataclass(frozen=True)
class Preset:
    """A named body and initial state; see the module docstring for units."""

    name: str
    description: str
    moments: tuple
    omega0: tuple
    q0: tuple = (0.0, 0.0, 0.0, 1.0)
    integration_rate: float = 1000.0
    publish_rate: float = 100.0
    real_time_factor: float = 1.0
    duration: float = 20.0


_EARTH_A = 8.0077e37
_EARTH_SPIN = 2.0 * math.pi / SIDEREAL_DAY
_EARTH_TILT = 1.0e-6

PRESETS = {p.name: p for p in (
    Preset(
        name='symmetric_top',
        description='Oblate axisymmetric top (I3 = 1.5 I1) spinning mostly about its '
                    'symmetry axis: omega circles the axis at Omega = 1 rad/s in the body, '
                    'the axis circles L at |L|/I1 = 3.01 rad/s in the lab.',
        moments=(1.0, 1.0, 1.5), omega0=(0.3, 0.0, 2.0), duration=20.0),
    Preset(
        name='prolate_top',
        description='Prolate axisymmetric body (a pencil, I3 = I1 / 2): the body-frame '
                    'precession runs backwards (Omega < 0).',
        moments=(2.0, 2.0, 1.0), omega0=(0.3, 0.0, 2.0), duration=20.0),
    Preset(
        name='tennis_racket',
        description='Asymmetric body I = (1, 2, 3) spun about the intermediate axis: '
                    'unstable, it flips end over end every 11 s (Dzhanibekov effect).',
        moments=(1.0, 2.0, 3.0), omega0=(0.01, 2.0, 0.01), duration=60.0),
    Preset(
        name='stable_major',
        description='The same body spun near its largest-moment axis: a stable, small wobble.',
        moments=(1.0, 2.0, 3.0), omega0=(0.1, 0.1, 2.0), duration=20.0),
    Preset(
        name='stable_minor',
        description='The same body spun near its smallest-moment axis: stable too, '
                    'polhode around the minor axis.',
        moments=(1.0, 2.0, 3.0), omega0=(2.0, 0.1, 0.1), duration=20.0),
    Preset(
        name='sphere',
        description='Equal moments: omega is constant in the body and the lab; no precession.',
        moments=(1.0, 1.0, 1.0), omega0=(0.5, 0.3, 1.0), duration=10.0),
    Preset(
        name='cubesat_3u',
        description='A 4 kg 3U CubeSat (10 x 10 x 34 cm, prolate) tumbling after deployment: '
                    'a plant for detumbling and pointing controllers.',
        moments=(0.0419, 0.0419, 0.00667), omega0=(0.05, -0.03, 0.1), duration=120.0),
    Preset(
        name='earth_chandler',
        description='The Earth as an oblate body with (C - A)/A = 1/300 whose spin axis is '
                    '1e-6 rad off its figure axis: the free (Chandler) wobble has a period of '
                    '300 sidereal days (Shapiro, Classical Mechanics, section 4.4). Runs at 1 '
                    'step per minute, as fast as possible (real_time_factor 0).',
        moments=(_EARTH_A, _EARTH_A, _EARTH_A * (1.0 + 1.0 / 300.0)),
        omega0=(_EARTH_SPIN * math.tan(_EARTH_TILT), 0.0, _EARTH_SPIN),
        integration_rate=1.0 / 60.0, publish_rate=1.0 / 600.0,
        real_time_factor=0.0, duration=600.0 * SIDEREAL_DAY),
)}

DEFAULT = 'symmetric_top'
"""Name of the default preset."""


def get(name):
    """Return the preset called ``name``; ValueError listing the known names otherwise."""
    try:
        return PRESETS[name]
    except KeyError:
        raise ValueError(f'unknown preset {name!r}; choose one of '
                         f'{", ".join(sorted(PRESETS))}') from None
