from rigid_body_dynamics.physics import FreeRigidBody, Inertia, simulate, theory

body = FreeRigidBody(Inertia((1.0, 2.0, 3.0)), omega0=(0.01, 2.0, 0.01))
q, omega = body.state_at([0.0, 5.0, 10.0])     # exact: (N, 4) x-y-z-w and (N, 3) rad/s

run = simulate((1.0, 1.0, 1.5), (0.3, 0.0, 2.0), duration=10.0, dt=1e-3,
               integrator='exact', torque=lambda t, q, w: (0.0, 0.0, 0.1))
print(run.omega[-1], run.work[-1], run.kinetic_energy[-1] - run.kinetic_energy[0])

print(theory.flip_interval((1.0, 2.0, 3.0), (0.01, 2.0, 0.01)))    # 10.98 s
print(theory.chandler_wobble_period() / 86164.0905)                 # 300 sidereal days
