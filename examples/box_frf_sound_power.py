"""# A free box driven by two forces: transfer functions, coherent response and sound power

The noise chain of a gearbox ends with the housing: forces at the bearings make the housing walls vibrate, and
the walls radiate sound.  This example runs the last three stages of that chain on the free box housing of the
thesis (van Roosmalen 1994, Sec. 4.2, see box_modes.py):

1. `modes(structure, f_max)`: the modal basis (all modes to 1.5 f_max, complete by the inertia count);
2. `harmonic_response(basis, loads, damping, frequencies)`: the response to loads that carry a complex rms
   amplitude per frequency (`Load(name, vector, spectrum, unit)`), summed coherently: phases count, so two
   forces can reinforce or cancel each other.  With one load of a flat 1 N spectrum the response is the
   transfer function TF_F = L_v - L_F (dB re v0 / F0 = 5e-8 m/s per N) of `housingfe run`;
3. `sound_power(response, radiator)`: L_W = L_v + 10 lg(S / 1 m^2) + L_sigma (eq. 4.16, dB re 1 pW) with the
   radiation index L_sigma of a radiator from the registry: "erp" (sigma = 1, an upper bound above coincidence)
   and "foller" (Föller's box model on the box's own plates, areas and perimeters measured on the mesh).

The loads: a force on the top plate (1 N rms, flat) and a force on the front plate of the same size that lags
by a delay tau = 0.4 ms, F_front = 1 N e^{-i omega tau} (time dependence e^{i omega t}) - two bearings seeing
the same tooth force at different times, say.  The surface-averaged mean-square velocity of the pair is not the
sum of the two alone; the difference is the cross term 2 Re(v_top^H W v_front).

Units SI: m, N, Hz, m^2/s^2; levels in dB (v0 = 5e-8 m/s, F0 = 1 N, P0 = 1 pW).
Run:  .venv/bin/python examples/box_frf_sound_power.py [--small] [--out DIR]
(--small: 40 mm elements, 100-2000 Hz in 20 Hz lines, seconds; default: 6 elements per bending wavelength at
4 kHz, 20-4000 Hz in 4.88 Hz lines, a few minutes.  --out DIR also writes the files of OUTPUTS.)
"""
# %%
from __future__ import annotations

import argparse

import numpy as np
from mpi4py import MPI

from housingfe import levels
from housingfe.fe.model import build_model
from housingfe.geometry.box import BoxGeometry
from housingfe.materials import LIBRARY
from housingfe.outputs import atomic_output_dir, format_table, write_csv
from housingfe.radiation.radiators import radiator_from_spec, sound_power
from housingfe.response.harmonic import Load, harmonic_response, loss_factor
from housingfe.scene import LoadSpec, MeshSpec, RadiationSpec
from housingfe.solvers.modal import modes

# The files written with --out DIR (tests/test_examples.py checks that they are there).
OUTPUTS = ("velocity_and_sound_power.csv", "bands.csv")

BOX = BoxGeometry(kind="box", length=0.325, width=0.225, height=0.125, wall_thickness=0.008,
                  flange_thickness=0.015, flange_width=0.073)
STEEL = LIBRARY["steel"]
ETA = 0.002                 # loss factor of a welded steel box (the thesis measured 0.001-0.0026)
TAU = 0.4e-3                # s: delay of the front force behind the top force

# %% [markdown]
# ## Structure and loads
#
# A load spec is the object a scene's `[[loads]]` entry becomes: a force spread over the facets within
# `radius` of `point` on `surface`.  `structure.load_vector(spec)` is its vector for 1 N; the `Load` adds the
# spectrum.  The radiating surface "outer" is the outside of the plates and the flange (not the foot's
# underside, which sits on the floor).

# %%
def loads(box) -> list[Load]:
    top = LoadSpec(name="top", kind="force", surface="outer_top", point=[0.060, 0.040, 0.125],
                   direction=[0.0, 0.0, -1.0])
    front = LoadSpec(name="front", kind="force", surface="outer_front", point=[0.080, -0.1125, 0.070],
                     direction=[0.0, 1.0, 0.0])
    return [Load("top", box.load_vector(top), 1.0, "N"),
            Load("front", box.load_vector(front), lambda f: np.exp(-2j * np.pi * f * TAU), "N")]


# %% [markdown]
# ## Responses and sound power

# %%
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0].lstrip("# "))
    parser.add_argument("--small", action="store_true", help="coarse mesh and lines (seconds)")
    parser.add_argument("--out", default=None, help="folder for the CSV files")
    args = parser.parse_args(argv)
    if args.small:
        mesh, f = MeshSpec(element="hex", degree=2, size=0.04), np.arange(100.0, 2000.0 + 1e-9, 20.0)
    else:
        mesh, f = MeshSpec(element="hex", degree=2, elements_per_wavelength=6), np.arange(20.0, 4000.0, 4.88)

    box = build_model(BOX, STEEL, mesh, f.max(), MPI.COMM_WORLD)
    basis = modes(box, 1.5 * f.max())                      # the modal basis: modes to 1.5 f_max + residual
    top, front = loads(box)
    damping = loss_factor(ETA)
    alone = {ld.name: harmonic_response(basis, ld, damping, f, surface="outer") for ld in (top, front)}
    both = harmonic_response(basis, [top, front], damping, f, surface="outer")

    plates = [{"surface": s, "thickness": 0.008}
              for s in ("outer_top", "outer_front", "outer_back", "outer_left", "outer_right")]
    plates.append({"surface": "outer_flange", "thickness": 0.015})
    radiators = {name: radiator_from_spec(RadiationSpec(model=name, plates=plates), box.housing, STEEL)
                 for name in ("erp", "foller")}
    power = {name: sound_power(both, r) for name, r in radiators.items()}

    ms = {name: r.mean_square_velocity() for name, r in alone.items()}
    cross = both.mean_square_velocity() - ms["top"] - ms["front"]
    tf_top = alone["top"].transfer_db()
    bands, lv_band = both.band_levels(f.min(), f.max())
    if MPI.COMM_WORLD.rank == 0:
        print(f"free box, {box.dofs} DOFs, {len(basis.eigenvalues) - basis.rigid_count} elastic modes to "
              f"{1.5 * f.max():g} Hz, radiating area S = {both.area:.4f} m^2, {len(f)} lines")
        k = int(np.argmax(tf_top))
        print(f"TF_F of the top force: max {tf_top[k]:.1f} dB re 5e-8 m/s/N at {f[k]:g} Hz")
        share = np.abs(cross) / (ms["top"] + ms["front"])
        print(f"coherent minus incoherent <v^2>: up to {100 * share.max():.0f} % of the incoherent sum "
              f"(cross term 2 Re(v_top^H W v_front))")
        for name, p in power.items():
            print(f"L_W ({name}): total {p.total_L_WA_db:.1f} dB(A) re 1 pW")
        rows = [[float(b), float(lv), float(pe), float(pf)] for b, lv, pe, pf in
                zip(bands.nominal, lv_band, power["erp"].band_L_W_db, power["foller"].band_L_W_db)]
        print(format_table(["band_hz", "L_v_dB", "L_W_erp_dB", "L_W_foller_dB"], rows, "{:.1f}"))
    if args.out:
        with atomic_output_dir(args.out) as tmp:
            write_csv(tmp / OUTPUTS[0], ["frequency_hz", "v2_top_m2_s2", "v2_front_m2_s2", "v2_both_m2_s2",
                                         "TF_top_dB", "L_v_both_dB", "L_W_erp_dB", "L_W_foller_dB"],
                      zip(f, ms["top"], ms["front"], both.mean_square_velocity(), tf_top,
                          levels.level(both.mean_square_velocity(), levels.V0), power["erp"].L_W_db,
                          power["foller"].L_W_db))
            write_csv(tmp / OUTPUTS[1], ["band_hz", "L_v_dB", "L_W_erp_dB", "L_W_foller_dB"],
                      zip(bands.nominal, lv_band, power["erp"].band_L_W_db, power["foller"].band_L_W_db))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
