"""Test-analysis correlation (issue 15): measured modes and FRFs in and out as universal files (uff), MAC,
cross-orthogonality and automatic pairing (mac), computed shapes at measured channels (points), and model
updating of scene parameters by bounded least squares (updating).  Reads scenes, so it sits beside studies and
verification in the layers."""
