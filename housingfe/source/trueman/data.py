"""Input data of Trueman (1974), Appendix B.2, and Table 6.1 / Sec. 6.9 critical speeds.

The thesis works in lbf, in, s, rad.  The values are kept here as printed (imperial) so that they can be
checked line by line against Appendix B; `to_si` converts them once.  Everything the model code uses is SI.

Flags carried over from the source (see docs/trueman.md):
- AK(5), AK(7) of Types A/C (0.272e7, 0.274e7) differ from Types B/E (0.250e7); kept as printed.
- The listing's DATA statements use 0.01 for the small grounded dampers and 0.675 for the mesh dampers;
  Appendix B says 0.03 and 0.625.  Appendix B is used.
- FXBSH / DXBSH (rubber bush) are given for Types B/E only; the same values are used for "Type C with
  bushed gears" (inferred).
"""
from __future__ import annotations

# --- unit conversions (exact definitions of the inch and pound-force) -------------------------------
INCH = 0.0254                      # m
LBF = 4.4482216152605              # N
LBF_IN = LBF * INCH                # N m (torque, torsional stiffness per rad, inertia lbf in s^2 -> kg m^2)
PSI = LBF / INCH**2                # Pa
LBF_S2_PER_IN4 = LBF / INCH**4     # kg/m^3 per (lbf s^2/in^4)

# --- Appendix B.2, imperial ----------------------------------------------------------------------
SHAFT_DENSITY_LBF_S2_IN4 = 0.00072
SHEAR_MODULUS_PSI = 11.8e6

# drawshaft sections from the GEAR end to the DRAWROLL end: SL(3)/SD(3), SL(2)/SD(2), SL(1)/SD(1)
DRAWSHAFT_SECTIONS_IN = ((2.375, 0.985), (11.0, 1.225), (1.187, 0.985))

MACHINE_DATA_IMPERIAL = {
    "A": {  # Types A & C (MDT.2/3)
        "half_coupling_inertia": 0.0561,                                         # AJ(1) = AJ(8)
        "layshaft_gear_inertia": (0.0147, 0.0145, 0.0136, 0.0146, 0.0145, 0.0137),  # AJ(2..7)
        "bronze_gear_inertia": 0.00201,                                          # AJ(9)
        "steel_gear_inertia": 0.00175,                                           # AJ(10)
        "drawroll_inertia": 0.0610,                                              # AJ(11)
        "coupling_stiffness": 0.840e6,                                           # AK(1) = AK(9)
        "layshaft_stiffness": (0.174e7, 0.153e7, 0.153e7, 0.272e7, 0.106e7, 0.274e7, 0.174e7),  # AK(2..8)
        "crossed_mesh_stiffness": 0.154e7,                                       # AK(10), drawshaft side
        "parallel_mesh_stiffness": 0.154e7,                                      # AK(11)
        "speed_ratio": 1.45,                                                     # SRAT = 29/20
    },
    "B": {  # Types B & E (MDT.6N/P)
        "half_coupling_inertia": 0.0567,
        "layshaft_gear_inertia": (0.0101, 0.0102, 0.00939, 0.0103, 0.0103, 0.00931),
        "bronze_gear_inertia": 0.00201,
        "steel_gear_inertia": 0.00175,
        "drawroll_inertia": 0.0410,
        "coupling_stiffness": 0.840e6,
        "layshaft_stiffness": (0.170e7, 0.167e7, 0.161e7, 0.250e7, 0.118e7, 0.250e7, 0.170e7),
        "crossed_mesh_stiffness": 0.154e7,
        "parallel_mesh_stiffness": 0.154e7,
        "speed_ratio": 1.25,                                                     # 25/20
    },
}

# damping (identical for all types), lbf in s/rad
DAMPING_IMPERIAL = {
    "half_coupling": 0.03,     # AJD(1), AJD(8), to ground
    "layshaft_gear": 0.03,     # AJD(2..7), to ground
    "drawshaft_gear": 0.03,    # AJD(9), AJD(10), to ground
    "drawroll": 1.45,          # AJD(11), to ground
    "coupling": 31.2,          # DCPLG, across each box coupling
    "crossed_mesh": 0.625,     # FFD(10), across the crossed helical mesh
    "parallel_mesh": 0.625,    # FFD(11), across the parallel helical mesh
}

RUBBER_BUSH_FLEXIBILITY_RAD_PER_LBF_IN = 0.0005   # FXBSH (Types B/E)
RUBBER_BUSH_DAMPING_LBF_IN_S = 25.0               # DXBSH (Types B/E)
TE_AMPLITUDE_MAX_RAD = 0.0021                     # ERR, eq. 5.9

# --- Sec. 6.9 / Appendix H: variable-speed drive of the 4-box rig --------------------------------
VS_DRIVE_IMPERIAL = {
    "motor_inertia": 0.470,                             # AJH (motor, with its half coupling added separately)
    "unit_inertias": (0.0348, 0.03672, 0.314, 0.0348),  # AJV(1..4)
    "motor_coupling_stiffness": 840000.0,               # standard coupling between motor and variator
    "motor_speed_rpm": (1510.0, -0.016),                # motor r.p.m. = 1510 - 0.016 * drawroll r.p.m.
    "disc_constants": (1.414, 2.7559, 4.750),           # DDBO formula constants (repaired OCR, see docs)
    "output_speed_rpm": (522.2, 539.0),                 # REVRR = 522.2 + 539 * VSRAT
}

# --- published critical speeds, drawroll r.p.m. (Table 6.1, Sec. 6.9) ----------------------------
TABLE_6_1_RPM = {
    "standard A, solid gears": (473, 1413, 2332, 3215, 4052),
    "standard C, solid gears": (476, 1422, 2346, 3233, 4065),
    "type B": (618, 1440, 1760, 1884, 1940),
    "type E": (622, 1444, 1763, 1885, 1941),
    "C with bushed gears": (460, 1109, 1396, 1520, 1580),
    "A with 1/2 in drawshafts": (475, 1318, 1925, 2310, 2545),
    "A with drawroll inertia -50 %": (621, 1856, 3069, 4245, 5371),
    "A with coupling flexibility x100": (95, 283, 464, 637, 795),
    "C with coupling flexibility x100": (103, 283, 465, 637, 796),
}
RIG_CRITICAL_RPM = {
    "rig 4 boxes, standard couplings": (2070,),
    "rig 4 boxes, couplings x290": (177, 394, 584, 727),
}


def to_si(machine_type: str) -> dict:
    """Appendix B data of machine type "A" (A & C) or "B" (B & E) in SI units.

    Inertias in kg m^2, stiffnesses in N m/rad, damping in N m s/rad, lengths in m, density kg/m^3,
    shear modulus Pa.  Values are as the thesis gives them, NOT yet referred to drawroll speed."""
    d = MACHINE_DATA_IMPERIAL[machine_type]
    out = {}
    for key, value in d.items():
        if key == "speed_ratio":
            out[key] = value
        elif isinstance(value, tuple):
            out[key] = tuple(v * LBF_IN for v in value)
        else:
            out[key] = value * LBF_IN
    out["damping"] = {k: v * LBF_IN for k, v in DAMPING_IMPERIAL.items()}
    out["drawshaft_sections"] = tuple((length * INCH, dia * INCH) for length, dia in DRAWSHAFT_SECTIONS_IN)
    out["density"] = SHAFT_DENSITY_LBF_S2_IN4 * LBF_S2_PER_IN4
    out["shear_modulus"] = SHEAR_MODULUS_PSI * PSI
    out["bush_stiffness"] = LBF_IN / RUBBER_BUSH_FLEXIBILITY_RAD_PER_LBF_IN
    out["bush_damping"] = RUBBER_BUSH_DAMPING_LBF_IN_S * LBF_IN
    return out
