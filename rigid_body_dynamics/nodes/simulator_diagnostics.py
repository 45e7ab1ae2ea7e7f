"""
The /diagnostics of attitude_simulator: two statuses per period, integrator and torque command.

``integrator``: steps, simulated time, requested and achieved real-time
factor, missed deadlines and lateness, quaternion norm error, drift since the
last torque, work, and in lockstep the answered and missed ticks and the wait
per tick. ``torque command``: age, timeout, frame, vector and the counters.
``magnetorquers`` (with a magnetic field): the dipole applied, the command held, the
counts of accepted, refused (non-finite, frame), clipped and stale commands;
``reaction wheels`` (with wheels): speeds, speed over limit, motor torques applied,
the held command, clipped and cut-off steps, motor work, friction loss, counters;
``sensors`` (with any sensor): each sensor's readings and the readings it did not
give, by reason (the star tracker's Sun and Earth exclusions, the sun sensor's field
of view and eclipses).
"""

import math
import time

from diagnostic_msgs.msg import DiagnosticStatus

from ..engine.pacer import LATE_LIMIT
from ..ros.conversions import status

_NS = 1_000_000_000


class SimulatorReport:
    """Builds the statuses of one body (``body``, its ``pace``; ``lockstep``: a Lockstep)."""

    def __init__(self, body, pace, lockstep):
        self.body, self.pace, self.lockstep = body, pace, lockstep
        self.achieved = 0.0
        self._misses_seen = 0

    def statuses(self, name, hardware_id):
        """Return [integrator, torque command (, reaction wheels)] DiagnosticStatus of ``name``."""
        out = [self._integrator(name, hardware_id), self._torque(name, hardware_id)]
        if self._health['wheels'] is not None:
            out.append(self._wheels(name, hardware_id))
        if self._health['magnetorquers'] is not None:
            out.append(self._magnetorquers(name, hardware_id))
        if self.body.sensors:
            out.append(self._sensors(name, hardware_id))
        return out

    def _sensors(self, name, hw):
        counts = self.body.sensor_health()
        values, parts = [], []
        for sensor, numbers in counts.items():
            values.append((f'{sensor} readings', numbers['valid']))
            missing = {why: n for why, n in numbers.items() if why != 'valid'}
            values += [(f'{sensor} excluded ({why})', n) for why, n in sorted(missing.items())]
            parts.append(f'{sensor} {numbers["valid"]}' + (
                f' ({sum(missing.values())} excluded)' if missing else ''))
        return status(f'{name}: sensors', DiagnosticStatus.OK,
                      'readings: ' + ', '.join(parts), values, hw)

    def _wheels(self, name, hw):
        w = self._health['wheels']
        counts, held = w['counts'], w['command']
        worst = max(w['speed fractions'], default=0.0)
        if worst >= 1.0:
            level, message = DiagnosticStatus.WARN, 'a wheel is at its speed limit'
        elif w['timed_out']:
            level, message = DiagnosticStatus.WARN, 'wheel command timed out: motors at 0'
        else:
            level, message = DiagnosticStatus.OK, ('no wheel command received' if held is None
                                                   else 'holding the last wheel command')
        if counts['rejected']:
            message += f'; {counts["rejected"]} rejected'
        return status(f'{name}: reaction wheels', level, message, [
            ('wheel speeds (rad/s)', list(w['speeds'])),
            ('speed / limit', list(w['speed fractions'])),
            ('motor torques applied (N m)', list(w['applied'])),
            ('command (N m)', 'none' if held is None else list(held[0])),
            ('timed out', w['timed_out']),
            ('clipped steps', list(w['clipped'])), ('cut-off steps', list(w['cut off'])),
            ('motor work since reset (J)', w['motor work']),
            ('friction loss since reset (J)', w['friction loss']),
            ('accepted', counts['accepted']), ('rejected', counts['rejected'])], hw)

    def _magnetorquers(self, name, hw):
        m = self._health['magnetorquers']
        counts, held = m['counts'], m['command']
        if m['timed_out']:
            level, message = DiagnosticStatus.WARN, 'magnetorquer command timed out: dipole 0'
        else:
            level, message = DiagnosticStatus.OK, ('no magnetorquer command received'
                                                   if held is None else
                                                   'holding the last magnetorquer command')
        refused = counts['rejected_non_finite'] + counts['rejected_frame']
        if refused:
            message += f'; {refused} rejected'
        return status(f'{name}: magnetorquers', level, message, [
            ('dipole applied (A m^2)', list(m['dipole'])),
            ('command (A m^2)', 'none' if held is None else list(held[0])),
            ('timed out', m['timed_out'])] + [(key, value) for key, value in counts.items()], hw)

    def _integrator(self, name, hw):
        body, pace = self.body, self.pace
        achieved = self.achieved = pace.achieved()
        max_late = pace.take_max_late()
        h = self._health = body.health()
        rtf = pace.rtf
        if h['paused']:
            level, message = DiagnosticStatus.OK, 'paused'
        elif self.lockstep:
            misses = pace.misses
            level = DiagnosticStatus.WARN if misses > self._misses_seen else DiagnosticStatus.OK
            self._misses_seen = misses
            message = ('lockstep: waiting for the first torque_cmd' if not pace.ticks else
                       f'lockstep at {achieved:.3g}x real time, {misses} missed ticks')
        elif rtf and achieved < 0.9 * rtf:
            level, message = DiagnosticStatus.WARN, (
                f'running at {achieved:.3g}x real time, {rtf:g}x requested')
        else:
            level, message = DiagnosticStatus.OK, 'running'
        return status(f'{name}: integrator', level, message, [
            ('integrator', body.integrator_name), ('dt (s)', body.dt), ('steps', h['steps']),
            ('simulated time (s)', h['time']), ('requested real-time factor', rtf),
            ('achieved real-time factor', achieved),
            (f'missed deadlines (> {LATE_LIMIT * 1e3:g} ms late)', pace.missed),
            ('latest step lateness in the last period (ms)', max_late),
            ('quaternion norm error', h['quaternion norm error']),
            ('energy drift since last torque (rel.)', h['energy drift']),
            ('|L| drift since last torque (rel.)', h['momentum drift']),
            ('L direction drift since last torque (rad)', h['direction drift']),
            ('work since reset (J)', h['work']),
        ] + self._lockstep_values(), hw)

    def _lockstep_values(self):
        """Lockstep's answered and missed ticks and the wall wait per tick ([] otherwise)."""
        if not self.lockstep:
            return []
        pace = self.pace
        mean, worst = pace.take_wait()
        return [('lockstep', True), ('control period (s)', pace.control_every * self.body.dt),
                ('answered ticks', pace.ticks), ('missed ticks', pace.misses),
                ('mean wait per answered tick (ms)', mean),
                ('longest wait in the last period (ms)', worst)]

    def _torque(self, name, hw):
        h = self._health
        cmd, counts, timed_out = h['command'], h['counts'], h['timed_out']
        age = (time.monotonic_ns() - cmd.received_ns) / _NS if cmd is not None else math.inf
        rejected = counts['rejected_non_finite'] + counts['rejected_frame']
        if cmd is None:
            level, message = DiagnosticStatus.OK, 'no command received'
        elif timed_out:
            level, message = DiagnosticStatus.WARN, f'timed out {age:.2f} s after the last command'
        else:
            level, message = DiagnosticStatus.OK, 'holding the last command'
        if rejected:
            message += f'; {rejected} rejected'
        return status(f'{name}: torque command', level, message, [
            ('command age (s)', age), ('timed out', timed_out),
            ('frame', 'none' if cmd is None else ('world' if cmd.world else 'body')),
            ('command (N m)', 'none' if cmd is None else list(cmd.vector)),
            ('timeout (s)', self.body.timeout_ns / _NS)] + list(counts.items()), hw)
