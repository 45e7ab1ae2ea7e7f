"""
The dynamics of the rigid body and the gyrostat: the equations and their integration.

:mod:`.equations` (Euler's equations, quaternion kinematics), :mod:`.free_motion`
(the exact torque-free flow), :mod:`.integrators` (the fixed-step integrators
behind one protocol) on :mod:`.rk_kernels` (unrolled Runge-Kutta stages of
:mod:`.dop853_tableau` and RK4), :mod:`.gyrostat` (a body with reaction
wheels), :mod:`.plant` (the one stepping core: a body, its wheels and its
environment, stepped) and :mod:`.reference` (the independent DOP853 reference
every accuracy claim is measured against).
"""
