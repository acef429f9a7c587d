"""The stepping task of the whole-body controller (docs/humanoid3d_stepping.md).

:mod:`.stepper` (the :class:`~.stepper.Stepper`: decide, lift off, swing, re-plan, land),
:mod:`.plan` (the foothold and the swing foot), :mod:`.leg` (the swing leg's joints and swing
time), :mod:`.height` (the pelvis height the legs reach), :mod:`.settings`
(:class:`~.settings.StepSettings`).
"""
