"""3-D humanoids in MuJoCo: a biped generated from the body parameters and real robots.

:mod:`.biped3d` builds the biped from a :class:`~pushrecovery.params.BodyParams`;
:mod:`.robots` finds the Unitree G1 (and H1) of the ``robots`` extra and derives their body
parameters; :mod:`.standing` holds a standing posture with a joint-space PD
(docs/humanoid3d.md). :mod:`.plant3d` puts them behind the backend contract and builds their
whole-body controller (:mod:`pushrecovery.control.wbc`, on the control floor); :mod:`.runs3d`
pushes them under it.
"""

from __future__ import annotations
