"""Read measured trials from CSV and C3D files into a :class:`~.recording.Recording`.

CSV (docs/analysis.md): a header row, then one row per frame at a constant rate. Column names
(case-insensitive; ``ap`` anterior-posterior, forward positive; ``ml`` medio-lateral, left
positive; lengths in ``units``, forces in N, time in s):

========================================  ===================================================
``time``                                  required [s]
``com_ap``, ``com_ml``                    CoM position (or give the force-plate columns)
``com_vel_ap``, ``com_vel_ml``            CoM velocity [units/s], optional (else differentiated)
``cop_ap``, ``cop_ml``                    centre of pressure, optional
``force_ap``, ``force_ml``, ``force_v``   ground reaction force on the subject [N], optional
``base_ap_min`` … ``base_ml_max``         base of support edges, optional (all four)
``ankle_ap``, ``ankle_ml``                stance ankle, optional
``com_height``                            CoM height above the ankle, optional
========================================  ===================================================

Empty cells and ``nan`` are missing samples. C3D: markers and force plates through
:mod:`pushrecovery.analysis.c3d`; the CoM from named markers (Plug-in Gait's ``CentreOfMass``
by default), feet from the Plug-in Gait heel/toe/ankle markers, the force of all plates summed
and their CoPs combined.
"""

from pushrecovery.analysis.readers.c3d_files import read_c3d_recording
from pushrecovery.analysis.readers.common import AP_AXES, FOOT_MARKERS, LENGTH_UNITS, body_rotation
from pushrecovery.analysis.readers.csv_files import CSV_COLUMNS, read_csv_recording, read_recording

__all__ = [
    "AP_AXES",
    "CSV_COLUMNS",
    "FOOT_MARKERS",
    "LENGTH_UNITS",
    "body_rotation",
    "read_c3d_recording",
    "read_csv_recording",
    "read_recording",
]
