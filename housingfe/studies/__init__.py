"""Studies that run the chain several times, e.g. the bearing configurations of the test gearbox (Sec. 5.8)."""
