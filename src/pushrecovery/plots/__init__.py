"""Figures: the only package that imports matplotlib.

It draws on ``matplotlib.figure.Figure`` objects outside pyplot, so it never changes the
caller's backend (no ``matplotlib.use``) and leaves nothing to close. It needs the ``plots``
extra: without matplotlib, importing any of its modules raises
:class:`~pushrecovery.extras.MissingExtraError` naming it.
"""

from pushrecovery.extras import require

require("plots", "matplotlib")
