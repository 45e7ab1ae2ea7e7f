"""
The command-line tools, each a console script with ``main(argv)``.

:mod:`.demo` (``rigid_body_demo``: the nodes on built-in bodies, then the closed
loop), :mod:`.report` (``rigid_body_report``: figures and one HTML page, with
:mod:`.report_page`'s interactive views), :mod:`.recorder` (its ``--record``: the
running nodes into a bag) and :mod:`.analyze` (``rigid_body_analyze``: the
analyzer's findings from a bag). Every tool runs the one analysis
(:mod:`rigid_body_dynamics.physics.analysis`) and prints its findings with
:mod:`rigid_body_dynamics.physics.analysis.findings_render`.
"""
