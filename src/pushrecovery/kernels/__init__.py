"""Compiled kernels: plain array functions, and the only package that imports numba.

Every kernel is a module-level ``@njit(cache=True)`` function: numba keys its on-disk cache by
the function's file, so a new process loads machine code instead of compiling (nothing compiles
on a call path after the first run on a machine). ``njit`` comes from :mod:`.jit`, which leaves
the functions plain Python in a process that answers one state and exits. A module here imports
nothing of the project but other kernels, only numpy, numba and math; the floors above call
these kernels with checked arguments (the checks and the units live with the models that own
the equations).

Importing this package imports no numba: each module is loaded where it is first needed,
because importing numba alone costs about 0.4 s.

Modules
-------
polygons
    convex polygon clipping, Minkowski sums, Chebyshev centres, foothold regions.
plane_codes
    fused planar margins and strategy codes over many states.
capture_point
    the fused capture-point margin of Eq. (4) over many states.
step_scalar, stepping
    the step model's scalar functions (plain Python) and their numba builds.
batched.ankle, batched.stepping
    many pushes of the analytic models in one compiled loop.
mpc.riccati, mpc.interior, mpc.scales
    the MPC's Riccati active-set passes and interior point.
wbc
    the whole-body controller's QP assembly, least-distance form, ankle and joint-guard rows.
hull
    the convex hull of every frame's points.
placement
    regions built once in a stance foot's frame, turned and moved onto a support.
single_margins
    one state's signed distances to a support polygon and its CMP region (single ``classify``).
threads
    numba's thread count, held at one while a worker runs pushes.
jit
    how the kernels run: compiled by numba, or as plain Python (one-state commands).
"""
