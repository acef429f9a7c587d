"""The whole-body controller (WBC) of the 3-D humanoids: task-space inverse dynamics as one QP.

Organised by concept, as mink (kevinzakka/mink) is: each tick the controller's laws write
their tasks (``tasks/``) and limits (``limits/``), the QP stacks them under MuJoCo's dynamics
and the feet's contact rows and solves it (``qp``, ``least_distance``); the compiled kernels are
:mod:`pushrecovery.kernels.wbc`. It reads MuJoCo's ``MjModel`` and nothing of
``pushrecovery.sim``: the plants (``sim.mujoco.humanoid3d.plant3d.wbc_for``) build it from
above. Importing this package imports nothing: import the module you need. Its public
entries (``__all__``: the controller, its gains and settings, the observation and command,
``bodies``' checks) check their arguments where the controller is built; the parts it runs
at every tick (``tasks``, ``limits``, ``qp``, ``stepper``) take those checked objects and are
not entries. docs/humanoid3d_wbc.md
("Where it lives") lists the modules and derives every law; docs/humanoid3d_stepping.md the
stepping task's.
"""
