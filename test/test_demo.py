"""The README's main command: it runs the node and prints measured against theory."""

import os
import re
import subprocess
import sys


def _demo(*args):
    return subprocess.run([sys.executable, '-m', 'rigid_body_dynamics.demo', *args],
                          capture_output=True, text=True, timeout=120, env=os.environ.copy())


def _relative_errors(text):
    return [float(x) for x in re.findall(r'\(rel\. ([0-9.e+-]+)\)', text)]


def test_demo_runs_the_node_and_matches_theory():
    out = _demo('--preset', 'symmetric_top', '--duration', '4')
    assert out.returncode == 0, out.stderr
    assert 'started attitude_simulator' in out.stdout
    assert 'stopped attitude_simulator (exit code 0)' in out.stdout
    errors = _relative_errors(out.stdout)
    assert len(errors) == 2 and max(errors) < 1e-12


def test_demo_offline_and_bad_preset():
    out = _demo('--offline', '--preset', 'tennis_racket', '--duration', '50')
    assert out.returncode == 0, out.stderr
    assert 'unstable' in out.stdout and 'flip interval' in out.stdout
    assert max(_relative_errors(out.stdout)) < 1e-6
    out = _demo('--offline', '--preset', 'frisbee')
    assert out.returncode == 2 and "unknown preset 'frisbee'" in out.stderr
