"""housingfe: gearbox noise from the gear mesh to radiated sound power.

The chain, one module per concern (data flows one way):
scene -> geometry -> model (solvers.elasticity) -> solver (solvers.modal, solvers.harmonic)
-> response -> radiation -> report.  Standalone analytic models: source (gears), bearings.

Units are SI throughout; dB references follow van Roosmalen (1994): v0 = omega0 = 5e-8,
F0 = 1 N, P0 = 1 pW (see housingfe.levels).
"""

__version__ = "0.1.0"
