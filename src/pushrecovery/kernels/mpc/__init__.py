"""The MPC's compiled solvers of Eq. (17): Riccati active-set passes, interior point, its scales."""
