"""Gear excitation source: three seed models side by side, on shared gear geometry and tooth stiffness.

Models (one subpackage each; `housingfe source <scene>` dispatches on the scene's `source.model`):
  `roosmalen`  van Roosmalen 1994, Ch. 2: 15-DOF lumped interior, engagement shock, L_omega, bearing spectra;
               its `operating.SourceModel` is the source stage of the noise chain
  `fukuma`     Fukuma et al. 1973: coupled circumferential/radial/axial vibration of a gear on a flexible shaft
  `trueman`    Trueman 1974: branched multi-mesh torsional drive excited by transmission-error harmonics
Shared: `gears` (involute pair geometry, Appendix B/F), `stiffness` (analytic tooth stiffness and load
distribution, Ch. 2.2-2.4), `misalignment` (the lead gap of the mesh under load), `cli` (`housingfe source <scene>`).
"""
