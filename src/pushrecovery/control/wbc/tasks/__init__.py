"""The whole-body QP's tasks: a task, the tick's stack of rows, the centroidal momentum rows.

:mod:`.task` (:class:`~.task.Task`, W ‖A x − b‖²), :mod:`.stack` (:class:`~.stack.TaskStack`)
and :mod:`.momentum` (:func:`~.momentum.momentum_rows`), :mod:`.swing_foot`
(:func:`~.swing_foot.swing_foot_task`, the stepper's).

The ankle controller's four tasks (CoM, torso, pelvis height, posture) are written as rows of
the stack by one compiled kernel (:func:`pushrecovery.kernels.wbc.ankle_targets`); the swing
foot's task is run by the stepper (:mod:`pushrecovery.control.wbc.stepper`).
"""
