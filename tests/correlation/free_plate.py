"""The correlation tests' cheap updating problem: a free steel plate, 400 x 300 x 5 mm, one layer of Q2 hexes at
50 mm, modes to 1 kHz (~0.1 s a solve); its modulus and thickness are what the tests identify."""

PLATE_SCENE = """
[scene]
name = "plate"
kind = "housing"
description = "free steel plate, the correlation tests' cheap updating problem"
[geometry]
kind = "plate"
a = 0.4
b = 0.3
h = 0.005
[material]
name = "plate-steel"
youngs_modulus = 210e9
poisson_ratio = 0.3
density = 7850.0
[mesh]
element = "hex"
degree = 2
size = 0.05
layers = 1
[analysis.modal]
f_max = 1000.0
"""
