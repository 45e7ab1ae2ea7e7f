"""A torque model of one's own: eddy-current damping, in the integrators' stages."""

import numpy as np
from rigid_body_dynamics.physics import make_integrator
from rigid_body_dynamics.physics.environment import (circular_elements, DipoleField, KeplerOrbit,
                                                     SpaceEnvironment)


class EddyCurrentDamping:
    """
    The eddy-current torque k (omega x B) x B of a conducting body spinning in the field.

    ``k`` (N m s / T^2); omega (rad/s) and B (T) in the principal frame. It takes
    kinetic energy out: omega . torque = k ((omega . B)^2 - |omega|^2 |B|^2) <= 0.
    """

    needs = frozenset({'field', 'rate'})

    def __init__(self, k):
        self.k = float(k)

    def torque(self, t, r, q, omega, env):
        """Return k (omega x B) x B = k (B (omega . B) - omega |B|^2) (N m, principal)."""
        bx, by, bz = env.b_body
        wx, wy, wz = omega
        wb, bb = wx * bx + wy * by + wz * bz, bx * bx + by * by + bz * bz
        return (self.k * (bx * wb - wx * bb), self.k * (by * wb - wy * bb),
                self.k * (bz * wb - wz * bb))

    def stage_source(self, p):
        """Return the same torque as statements for the generated stages."""
        lines = [f'{p}wb = {p}k * (o_x * b_bx + o_y * b_by + o_z * b_bz)',
                 f'{p}bb = {p}k * (b_bx * b_bx + b_by * b_by + b_bz * b_bz)']
        return ({f'{p}k': self.k}, lines, (f'b_bx * {p}wb - o_x * {p}bb',
                                           f'b_by * {p}wb - o_y * {p}bb',
                                           f'b_bz * {p}wb - o_z * {p}bb'))


orbit = KeplerOrbit(circular_elements(500e3, inclination=1.4))
env = SpaceEnvironment(orbit, DipoleField(), [EddyCurrentDamping(2e6)])
print('in the stages:', env.stage_code is not None)

# the statements against torque() at a few states (the attitude not unit, as inside a step)
rng = np.random.default_rng(7)
worst = 0.0
for _ in range(20):
    q, w, t = 1.2 * rng.normal(size=4), rng.normal(size=3), rng.uniform(0.0, 6000.0)
    exact = np.array(env.torque_of_models(t, *q, *w))
    worst = max(worst, np.abs(np.array(env(t, *q, *w)) - exact).max() / np.abs(exact).max())
print('statements against torque():', f'{worst:.1e}')

# a 0.5 rad/s tumble damped for 600 s at 10 ms steps
body = make_integrator('exact', (0.03, 0.035, 0.01), 0.01, (0, 0, 0, 1), (0.3, -0.2, 0.35))
energy0 = body.kinetic_energy
for _ in range(60000):
    body.step((0.0, 0.0, 0.0), None, env)
print('|omega| (rad/s):', f'{np.linalg.norm(body.omega):.4f}',
      'T - T0 (J):', f'{body.kinetic_energy - energy0:.6e}', 'work (J):', f'{body.work:.6e}')
