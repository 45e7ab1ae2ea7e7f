import math


def test_detumble_settles(attitude_sim):
    sim = attitude_sim('cubesat_3u')               # lockstep: the plant waits for you
    sim.start('attitude_controller', '-p', 'mode:=detumble', '-p', 'natural_frequency:=0.5')
    sim.wait_until(10.0)                           # simulated seconds
    t, q, omega = sim.latest()
    assert t >= 10.0 and math.sqrt(sum(w * w for w in omega)) < 1e-3
