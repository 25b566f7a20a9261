"""Gear excitation source (van Roosmalen 1994, Ch. 2; Fukuma 1973; Trueman 1974).

Modules: `gears` (involute pair geometry, Appendix B/F), `stiffness` (analytic tooth stiffness and
load distribution, Ch. 2.2-2.4), `dynamics` (15-DOF lumped interior model, engagement shock, L_omega),
`cli` (`housingfe source <scene>`).
"""
