"""Tests of housingfe.source.fukuma."""
