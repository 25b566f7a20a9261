"""The thesis' test gears (housingfe/data/roosmalen1994.toml, Appendix F) as the source tests build them."""
from housingfe.data import thesis
from housingfe.source.gears import GearPair
from housingfe.source.stiffness import ShaftBending

REF = thesis()["gears"]
# equal spans both sides of the gears (m, m) and the shaft diameters (m): a mesh without the thesis' overhang asymmetry
SYMMETRIC_SHAFTS = (ShaftBending(0.06, 0.06, 0.080), ShaftBending(0.06, 0.06, 0.095))


def spur_pair() -> GearPair:
    """The test gears' data with a zero helix angle (a spur pair, eps_beta = 0)."""
    table = dict(thesis()["gears"]["single_helical"], helix_angle_deg=0.0, kind="spur")
    return GearPair.from_table({k: v for k, v in table.items() if k in (
        "module_mm", "teeth", "pressure_angle_deg", "helix_angle_deg", "addendum_modification", "face_width_mm",
        "centre_distance_mm", "addendum_coefficient", "dedendum_coefficient", "rack_tip_radius_factor", "kind")})
