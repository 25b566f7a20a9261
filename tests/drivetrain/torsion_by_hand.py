"""The pieces of the rig's torsional chain written by hand, independently of housingfe's FE drive line, shared by
the drive-line tests (grounded quills: test_drive_line; back-to-back loop: test_rig_loop)."""

import math


def gear_train_polar(dt) -> dict:
    """{"pinion" | "wheel": polar inertia (kg m^2)}: each gear body with its whole FE shaft, as solid cylinders."""
    rho = dt.gears.pair.density
    polar = {}
    for g, name in enumerate(("pinion", "wheel")):
        dg, width, _ = dt.gears.gear_body(g)
        line = dt.shaft(name)
        length = line.ends[1] - line.ends[0]
        polar[name] = rho * math.pi / 32 * (dg**4 * width + line.diameter**4 * (length - width))
    return polar


def base_ratio(dt) -> float:
    """Wheel over pinion base diameter: the test wheel turns by -theta_pinion / ratio."""
    pair = dt.gears.pair
    return pair.base_diameter[1] / pair.base_diameter[0]


def near_quill_stiffness(dt, name: str) -> float:
    """Torsion stiffness (N m/rad) of the near quill in series with its FE shaft from the gear (z = 0) to the front
    end: G pi d^4 / 32 / 0.14 m for the test gearbox."""
    pair = dt.gears.pair
    G = pair.youngs_modulus / (2 * (1 + pair.poisson_ratio))
    line = dt.shaft(name)
    shaft = G * math.pi * line.diameter**4 / 32 / (0 - line.ends[0])
    return 1.0 / (1.0 / dt.drive_line_parts()[name][0] + 1.0 / shaft)
