"""Tests of housingfe.source.trueman."""
