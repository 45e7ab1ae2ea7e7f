"""The ROS-free engine: one body's rules and its pacing, on a fake steady clock (no rclpy)."""

import math
import subprocess
import sys

import numpy as np
import pytest
from rigid_body_dynamics.engine import BodySimulation, Pace, TorqueCommands
from rigid_body_dynamics.engine import pacer
from rigid_body_dynamics.physics import FreeRigidBody, Inertia, make_integrator, quaternions

MS = 1_000_000


class FakeClock:
    """A steady clock the test moves by hand: ``clock()`` int ns, ``perf()`` s."""

    def __init__(self):
        self.ns = 10 ** 12

    def __call__(self):
        return self.ns

    def perf(self):
        return self.ns / 1e9

    def advance(self, ns):
        self.ns += int(ns)


def make_body(**kwargs):
    options = {'inertia': Inertia((1.0, 2.0, 3.0)), 'integrator': 'exact', 'rate': 1000.0,
               'initial': ((0.0, 0.0, 0.0, 1.0), (0.3, 1.5, -0.4)), 'torque_timeout': 0.5,
               'max_torque': 0.0, 'publish_every': 10, 'start_ns': 0}
    options.update(kwargs)
    return BodySimulation(**options)


def test_the_physics_the_engine_and_the_messages_import_no_ros():
    code = ('import sys, rigid_body_dynamics.physics, rigid_body_dynamics.engine; '
            'import rigid_body_dynamics.physics.environment; '
            'import rigid_body_dynamics.physics.analysis.findings_render; '
            'import rigid_body_dynamics.messages.bags, rigid_body_dynamics.messages.cdr; '
            'print(sorted(m for m in sys.modules if m == "rclpy" or m.startswith('
            '("rclpy.", "rosidl_runtime_py", "rigid_body_dynamics.ros"))))')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == '[]', out.stdout + out.stderr


def test_held_torque_matches_the_integrator_and_snapshots_carry_stamps():
    body, outbox = make_body(), []
    body.command((0.1, -0.2, 0.05), False, now_ns=0)
    with body.lock:
        for _ in range(100):
            body.advance(now_ns=50 * MS, outbox=outbox)
    ref = make_integrator('exact', (1.0, 2.0, 3.0), 1e-3, (0.0, 0.0, 0.0, 1.0), (0.3, 1.5, -0.4))
    for _ in range(100):
        ref.step((0.1, -0.2, 0.05))
    assert body.stepper.q == ref.q and body.stepper.omega == ref.omega
    assert [s.stamp_ns for s in outbox] == [k * 10 * MS for k in range(1, 11)]
    assert outbox[-1].torque_principal == (0.1, -0.2, 0.05) and outbox[-1].steps == 100


def test_watchdog_times_out_the_command_once_and_says_so():
    body, outbox = make_body(torque_timeout=0.5), []
    body.command((0.0, 0.0, 1.0), False, now_ns=0)
    with body.lock:
        body.advance(499 * MS, outbox)
        assert body.last_torque == (0.0, 0.0, 1.0)
        body.advance(501 * MS, outbox)
        body.advance(600 * MS, outbox)
    assert body.last_torque == (0.0, 0.0, 0.0) and body.timed_out
    assert body.take_notes() == ['torque command timed out: torque is zero until the next '
                                 'command']
    assert body.take_notes() == []
    body.command((0.0, 0.0, 1.0), False, now_ns=700 * MS)
    with body.lock:
        body.advance(701 * MS, outbox)
    assert body.last_torque == (0.0, 0.0, 1.0) and not body.timed_out


def test_clipping_rejection_and_forces_are_counted_and_leave_the_state():
    body = make_body(max_torque=0.2)
    before = (body.stepper.q, body.stepper.omega)
    assert body.command((math.nan, 0.0, 0.0), False, 0) == {'rejected_non_finite'}
    assert body.command_held is None and (body.stepper.q, body.stepper.omega) == before
    assert body.command((0.5, -0.1, -3.0), False, 0, force=(1.0, 0.0, 0.0)) == {
        'clipped', 'force_ignored', 'accepted'}
    assert body.command_held.vector == (0.2, -0.1, -0.2)
    body.reject('rejected_frame')
    assert body.health()['counts'] == {'accepted': 1, 'rejected_non_finite': 1,
                                       'rejected_frame': 1, 'clipped': 1, 'force_ignored': 1,
                                       'stale': 0}


def test_world_command_stays_fixed_in_the_world():
    body, outbox = make_body(), []
    tau_w = (0.05, -0.02, 0.04)
    body.command(tau_w, True, 0)
    l0 = np.array(body.stepper.angular_momentum_world)
    with body.lock:
        for _ in range(1000):
            body.advance(1 * MS, outbox)
    l1 = np.array(body.stepper.angular_momentum_world)
    np.testing.assert_allclose(l1 - l0, np.array(tau_w) * 1.0, atol=1e-13)
    # applied torque reported in the body frame: R^T tau_w at the step's end
    q = body.stepper.q
    np.testing.assert_allclose(outbox[-1].torque_principal, quaternions.rotate_inverse(q, tau_w),
                               atol=1e-15)


def test_reset_pause_and_a_rotated_inertia_change():
    body, outbox = make_body(), []
    body.command((0.0, 0.3, 0.0), False, 0)
    with body.lock:
        for _ in range(20):
            body.advance(1 * MS, outbox)
    q_b, w_b = body.body_state()
    rotated = Inertia.from_tensor([1.5, 2.0, 2.5, 0.2, 0.0, 0.1])
    lines = body.configure(inertia=rotated)
    assert lines and 'attitude and angular velocity kept' in lines[0]
    q_b2, w_b2 = body.body_state()
    np.testing.assert_allclose(w_b2, w_b, atol=1e-15)
    assert float(quaternions.angle_between(q_b, q_b2)) < 1e-15
    assert body.command_held.principal != (0.0, 0.3, 0.0)      # re-expressed in the new frame
    assert body.set_paused(True) is False and body.paused
    body.reset()
    assert body.steps == 0 and not body.paused and body.command_held is None
    assert body.snapshot().stamp_ns == 0


def test_drift_since_the_last_torque():
    body, outbox = make_body(), []
    body.command((0.0, 0.3, 0.0), False, 0)
    with body.lock:
        body.advance(1 * MS, outbox)
    body.command((0.0, 0.0, 0.0), False, 2 * MS)
    with body.lock:
        for _ in range(2000):
            body.advance(3 * MS, outbox)
    h = body.health()
    assert h['energy drift'] < 1e-14 and h['momentum drift'] < 1e-14
    assert h['direction drift'] < 1e-14 and h['work'] != 0.0


def test_pace_wakes_at_ticks_counts_lateness_and_drops_a_backlog():
    """Real time: woken at publish ticks (10 steps here), late wakes counted, backlog dropped."""
    clock = FakeClock()
    body = make_body()
    backlog = []
    pace = Pace(body, 1.0, clock=clock, perf=clock.perf, on_backlog=backlog.append)
    outbox = []
    assert pace.due(outbox) == pytest.approx(10e-3)             # the first tick: step 10
    clock.advance(10 * MS)
    wait = pace.due(outbox)
    assert body.steps == 10 and len(outbox) == 1 and wait == pytest.approx(10e-3)
    assert pace.missed == 0 and pace.take_max_late() == 0.0      # on time
    clock.advance(17 * MS)                                        # the tick at 20 ms: 7 ms late
    wait = pace.due(outbox)
    assert body.steps == 27 and [s.steps for s in outbox] == [10, 20]
    assert wait == pytest.approx(3e-3) and pace.missed == 1
    assert pace.take_max_late() == pytest.approx(7.0)
    clock.advance(int(0.3e9))                                     # 300 ms behind: dropped
    pace.due(outbox)
    assert backlog == [300] and body.steps == 28
    pace.set_rtf(2.0)
    clock.advance(10 * MS)
    pace.due(outbox)
    assert body.steps == 48                                        # 2x: 20 steps in 10 ms
    assert pace.achieved() > 0.0
    body.configure(publish_every=1000)
    clock.advance(10 * MS)
    pace.due(outbox)
    assert pace.due(outbox) == pytest.approx(pacer.COMMAND_LOOK, abs=1e-3)  # at least every 20 ms


def test_the_schedule_starts_when_its_thread_does_not_at_construction():
    """Getting ready (DDS, imports, a busy machine) is no missed deadline: issue 22's demo."""
    from rigid_body_dynamics.engine import Loop, Member

    class OneCycle:
        """A stop event that lets Loop.run do one cycle."""

        def __init__(self):
            self.looks = 0

        def is_set(self):
            self.looks += 1
            return self.looks > 1

        def wait(self, _seconds):
            pass
    clock = FakeClock()
    backlogs = []
    paces = [Pace(make_body(), rtf, clock=clock, perf=clock.perf, on_backlog=backlogs.append)
             for rtf in (1.0, 4.0)]
    clock.advance(int(0.4e9))                      # 0.4 s from construction to the thread
    loop = Loop([Member(p, lambda item: None) for p in paces], clock=clock.perf,
                perf=clock.perf)
    loop.run(OneCycle())
    assert backlogs == [] and [p.body.steps for p in paces] == [0, 0]
    assert [p.missed for p in paces] == [0, 0]
    for _ in range(4):                             # the 4x body's ticks: every 2.5 ms
        clock.advance(2501 * 1000)                 # (1 us on: float due times)
        loop.cycle()
    assert [p.body.steps for p in paces] == [10, 40] and [p.missed for p in paces] == [0, 0]
    # anchored at construction instead, the same wait is a backlog dropped with a warning
    late = Pace(make_body(), 4.0, clock=clock, perf=clock.perf, on_backlog=backlogs.append)
    clock.advance(int(0.4e9))
    late.due([])
    assert backlogs == [1600]


def test_achieved_rate_is_counted_wake_to_wake_not_to_the_call():
    """A body woken every 20 ms (50 Hz ticks) reads 1 in every 1 s period, wherever it is read."""
    clock = FakeClock()
    body = make_body(publish_every=20)
    pace = Pace(body, 1.0, clock=clock, perf=clock.perf)
    outbox, readings = [], []
    clock.advance(int(pace.due(outbox) * 1e9))
    pace.achieved()
    for offset in (3, 7, 11, 15, 19, 5):         # ms after a wake at which diagnostics read it
        end = clock.ns + 1000 * MS
        while True:
            wait = int(round(pace.due(outbox) * 1e9))
            if clock.ns + wait > end + offset * MS:
                break
            clock.advance(wait)
        clock.ns = end + offset * MS
        readings.append(pace.achieved())
    # each exactly 1 (wake to wake, every wake on time); counted to the call they read
    # 0.985-1.017 here
    assert readings == pytest.approx([1.0] * 6, abs=1e-12)
    assert pace.missed == 0
    body.set_paused(True)
    clock.advance(1000 * MS)
    assert pace.achieved() == 0.0
    body.set_paused(False)
    pace.anchor()                                # as the node resumes a body
    clock.advance(5 * MS)
    assert pace.achieved() == 0.0                # no wake yet since the pause
    for _ in range(50):                          # 1 s on time: the paused second counts too
        clock.advance(int(round(pace.due(outbox) * 1e9)))
    pace.due(outbox)
    assert 0.45 < pace.achieved() < 0.55


def test_commands_act_from_the_step_they_came_in_as_if_stepped_every_deadline():
    """
    Woken only at ticks, a body ends bit for bit where stepping at every deadline ends.

    Commands (some non-finite, a gap longer than the 50 ms watchdog) come at random
    steady times. The reference takes the pending ones before each step at its deadline and
    steps; the paced body is woken at its ticks (with jitter) and gets them with their
    receive times. Same steps, same torques at the same steps, same counts, same snapshots.
    """
    rng = np.random.default_rng(3)
    clock = FakeClock()
    t0 = clock.ns
    times = np.sort(rng.uniform(0.0, 0.4e9, 60)).astype(np.int64) + t0
    times[40:] += int(0.2e9)                                          # a gap: the watchdog acts
    vectors = rng.normal(scale=0.2, size=(60, 3))
    vectors[[7, 33]] = np.nan
    from rigid_body_dynamics.physics.sensors import Gyro, GyroErrors
    options = {'publish_every': 10, 'torque_timeout': 0.05, 'seed': 9}
    paced, ref = (make_body(sensors=[Gyro(GyroErrors(1e-3, 1e-4, 1e-3), 250.0)], **options)
                  for _ in range(2))
    pending = list(zip(times.tolist(), vectors))

    def inbox():
        came = [p for p in pending if p[0] <= clock.ns]
        del pending[:len(came)]
        return [TorqueCommands([c[0] for c in came], [c[1] for c in came])] if came else []
    pace = Pace(paced, 1.0, clock=clock, perf=clock.perf, inbox=inbox)
    out, ref_out = [], []
    while clock.ns < t0 + int(0.7e9):
        wait = pace.due(out)
        clock.advance(wait * 1e9 + rng.uniform(0, 0.4 * MS))
    k = 0
    with ref.lock:
        for step in range(1, paced.steps + 1):
            at = pace.anchor_ns + step * MS
            while k < 60 and times[k] <= at:
                ref.command(vectors[k], False, int(times[k]))
                k += 1
            ref.advance(at, ref_out)
    assert paced.steps > 650 and paced.stepper.q == ref.stepper.q
    assert paced.stepper.omega == ref.stepper.omega and paced.counts == ref.counts
    assert len(out) > 200 and [s[:5] for s in out] == [s[:5] for s in ref_out]   # and imu
    assert paced.counts['rejected_non_finite'] == 2
    # the watchdog zeroed the torque at some tick
    assert any(getattr(s, 'torque_principal', None) == (0.0, 0.0, 0.0) for s in out[100:])


def test_pace_as_fast_as_possible_and_paused():
    clock = FakeClock()
    body = make_body()
    ticks = iter(range(10 ** 9))

    def perf():               # each look at the clock moves it 0.5 ms: a 5 ms batch = 10 steps
        return next(ticks) * 0.0005
    pace = Pace(body, 0.0, clock=clock, perf=perf)
    assert pace.due([]) == pacer.AFAP_YIELD and body.steps == 9
    body.set_paused(True)
    assert pace.due([]) == pacer.PAUSED_WAIT and body.steps == 9


@pytest.mark.parametrize('name', ['exact', 'rk4'])
@pytest.mark.parametrize('omega', [(0.3, 1.5, -0.4), (1e-9, 1.0, 1e-9)])   # the second: RK
def test_free_steps_at_once_equal_one_at_a_time(name, omega):
    """Integrator.free_steps(n): the state of n torque-free step() calls, bit for bit."""
    one = make_integrator(name, (1.0, 2.0, 3.0), 1e-3, (0.0, 0.0, 0.0, 1.0), omega)
    many = make_integrator(name, (1.0, 2.0, 3.0), 1e-3, (0.0, 0.0, 0.0, 1.0), omega)
    for _ in range(3):
        for _ in range(97):
            one.step()
        many.free_steps(97)
        assert (one.q, one.omega, one.steps) == (many.q, many.omega, many.steps)
        one.step((0.01, 0.0, -0.02))
        many.step((0.01, 0.0, -0.02))


def test_torque_free_steps_stay_exact():
    body, outbox = make_body(publish_every=1000), []
    with body.lock:
        for _ in range(5000):
            body.advance(0, outbox)
    q, w = FreeRigidBody((1.0, 2.0, 3.0), (0.3, 1.5, -0.4)).state_at(5.0)
    assert float(quaternions.angle_between(outbox[-1].q_principal, q)) < 1e-13


def test_lockstep_waits_for_each_tick_and_holds_from_it():
    """10 steps per tick: the state at t_k goes out, a command stamped >= t_k releases the tick."""
    from rigid_body_dynamics.engine import Lockstep
    clock = FakeClock()
    body = make_body(publish_every=5, torque_timeout=0.0)
    lock = Lockstep(body, control_every=10, timeout=0.2, clock=clock, perf=clock.perf)
    outbox = []
    assert lock.due(outbox) == 0.0 and outbox == [] and body.steps == 0   # waiting, no timeout
    clock.advance(int(1.5e9))
    lock.due(outbox)
    assert [s.stamp_ns for s in outbox] == [0]                # t_0 again for a late controller
    lock.mailbox.put(TorqueCommands.one((0.1, 0.0, 0.0), False, clock(), stamp_ns=0))
    assert lock.wait(0.0)                                     # the wait ends: a command came
    outbox.clear()
    lock.due(outbox)
    assert body.steps == 10 and [s.stamp_ns for s in outbox] == [5 * MS, 10 * MS]
    assert lock.ticks == 1 and lock.misses == 0
    lock.due(outbox)
    assert body.steps == 10                                   # the held command is for t_0
    lock.mailbox.put(TorqueCommands.one((0.2, 0.0, 0.0), False, clock(), stamp_ns=5 * MS))
    lock.due(outbox)
    assert body.steps == 10 and body.counts['stale'] == 1
    assert body.command_held.vector == (0.1, 0.0, 0.0) and body.take_events() == {
        'accepted', 'stale'}
    lock.mailbox.put(TorqueCommands.one((0.2, 0.0, 0.0), False, clock(), stamp_ns=10 * MS))
    lock.due(outbox)
    assert body.steps == 20
    # the same commands offline: a body stepped with 0.1 for 10 steps, then 0.2 for 10
    ref = make_integrator('exact', (1.0, 2.0, 3.0), 1e-3, (0.0, 0.0, 0.0, 1.0), (0.3, 1.5, -0.4))
    for torque in [(0.1, 0.0, 0.0)] * 10 + [(0.2, 0.0, 0.0)] * 10:
        ref.step(torque)
    assert body.stepper.q == ref.q and body.stepper.omega == ref.omega
    # no answer within the timeout: a miss, noted once, the last command held
    clock.advance(int(0.25e9))
    lock.due(outbox)
    clock.advance(int(0.25e9))
    lock.due(outbox)
    assert body.steps == 40 and lock.misses == 2 and body.command_held.vector == (0.2, 0.0, 0.0)
    assert len([n for n in body.take_notes() if 'lockstep: no torque_cmd' in n]) == 1
    lock.mailbox.put(TorqueCommands.one((0.0, 0.0, 0.0), False, clock(), stamp_ns=40 * MS))
    lock.due(outbox)
    assert body.steps == 50 and any('answered again after 2' in n for n in body.take_notes())
    mean, worst = lock.take_wait()
    assert worst >= mean >= 0.0
    body.set_paused(True)
    assert lock.due(outbox) == pacer.PAUSED_WAIT and body.steps == 50


def test_lockstep_publishes_the_tick_state_when_it_is_not_a_publish_tick():
    from rigid_body_dynamics.engine import Lockstep
    clock = FakeClock()
    body = make_body(publish_every=7, torque_timeout=0.0)
    lock = Lockstep(body, control_every=10, timeout=0.0, clock=clock, perf=clock.perf)
    outbox = []
    lock.mailbox.put(TorqueCommands.one((0.0, 0.0, 0.0), False, clock(), stamp_ns=0))
    lock.due(outbox)
    assert [s.stamp_ns for s in outbox] == [7 * MS, 10 * MS]
    assert [s.odom_only for s in outbox] == [False, True]     # the tick: odom (clock, TF)


def test_disturbances_are_summed_into_the_integrated_and_reported_torque():
    """Constant body and world disturbances and the gravity gradient, against the integrator."""
    from rigid_body_dynamics.engine import Disturbances
    from rigid_body_dynamics.physics.environment import (GravityGradient, KeplerOrbit,
                                                         SpaceEnvironment)
    orbit = KeplerOrbit((1.0, 0.0, 0.3, 0.0, 0.0, 0.0), mu=0.0025, planet_radius=0.0)  # n 0.05
    d = Disturbances(body=(0.01, 0.0, 0.0), world=(0.0, 0.0, 0.02), orbit=orbit,
                     gravity_gradient=True)
    body, outbox = make_body(disturbances=d, publish_every=50), []
    body.command((0.0, 0.1, 0.0), False, now_ns=0)
    with body.lock:
        for _ in range(100):
            body.advance(now_ns=0, outbox=outbox)
    gg = SpaceEnvironment(orbit, None, [GravityGradient((1.0, 2.0, 3.0), 0.0025)])
    ref = make_integrator('exact', (1.0, 2.0, 3.0), 1e-3, (0.0, 0.0, 0.0, 1.0), (0.3, 1.5, -0.4))
    for _ in range(100):
        ref.step((0.01, 0.1, 0.0), (0.0, 0.0, 0.02), gg)
    assert body.stepper.q == ref.q and body.stepper.omega == ref.omega
    q = ref.q
    world = quaternions.rotate_components((-q[0], -q[1], -q[2], q[3]), (0.0, 0.0, 0.02))
    expected = np.array((0.01, 0.1, 0.0)) + world + gg(0.1, *q, *ref.omega)
    np.testing.assert_allclose(outbox[-1].torque_principal, expected, rtol=0, atol=1e-17)
    # the snapshot carries the orbit's position and velocity at its time
    assert outbox[-1].position == orbit.state(0.1)
    # an integrator change mid-run keeps the orbit's clock (the environment's epoch)
    with body.lock:
        body.configure(integrator='rk4')
        assert body.plant.field.epoch == pytest.approx(0.1)


def test_loop_publishes_within_its_budget_and_schedules_diagnostics():
    """engine.Loop over two bodies: every snapshot published in order, diagnostics each period."""
    from rigid_body_dynamics.engine import Loop, Member
    clock = FakeClock()
    published, diagnosed = [], []
    members = []
    for k in range(2):
        body = make_body(publish_every=1)
        pace = Pace(body, 1.0, clock=clock, perf=clock.perf)
        members.append(Member(pace, lambda item, k=k: published.append((k, item.stamp_ns)),
                              diagnostics=lambda k=k: diagnosed.append(k)))
    seconds = [0.0]
    loop = Loop(members, publish_budget=0.0, diagnostics_period=1.0,
                clock=lambda: seconds[0], perf=lambda: seconds[0])
    clock.advance(3 * MS)
    wait = loop.cycle()
    # a budget of 0 publishes only the backlog beyond 3 items per member (6 here, 0 over)
    assert len(loop.pending) == 6 and published == [] and wait == 0.0
    loop.budget = float('inf')
    loop.cycle()
    assert published == [(0, 1 * MS), (0, 2 * MS), (0, 3 * MS),
                         (1, 1 * MS), (1, 2 * MS), (1, 3 * MS)]
    seconds[0] = 0.5                 # diagnostics spread over the period: one member by now
    loop.cycle()
    assert diagnosed == [0]
    seconds[0] = 1.0
    loop.cycle()
    assert diagnosed == [0, 1]
    seconds[0] = 3.2                 # after a stall: each member once, not every missed turn
    loop.cycle()
    assert diagnosed == [0, 1, 0, 1]
    seconds[0] = 3.5
    loop.cycle()
    assert diagnosed == [0, 1, 0, 1, 0]
    assert 0.0 < loop.cycle() <= 0.05                    # sleeps until the next step, capped


def test_loop_looks_only_at_due_members_and_at_once_at_a_moved_schedule():
    """
    engine.Loop: a member is looked at when its step is due, not before; a resume re-anchors.

    One body paused (its pace says: look again in PAUSED_WAIT), one running at 1 kHz:
    while paused the first is not stepped; after resume + anchor (what the node's pause
    service does) it is stepped at its next step, long before PAUSED_WAIT is over.
    """
    from rigid_body_dynamics.engine import Loop, Member
    from rigid_body_dynamics.engine.pacer import PAUSED_WAIT
    clock = FakeClock()
    bodies = [make_body(publish_every=1) for _ in range(2)]     # a tick every step
    paces = [Pace(b, 1.0, clock=clock, perf=clock.perf) for b in bodies]
    calls = [0, 0]

    def counting(k):
        due = paces[k].due

        def wrapped(outbox):
            calls[k] += 1
            return due(outbox)
        return wrapped
    for k, pace in enumerate(paces):
        pace.due = counting(k)
    loop = Loop([Member(p, lambda item: None) for p in paces],
                clock=lambda: clock.ns / 1e9, perf=clock.perf)
    bodies[0].set_paused(True)
    for _ in range(20):                         # 20 ms in 1 ms cycles
        clock.advance(MS)
        loop.cycle()
    assert bodies[0].steps == 0 and bodies[1].steps == 20
    assert calls[0] == 1 and calls[1] == 20     # the paused body: one look, not twenty
    bodies[0].set_paused(False)
    paces[0].anchor()
    clock.advance(MS)
    loop.cycle()                     # the move is seen: looked at, and its first step is due
    assert calls[0] == 2 and bodies[0].steps == 1
    clock.advance(MS)
    loop.cycle()
    assert bodies[0].steps == 2 and bodies[1].steps == 22
    assert 2 * MS < PAUSED_WAIT * 1e9     # (so the steps came from the move, not a late look)


def test_paces_anchor_on_whole_periods_and_spread_over_phases():
    """
    Steps on whole periods of the clock plus the phase; 40 bodies: 3 phases of the wake period.

    1 kHz steps, a tick every 10: the groups' phases are 0, 10/3 and 20/3 steps, so their
    ticks (wakes) fall 3.3 ms apart, not their steps alone.
    """
    from rigid_body_dynamics.engine.pacer import spread_phases
    clock = FakeClock()
    clock.advance(0.3 * MS)                       # between two whole periods of 1 ms
    paces = [Pace(make_body(), 1.0, clock=clock, perf=clock.perf) for _ in range(40)]
    assert {p.anchor_ns % MS for p in paces} == {0} and paces[0].wake_steps == 10
    spread_phases(paces)
    assert sorted({p.phase for p in paces}) == pytest.approx([0.0, 10 / 3, 20 / 3])
    assert sum(p.phase == 0.0 for p in paces) == 14      # at most 16 due at one instant
    ticks = set()
    for p in paces:
        assert (p.anchor_ns - p.phase * MS) % MS == pytest.approx(0.0, abs=1e-3)
        assert 0 <= clock.ns - (p.anchor_ns - p.phase * MS) < MS  # first step: 1 + phase
        ticks.add(round((p.deadline(10) - paces[0].deadline(10)) / MS, 3))
    assert ticks == {0.0, 3.333, 6.667}                    # the groups' ticks 3.3 ms apart
    with pytest.raises(ValueError, match='phase'):
        paces[0].set_phase(-0.5)


def test_a_batch_of_commands_counts_and_holds_as_one_by_one():
    """A batch applied whole: the counters and the held command equal command() per message."""
    rng = np.random.default_rng(5)
    vectors = rng.normal(scale=0.3, size=(40, 3))
    vectors[[3, 17]] = np.nan
    vectors[21, 1] = np.inf
    forces = np.zeros((40, 3))
    forces[[5, 30], 0] = 1.0
    one, many = make_body(max_torque=0.25), make_body(max_torque=0.25)
    for v, f in zip(vectors, forces):
        one.command(v, False, 7, force=tuple(f))
    whole = many.check(TorqueCommands([7] * 40, vectors, False, forces=forces))
    events = many.hold(whole, 0, len(whole))
    assert many.counts == one.counts and many.command_held == one.command_held
    assert events == {'accepted', 'clipped', 'force_ignored', 'rejected_non_finite'}
    assert many.counts['rejected_non_finite'] == 3 and many.counts['force_ignored'] == 2
    nothing = make_body()
    refused = nothing.check(TorqueCommands([0, 0], np.full((2, 3), np.nan), True))
    assert nothing.hold(refused, 0, 2) == {'rejected_non_finite'}
    assert nothing.command_held is None
    # in slices (what a pace does, a slice per step): after each slice, as one by one
    sliced, ref = make_body(max_torque=0.25), make_body(max_torque=0.25)
    slices = ((0, 3), (3, 4), (4, 17), (17, 18), (18, 40))
    received = [100 + stop for start, stop in slices for _ in range(start, stop)]
    batch = sliced.check(TorqueCommands(received, vectors, False, forces=forces))
    for start, stop in slices:
        sliced.hold(batch, start, stop)
        for v, f in zip(vectors[start:stop], forces[start:stop]):
            ref.command(v, False, 100 + stop, force=tuple(f))
        assert sliced.counts == ref.counts and sliced.command_held == ref.command_held


# --- Reaction wheels through the one command path ---------------------------------------------

def _wheels():
    from rigid_body_dynamics.physics.dynamics.gyrostat import Wheels
    pyramid = [c / math.sqrt(3.0) for g in ((1, 1, 1), (-1, 1, 1), (-1, -1, 1), (1, -1, 1))
               for c in g]
    return Wheels(pyramid, (0.02,) * 4, max_torque=(0.05,) * 4, max_speed=(200.0,) * 4,
                  coulomb=(1e-4,) * 4, viscous=(1e-6,) * 4)


def test_wheel_commands_act_from_their_step_as_offline_and_bad_ones_are_counted():
    """Paced wheel commands (with bad ones) = a gyrostat stepped offline at the same deadlines."""
    from rigid_body_dynamics.engine import WheelCommands
    from rigid_body_dynamics.physics.dynamics.gyrostat import GyrostatIntegrator
    clock = FakeClock()
    t0 = clock.ns
    rng = np.random.default_rng(8)
    times = (np.sort(rng.uniform(0.0, 0.3e9, 30)).astype(np.int64) + t0).tolist()
    commands = [tuple(rng.normal(scale=0.03, size=4)) for _ in times]
    commands[5] = (0.01, 0.02)                               # wrong length
    commands[9] = (math.nan, 0.0, 0.0, 0.0)                  # non-finite
    wheels = _wheels()
    body = make_body(wheels=wheels, wheel_speeds=(100.0, -50.0, 0.0, 20.0), publish_every=10)
    pending = list(zip(times, commands))

    def inbox():
        came = [p for p in pending if p[0] <= clock.ns]
        del pending[:len(came)]
        return [WheelCommands([c[0] for c in came], [c[1] for c in came])] if came else []
    pace = Pace(body, 1.0, clock=clock, perf=clock.perf, inbox=inbox)
    out = []
    while clock.ns < t0 + int(0.4e9):
        clock.advance(pace.due(out) * 1e9 + rng.uniform(0, 0.3 * MS))
    assert body.wheel_counts == {'accepted': 28, 'rejected': 2}
    ref = GyrostatIntegrator((1.0, 2.0, 3.0), wheels, 1e-3, omega0=(0.3, 1.5, -0.4),
                             speeds0=(100.0, -50.0, 0.0, 20.0))
    held, k = (0.0,) * 4, 0
    for step in range(1, body.steps + 1):
        at = pace.anchor_ns + step * MS
        while k < len(times) and times[k] <= at:
            if len(commands[k]) == 4 and all(math.isfinite(c) for c in commands[k]):
                held = commands[k]
            k += 1
        ref.command_motors(held)
        ref.step()
    assert body.steps > 350 and body.stepper.q == ref.q and body.stepper.omega == ref.omega
    assert body.stepper.speeds == ref.speeds and body.stepper.applied == ref.applied
    snaps = [s for s in out if getattr(s, 'wheels', None) is not None]
    assert len(snaps) > 30 and all(len(s.wheels.speeds) == 4 for s in snaps)
    assert body.take_events() >= {'wheel_accepted', 'wheel_rejected'}


def test_wheel_commands_time_out_like_the_torque_and_reset_restores_the_speeds():
    from rigid_body_dynamics.engine import WheelCommands
    body = make_body(wheels=_wheels(), wheel_speeds=(10.0, 0.0, 0.0, 0.0), torque_timeout=0.05)
    body.hold(body.check(WheelCommands.one((0.01, 0.0, 0.0, 0.0), 0)), 0, 1)
    outbox = []
    with body.lock:
        for k in range(100):
            body.advance(k * MS, outbox)
    assert body.stepper.applied == (0.0,) * 4 and body.wheel_timed_out
    assert any('wheel command timed out' in n for n in body.take_notes())
    body.reset()
    assert body.stepper.speeds == (10.0, 0.0, 0.0, 0.0) and body.wheel_held is None


def test_lockstep_with_wheels_a_wheel_command_answers_the_tick():
    """Bit for bit: the state after three ticks equals a gyrostat stepped offline with them."""
    from rigid_body_dynamics.engine import Lockstep, WheelCommands
    from rigid_body_dynamics.physics.dynamics.gyrostat import GyrostatIntegrator
    clock = FakeClock()
    wheels = _wheels()
    body = make_body(wheels=wheels, torque_timeout=0.0, publish_every=5)
    lock = Lockstep(body, control_every=10, timeout=0.0, clock=clock, perf=clock.perf)
    outbox = []
    sent = [(0.01, 0.0, -0.01, 0.02), (0.0, 0.03, 0.0, 0.0), (-0.02, 0.0, 0.0, 0.01)]
    for u in sent:
        lock.due(outbox)
        steps = body.steps
        lock.mailbox.put(WheelCommands.one(u, clock()))
        lock.due(outbox)
        assert body.steps == steps + 10
    ref = GyrostatIntegrator((1.0, 2.0, 3.0), wheels, 1e-3, omega0=(0.3, 1.5, -0.4),
                             speeds0=(0.0,) * 4)
    for u in sent:
        ref.command_motors(u)
        for _ in range(10):
            ref.step()
    assert body.stepper.q == ref.q and body.stepper.speeds == ref.speeds and lock.ticks == 3


def test_the_start_up_heap_is_frozen_before_the_loop_starts():
    """
    runner.run freezes the objects start-up made (after one collection) before on_start.

    In a fresh interpreter with the package's ROS modules imported: most tracked objects
    are frozen after settle_heap(), and run() calls it between make_node() and on_start.
    """
    source = (
        'import gc\n'
        'from unittest import mock\n'
        'from rigid_body_dynamics.ros import runner\n'
        'before = len(gc.get_objects())\n'
        'runner.settle_heap()\n'
        'print(before, gc.get_freeze_count(), len(gc.get_objects()))\n'
        'gc.unfreeze()\n'
        'order = []\n'
        'node = mock.Mock(nodes=[])\n'
        'with mock.patch.object(runner, "rclpy"), mock.patch.object(runner, "_spin"), \\\n'
        '        mock.patch.object(runner, "settle_heap", lambda: order.append("settle")):\n'
        '    runner.run(lambda: order.append("make") or node, "n",\n'
        '               on_start=lambda n: order.append("start"))\n'
        'print(" ".join(order))\n')
    out = subprocess.run([sys.executable, '-c', source], capture_output=True, text=True,
                         timeout=120, check=True).stdout.split('\n')
    before, frozen, after = (int(v) for v in out[0].split())
    assert frozen > 0.8 * before and after < 0.2 * before
    assert out[1] == 'make settle start'
