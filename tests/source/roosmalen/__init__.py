"""Tests of housingfe.source.roosmalen."""
