"""The double helical source's torque law (issue 28, docs/design-variants.md "The torque law per harmonic")."""
import math
from dataclasses import replace

import numpy as np

from housingfe.drivetrain.description import test_gearbox
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen.operating import SourceModel
from housingfe.source.stiffness import Corrections


def _excitation(src, torque, harmonics):
    """k_m |d_qs,n| [N]: the chain's quasi-static excitation at the tooth harmonics."""
    S, shock = src.mesh_stiffness(torque)
    op = src._point(torque)
    d = dyn.quasi_static_compression(S, shock, op.normal_force)
    return S.mean() * 2 * np.abs(np.fft.rfft(d) / d.size)[list(harmonics)]


def test_unrelieved_double_helical_excitation_is_linear_in_the_load():
    """Without flank corrections the mesh is linear but for Hertz: every harmonic of the quasi-static excitation
    grows 20 lg 2 = +6.02 dB per doubling of the torque (Hertz's flattening and the stiffening k_m allow 0.5 dB).
    A torque that entered twice (the force or the shock scaled with it again) would give +12 dB."""
    src = test_gearbox("double_helical", "cylindrical_roller").source_model(stiffness_positions=16)
    bare = SourceModel(src.pair, Corrections(), src.interior, src.geometry,
                       mesh_model=replace(src.mesh_model, corrections=Corrections()), stiffness_positions=16)
    n = (1, 2, 4)
    law = 20 * np.log10(_excitation(bare, 2000.0, n) / _excitation(bare, 1000.0, n))
    assert np.all(np.abs(law - 20 * math.log10(2.0)) < 0.5), law
