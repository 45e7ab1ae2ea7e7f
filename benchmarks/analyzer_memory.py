"""
Where the analyzer's memory goes when it is fed faster than real time.

The simulator runs as fast as possible (a process, publishing every 10 ms of
simulated time, about 4 kHz of odom); attitude_analyzer (default 10 s window)
runs in this process so that its heap can be read: every 15 s of wall time its
resident memory, the C heap (glibc mallinfo2: bytes in use, arena size,
mmapped), Python's allocated blocks and live objects, and the samples in its
buffer. At the end ``malloc_trim(0)`` shows how much of the resident memory
was free heap kept by the allocator. ``./dev bench --only analyzer-memory``
(about 4 minutes).
"""

import ctypes
import os
import sys
import threading
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rigid_body_dynamics.nodes.analyzer import AttitudeAnalyzer

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import table  # noqa: E402, I100 (after the path set-up)
from nodes import Process, sim  # noqa: E402
from soak import rss_mb  # noqa: E402

MB = float(2 ** 20)


class MallInfo2(ctypes.Structure):
    """glibc's struct mallinfo2 (sizes in bytes)."""

    _fields_ = [(name, ctypes.c_size_t) for name in (
        'arena', 'ordblks', 'smblks', 'hblks', 'hblkhd', 'usmblks', 'fsmblks', 'uordblks',
        'fordblks', 'keepcost')]


def _libc():
    libc = ctypes.CDLL('libc.so.6')
    libc.mallinfo2.restype = MallInfo2
    return libc


def measure(seconds=240.0, period=15.0):
    """Feed the in-process analyzer from an as-fast-as-possible simulator; Markdown lines."""
    import gc
    libc = _libc()
    simulator = Process(sim('real_time_factor:=0.0', 'publish_rate:=100.0'))
    rclpy.init()
    node = AttitudeAnalyzer(parameter_overrides=[Parameter('window', value=10.0)])
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.1)
    thread = threading.Thread(target=spin)
    thread.start()
    rows = []
    start = time.monotonic()
    try:
        while time.monotonic() - start < seconds:
            time.sleep(period)
            heap = libc.mallinfo2()
            rows.append((f'{time.monotonic() - start:.0f}', f'{rss_mb(os.getpid()):.1f}',
                         f'{heap.uordblks / MB:.2f}', f'{heap.arena / MB:.2f}',
                         f'{heap.hblkhd / MB:.2f}', sys.getallocatedblocks(),
                         len(gc.get_objects()), node._received, len(node._buffer.t)))
    finally:
        stop.set()
        thread.join()
        simulator.close()
    node._analyse()                                   # one more trim, from this thread now
    trimmed = len(node._buffer.t)
    before, rss_before = libc.mallinfo2(), rss_mb(os.getpid())
    libc.malloc_trim(0)
    after = libc.mallinfo2()
    executor.shutdown()
    node.destroy_node()
    rclpy.shutdown()
    quarter = rows[len(rows) // 4]
    return [
        table(['wall (s)', 'RSS (MB)', 'C heap in use (MB)', 'C heap arena (MB)',
               'mmapped (MB)', 'Python blocks', 'Python objects', 'odom received',
               'samples in buffer'], rows),
        '',
        f'From {quarter[0]} s to the end: RSS {float(rows[-1][1]) - float(quarter[1]):+.1f} MB, '
        f'C heap in use {float(rows[-1][2]) - float(quarter[2]):+.2f} MB, arena '
        f'{float(rows[-1][3]) - float(quarter[3]):+.2f} MB, Python objects '
        f'{rows[-1][6] - quarter[6]:+d}. malloc_trim(0) at the end: RSS {rss_before:.1f} -> '
        f'{rss_mb(os.getpid()):.1f} MB, free heap {before.fordblks / MB:.2f} -> '
        f'{after.fordblks / MB:.2f} MB, in use {before.uordblks / MB:.2f} -> '
        f'{after.uordblks / MB:.2f} MB. Samples in the buffer after one more analysis: '
        f'{trimmed}.',
        '',
        'The buffer holds the window (10 s of stamps: at most 1000 samples right after each '
        '1 Hz analysis trims it) plus what arrived since the last analysis (up to one second '
        'of input), so the C heap in use rises and falls with it, and the arena keeps the '
        'high-water mark of those swings.',
    ]
