"""
Several hosts on this machine: Linux network namespaces on a private subnet.

``Hosts`` makes one namespace per host and one more holding a bridge (the
switch); each host has a veth link ``eth0`` to the switch, an address on a
private 10.x.y.0/24 subnet of its own (chosen from the process id so that
parallel runs never share one), loopback up and a multicast route so that
DDS discovery works across the switch. Nothing touches the machine's own
network namespace, and ``close()`` deletes every namespace it made (the veth
links go with them).

Processes start in a host with ``Hosts.popen(host, cmd)`` (``ip netns exec``,
which execs the command, so the pid is the node's own). They get DDS
discovery on that host's networks (``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET``:
inside the namespace that is loopback and the private subnet only) and UDP
only, so that nodes on different "hosts" do not take Fast DDS's shared-memory
shortcut through /dev/shm and really cross the network.
"""

import os
import shutil
import subprocess

#: Why hosts cannot be made here, or None (evaluated once by ``unavailable()``).
_REASON = []


def _ip(*args):
    """Run one ``ip`` command; raise RuntimeError with its message on failure."""
    done = subprocess.run(['ip', *args], capture_output=True, text=True, timeout=20)
    if done.returncode != 0:
        raise RuntimeError(f'ip {" ".join(args)}: {done.stderr.strip() or done.returncode}')
    return done.stdout


def unavailable():
    """Return why network namespaces cannot be made on this machine, or None if they can."""
    if not _REASON:
        if shutil.which('ip') is None:
            _REASON.append('the ip command (iproute2) is not installed')
        elif os.geteuid() != 0:
            _REASON.append('creating network namespaces needs root (CAP_SYS_ADMIN)')
        else:
            name = f'rbd{os.getpid()}probe'
            try:
                _ip('netns', 'add', name)
                _ip('netns', 'del', name)
                _REASON.append(None)
            except (RuntimeError, OSError, subprocess.TimeoutExpired) as err:
                _REASON.append(f'network namespaces cannot be created here: {err}')
    return _REASON[0]


class Hosts:
    """Hosts named by ``names`` on one private /24 behind a bridge; use as a context manager."""

    def __init__(self, names):
        pid = os.getpid()
        self.subnet = f'10.{200 + pid % 50}.{(pid // 50) % 250}'
        self.prefix = f'rbd{pid}'
        self.switch = f'{self.prefix}sw'
        self.namespaces = {}
        self.addresses = {}
        self._made = []
        try:
            self._make(names)
        except Exception:
            self.close()
            raise

    def _make(self, names):
        self._add(self.switch)
        _ip('-n', self.switch, 'link', 'add', 'br0', 'type', 'bridge', 'mcast_snooping', '0')
        _ip('-n', self.switch, 'link', 'set', 'br0', 'up')
        for k, host in enumerate(names, start=1):
            ns = f'{self.prefix}{host}'
            self._add(ns)
            port = f'p{k}'
            _ip('-n', self.switch, 'link', 'add', port, 'type', 'veth', 'peer', 'name', 'eth0',
                'netns', ns)
            _ip('-n', self.switch, 'link', 'set', port, 'master', 'br0')
            _ip('-n', self.switch, 'link', 'set', port, 'up')
            address = f'{self.subnet}.{k}'
            _ip('-n', ns, 'addr', 'add', f'{address}/24', 'dev', 'eth0')
            _ip('-n', ns, 'link', 'set', 'eth0', 'up')
            _ip('-n', ns, 'link', 'set', 'lo', 'up')
            _ip('-n', ns, 'route', 'add', '224.0.0.0/4', 'dev', 'eth0')
            self.namespaces[host] = ns
            self.addresses[host] = address

    def _add(self, ns):
        _ip('netns', 'add', ns)
        self._made.append(ns)

    def env(self):
        """Environment for a ROS process in a host: discovery on its own subnet, UDP only."""
        env = os.environ.copy()
        env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'SUBNET'
        env['FASTDDS_BUILTIN_TRANSPORTS'] = 'UDPv4'
        env.pop('ROS_LOCALHOST_ONLY', None)
        env.pop('ROS_STATIC_PEERS', None)
        return env

    def popen(self, host, cmd, **kwargs):
        """Start ``cmd`` in ``host`` (subprocess.Popen keyword arguments pass through)."""
        kwargs.setdefault('env', self.env())
        return subprocess.Popen(['ip', 'netns', 'exec', self.namespaces[host], *cmd], **kwargs)

    def run(self, host, cmd, timeout=60):
        """Run ``cmd`` in ``host`` to its end; returns the CompletedProcess (text output)."""
        return subprocess.run(['ip', 'netns', 'exec', self.namespaces[host], *cmd],
                              capture_output=True, text=True, timeout=timeout, env=self.env())

    def close(self):
        """Delete every namespace this object made (their links go with them)."""
        for ns in reversed(self._made):
            subprocess.run(['ip', 'netns', 'del', ns], capture_output=True, timeout=20)
        self._made = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
