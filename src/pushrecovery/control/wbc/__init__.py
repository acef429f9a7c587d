"""The whole-body controller (WBC) of the 3-D humanoids: task-space inverse dynamics as one QP.

Organised by concept, as mink (kevinzakka/mink) is: each tick the controller's laws write
their tasks (``tasks/``) and limits (``limits/``), the QP stacks them under MuJoCo's dynamics
and the feet's contact rows and solves it (``qp``, ``least_distance``). docs/humanoid3d_wbc.md
derives every law, docs/humanoid3d_stepping.md the stepping task's. The compiled kernels are
:mod:`pushrecovery.kernels.wbc`.

The WBC is a :class:`~pushrecovery.control.base.Controller` over a typed
:class:`~.observation.HumanoidObservation` the plant hands it (views of the plant's own
``MjData``: nothing copied per tick); it reads MuJoCo's ``MjModel`` (it may import ``mujoco``,
as mink does) and nothing of ``pushrecovery.sim``: the plants
(``sim.mujoco.humanoid3d.plant3d.wbc_for``) build it from above. Importing this package
imports nothing: import the module you need.

Modules
-------
controller
    :class:`~.controller.WholeBodyController`: the balance laws (DCM, torso, pelvis, posture),
    the hip and the stepper, one QP per tick; ``reset(state)``,
    ``compute(t, state) -> HumanoidCommand``.
observation
    :class:`~.observation.HumanoidObservation` (what the WBC reads, built by
    :func:`~.observation.mujoco_observation`) and :class:`~.observation.HumanoidCommand`.
gains
    :class:`~.gains.WbcGains`, the tasks' gains and weights.
qp
    :class:`~.qp.WholeBodyQP`: the QP's dynamics, contact and motor rows, assembled in place.
least_distance
    :class:`~.least_distance.LeastDistanceSolver`: DAQP on the QP's least-distance form.
buffers
    The per-tick arrays of the QP, allocated once, and MuJoCo's dense inertia.
foot_contact
    :class:`~.foot_contact.FootContact`: a foot's sole frame and its wrench constraints.
bodies
    Bodies by name, the colliding geoms and each sole's points of a compiled humanoid.
hip
    :class:`~.hip.HipLaw`: the hip (CMP balancing) law, Stephens' bang-bang as a feedback.
tasks.task, tasks.stack, tasks.momentum, tasks.swing_foot
    A task W ‖A x − b‖²; the tick's tasks as one stack of rows; the centroidal momentum rows;
    the swing foot's task.
limits.joint_guard, limits.knee_guard
    Soft limits: the guarded joints kept off their stops; the stepper's knee guard.
stepper.stepper, stepper.plan, stepper.leg, stepper.height, stepper.settings
    The stepping task: decide, plan the foothold, swing and land a foot.
"""
