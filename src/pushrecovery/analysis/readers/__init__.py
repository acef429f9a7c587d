"""Read measured trials from CSV and C3D files into a :class:`~.recording.Recording`.

CSV: a header row, then one row per frame at a constant rate; the columns
(:data:`~.csv_files.CSV_COLUMNS`: ``time``, ``com_ap``, ``cop_ml``, ...; ``ap`` forward, ``ml``
left positive; lengths in ``units``, forces in N, time in s) are listed in docs/analysis.md,
"CSV format". C3D: markers and force plates through :mod:`pushrecovery.analysis.c3d`; the CoM
from named markers (Plug-in Gait's ``CentreOfMass`` by default), feet from the Plug-in Gait
heel/toe/ankle markers, the force of all plates summed and their CoPs combined.
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
