"""Forced response: observers of the solution (surface mean-square velocity, points, bands) and the harmonic
analysis of a scene (`forced`)."""
