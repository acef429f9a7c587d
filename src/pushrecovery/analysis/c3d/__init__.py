"""Read and write C3D motion-capture files: markers and force plates, SI units, lab frame.

:func:`read_c3d` returns the markers [m] and, per force plate, the ground reaction force on the
subject [N], the centre of pressure (CoP) [m] and the free moment [N m], all in the lab frame;
:func:`write_c3d` writes the same quantities as a file that third-party readers understand;
:func:`write_events` copies a file with a trial's events in its EVENT group (:mod:`.event_group`).
The conventions (lab frame, plate types 1-4, units, what is ours and what is ezc3d's) are in
docs/c3d.md. Modules: :mod:`.reader`, :mod:`.writer`, :mod:`.plates` (each plate through
ezc3d's force-platform module or ours), :mod:`.dispatch` (which of the two, and why),
:mod:`.forceplate` (our plate mathematics, pure numpy, and Kistler's CoP correction),
:mod:`.parameters`, :mod:`.header`, :mod:`.content` (the results).
"""

from pushrecovery.analysis.c3d.content import C3DContent, ForcePlate
from pushrecovery.analysis.c3d.dispatch import ezc3d_extracts, plate_path
from pushrecovery.analysis.c3d.event_group import C3DEvent, read_events, write_events
from pushrecovery.analysis.c3d.forceplate import (
    kistler_cop_correction,
    plate_cop_in_plate_frame,
    plate_frame,
    wrench_type2,
    wrench_type3,
    wrench_type4,
)
from pushrecovery.analysis.c3d.reader import read_c3d
from pushrecovery.analysis.c3d.writer import write_c3d

__all__ = [
    "C3DContent",
    "C3DEvent",
    "ForcePlate",
    "ezc3d_extracts",
    "kistler_cop_correction",
    "plate_cop_in_plate_frame",
    "plate_frame",
    "plate_path",
    "read_c3d",
    "read_events",
    "wrench_type2",
    "wrench_type3",
    "wrench_type4",
    "write_c3d",
    "write_events",
]
