"""How well a mesh resolves the highest frequency of interest (issue 27): elements per bending wavelength of
every wall at f_max, and the eigenfrequency error that implies for the modes near f_max.

The error estimate is empirical, per element family, in x = h / lambda_b (h: the longest cell edge, lambda_b:
the Kirchhoff bending wavelength of the wall at the mode's frequency): a typical error C_typ x^q and a bound
e0 + C_max x^q, fitted on the package's own convergence data: free 0.4 x 0.3 m steel plates 6 and 12 mm thick
meshed with each family at 5-7 element sizes, every elastic mode below 3 / 6 kHz against the same 3-D model
converged (Q3, 12.5 mm) (housingfe/data/benchmarks/resolution_calibration.csv, made by
benchmarks/experiments/resolution/calibrate.py; docs/resolution.md).  q and C_typ are the least-squares line on
log-log axes through the points with 1-50 % error, C_max and e0 the envelope: every calibration point up to 50 %
lies on or under the bound.

It covers the in-plane resolution of bending waves only.  What a mesh of a welded housing adds on top (the layers
through a wall, the singular fields at re-entrant junctions: 0.9-3.4 % on the free box at 4 kHz, docs/benchmarks.md)
is not in it, and Kirchhoff's wavelength is shorter than a thick wall's real one (shear), which makes the
estimate conservative there.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from housingfe.errors import InputError
from housingfe.geometry.mesh import bending_wavelength

# element family -> (C_typical, C_bound, e0, q, (x_min, x_max)): fit_calibration of
# housingfe/data/benchmarks/resolution_calibration.csv (docs/resolution.md).  Typical error C_typical x^q, bound
# e0 + C_bound x^q, x = h / lambda_b; fitted on x_min <= x <= x_max (below x_min the calibration errors are < 1 %).
ERROR_MODEL: dict[str, tuple[float, float, float, float, tuple[float, float]]] = {
    "Q2": (0.7091, 1.8406, 0.00133, 2.017, (0.1086, 0.7028)),
    "Q3": (0.2408, 1.077, 0.00436, 3.251, (0.2505, 1.0542)),
    "S2R": (1.0239, 1.9773, 0.00358, 3.202, (0.2349, 0.7028)),
    "S2": (1.2571, 2.9754, 0.00236, 2.309, (0.1086, 0.7028)),
    "P2": (0.5717, 2.736, 0.0, 1.845, (0.0974, 0.7386)),
    "P3": (0.1521, 0.5346, 0.00396, 3.217, (0.3342, 0.9069)),
}

# the estimated error of the modes near f_max above which a run warns (summary.txt, modes.json) ...
WARN_ERROR = 0.05
# ... and above which it refuses before meshing unless mesh.allow_coarse is set
REFUSE_ERROR = 0.25
# fewer nodes than this per bending wavelength cannot carry the wave at all (two per wavelength is the Nyquist
# limit of the nodal grid): refused whatever the family, calibrated or not
MIN_NODES_PER_WAVELENGTH = 2.0
# Kirchhoff's wavelength describes a wall only while it is several thicknesses long
THIN_WALL_WAVELENGTHS = 6.0


CALIBRATION_FILE = "resolution_calibration.csv"   # in housingfe/data/benchmarks
# the power law is fitted to the calibration points with at least this error: below it the slowly converging
# twisting modes of the free edges (0.2-0.4 % on the finest meshes) and the reference's own error (Q3 12.5 mm
# differs from Q3 16.7 mm by 1.4e-4-4.7e-4) bend the line; they enter the floor e0 of the bound instead
FIT_ERROR_FLOOR = 1e-2
# ... and so are those above this: sorted-order pairs of a mesh that far off no longer compare the same modes
FIT_ERROR_CEILING = 0.5


def calibration_points(path=None) -> dict[str, list[tuple[float, float]]]:
    """family -> [(x = largest cell edge / bending wavelength, |relative frequency error|)] of the calibration
    data (housingfe/data/benchmarks/resolution_calibration.csv unless `path`)."""
    import csv
    from pathlib import Path

    if path is None:
        path = Path(__file__).resolve().parents[1] / "data" / "benchmarks" / CALIBRATION_FILE
    points: dict[str, list[tuple[float, float]]] = {}
    with open(path) as fh:
        for r in csv.DictReader(line for line in fh if not line.startswith("#")):
            points.setdefault(r["family"], []).append(
                (float(r["largest_edge_m"]) / float(r["wavelength_m"]), abs(float(r["relative_error"]))))
    return points


def fit_calibration(path=None) -> dict[str, tuple[float, float, float, float, tuple[float, float]]]:
    """The ERROR_MODEL entries from the calibration data, per family (C_typical, C_bound, e0, q, (x_min, x_max)):
    on the points with FIT_ERROR_FLOOR <= err <= FIT_ERROR_CEILING, q and C_typical are the least-squares line of
    log err against log x (half the points lie above it: a typical error), C_bound = max err / x^q over them, and
    e0 the floor that puts every point with err <= FIT_ERROR_CEILING under e0 + C_bound x^q (the slowly converging
    twisting modes of the free edges); (x_min, x_max) is the range of x of the fitted points."""
    import numpy as np

    model = {}
    for family, pts in calibration_points(path).items():
        x_all, err_all = np.array([p for p in pts if p[1] <= FIT_ERROR_CEILING]).T
        fit = err_all >= FIT_ERROR_FLOOR
        x, err = x_all[fit], err_all[fit]
        q, log_c = np.polyfit(np.log(x), np.log(err), 1)
        q = round(float(q), 3)    # rounded first: the envelope is that of the rounded exponent
        c_bound = float(np.max(err / x**q))
        e0 = max(0.0, float(np.max(err_all - c_bound * x_all**q)))
        # the bound's constants rounded up, so that the data stay under the rounded bound
        model[family] = (round(float(np.exp(log_c)), 4), math.ceil(c_bound * 1e4) / 1e4,
                         math.ceil(e0 * 1e5) / 1e5, q, (round(float(x.min()), 4), round(float(x.max()), 4)))
    return model


def element_family(mesh) -> str:
    """The name of a mesh spec's element family: Q2, Q3, S2R (20-node reduced), S2, P2, ... (Q: hexahedra with
    Lagrange nodes, S: serendipity hexahedra, P: tetrahedra)."""
    if mesh.element == "tet":
        return f"P{mesh.degree}"
    if mesh.family == "serendipity":
        return "S2R" if mesh.integration == "reduced" else "S2"
    return f"Q{mesh.degree}"


def nodes_per_element_edge(mesh) -> int:
    """Node spacings per element edge: the polynomial degree (Lagrange and serendipity alike)."""
    return int(mesh.degree)


def graded_largest_element(size: float, grading: float) -> float:
    """The middle element length (m) of gmsh's symmetric "Bump" distribution whose mean is `size` and whose end
    to middle ratio is `grading` (the size profile is a parabola, s(t) = s_mid (1 - 4 (1 - g) (t - 1/2)^2), so
    s_mid = size * atanh(sqrt(1 - g)) / sqrt(1 - g)); `size` for a uniform mesh."""
    if grading >= 1.0:
        return size
    c = math.sqrt(1.0 - grading)
    return size * math.atanh(c) / c


@dataclass
class Resolution:
    """The resolution of a mesh at f_max (Hz).  walls: one dict per wall (name, thickness_m, element_size_m = h,
    bending_wavelength_m, x = h / bending wavelength, elements_per_wavelength, nodes_per_wavelength, estimated_error, error_bound);
    estimated_error / error_bound: those of the worst wall (relative frequency error of a mode near f_max, typical
    and the calibration's upper bound; None for an uncalibrated family); status: "ok", "coarse" (warned) or
    "far too coarse" (refused before meshing unless mesh.allow_coarse)."""

    family: str
    f_max_hz: float
    element_size_m: float           # that of the worst wall
    element_size_measure: str
    walls: list[dict]
    status: str
    warnings: list[str] = field(default_factory=list)

    @property
    def worst(self) -> dict:
        """The wall that decides: the fewest nodes per bending wavelength (the largest error)."""
        return min(self.walls, key=lambda w: w["nodes_per_wavelength"])

    @property
    def estimated_error(self) -> float | None:
        return self.worst["estimated_error"]

    @property
    def error_bound(self) -> float | None:
        return self.worst["error_bound"]

    @property
    def below_calibration(self) -> bool:
        """The worst wall is finer than every calibration point with >= 1 % error: the typical error is < 1 %."""
        return self.family in ERROR_MODEL and self.worst["x"] < ERROR_MODEL[self.family][4][0]

    @property
    def extrapolated(self) -> bool:
        """The worst wall is coarser than every calibration point."""
        return self.family in ERROR_MODEL and self.worst["x"] > ERROR_MODEL[self.family][4][1]

    def as_dict(self) -> dict:
        """modes.json's "resolution" entry."""
        model = ERROR_MODEL.get(self.family)
        if model is None:
            described = f"no calibration for {self.family} elements"
        else:
            ct, cb, e0, q, (lo, hi) = model
            described = (f"relative frequency error of a mode at x = h / lambda_b: typical {ct:.4g} x^{q:.3g}, "
                         f"bound {e0:.3g} + {cb:.4g} x^{q:.3g}; fitted for x in [{lo:.3g}, {hi:.3g}] "
                         "(housingfe/data/benchmarks/resolution_calibration.csv, docs/resolution.md)")
        return {
            "element_family": self.family,
            "f_max_hz": self.f_max_hz,
            "element_size_m": self.element_size_m,
            "element_size_measure": self.element_size_measure,
            "walls": self.walls,
            "worst_wall": self.worst["name"],
            "estimated_error_near_f_max": self.estimated_error,
            "error_bound_near_f_max": self.error_bound,
            "below_calibration": self.below_calibration,
            "extrapolated": self.extrapolated,
            "status": self.status,
            "warnings": self.warnings,
            "error_model": described,
            "scope": "in-plane resolution of the walls' bending waves at f_max; not included: the layers through "
                     "the walls, re-entrant junctions, the geometry and material model",
            "thresholds": {"warn_error": WARN_ERROR, "refuse_error": REFUSE_ERROR,
                           "min_nodes_per_wavelength": MIN_NODES_PER_WAVELENGTH},
        }


def percent(err: float) -> str:
    """An error as a short percentage: ~3.1 %, ~0.42 %, ~50 %, > 100 %."""
    return "> 100 %" if err > 1.0 else f"~{err * 100:.2g} %"


def error_at(family: str, x: float) -> tuple[float | None, float | None]:
    """(typical, bound) relative frequency error of a mode at x = h / lambda_b for an element family (ERROR_MODEL;
    (None, None) for an uncalibrated family)."""
    if family not in ERROR_MODEL:
        return None, None
    ct, cb, e0, q, _ = ERROR_MODEL[family]
    return ct * x**q, e0 + cb * x**q


def walls_of(geometry) -> dict | None:
    """{wall name: thickness (m)} of a geometry spec (its wall_thicknesses, else its min_thickness as the thinnest
    wall), or None when it does not know them (an imported mesh)."""
    walls = getattr(geometry, "wall_thicknesses", None)
    if walls:
        return walls
    thinnest = getattr(geometry, "min_thickness", None)
    return {"thinnest wall": thinnest} if thinnest else None


def assess(geometry, mesh, element_size, f_max: float, material, measure: str) -> Resolution:
    """The resolution of a mesh of `element_size` (m, the longest cell edge; or a dict wall name -> that of each
    wall, see wall_element_sizes; `measure` says where it comes from) at f_max (Hz) on every wall of a geometry spec (its wall_thicknesses, else its min_thickness), for the
    housing's material (SI) and a scene's mesh spec (element, degree, family, integration)."""
    family = element_family(mesh)
    p = nodes_per_element_edge(mesh)
    thicknesses = walls_of(geometry)
    walls = []
    for name, t in thicknesses.items():
        h = element_size[name] if isinstance(element_size, dict) else element_size
        lam = bending_wavelength(f_max, t, material.youngs_modulus, material.poisson_ratio, material.density)
        typical, bound = error_at(family, h / lam)
        walls.append({"name": name, "thickness_m": t, "element_size_m": h, "bending_wavelength_m": lam,
                      "x": h / lam, "elements_per_wavelength": lam / h, "nodes_per_wavelength": p * lam / h,
                      "estimated_error": typical, "error_bound": bound})
    worst = min(walls, key=lambda w: w["nodes_per_wavelength"])
    err = worst["estimated_error"]
    far = worst["nodes_per_wavelength"] < MIN_NODES_PER_WAVELENGTH or (err is not None and err > REFUSE_ERROR)
    coarse = far or (err is not None and err > WARN_ERROR)
    warnings = []
    if err is None:
        warnings.append(f"no error calibration for {family} elements: the discretisation error is not estimated")
    if coarse:
        warnings.append(
            f"mesh too coarse for f_max = {f_max:g} Hz: {worst['elements_per_wavelength']:.2g} {family} elements per "
            f"bending wavelength of the {worst['name']} ({worst['thickness_m'] * 1e3:.3g} mm)"
            + (f", estimated error of the modes near f_max {percent(err)}" if err is not None else "")
            + (" (far too coarse)" if far else f" (warned above {WARN_ERROR * 100:g} %)"))
    thick = [w["name"] for w in walls if w["bending_wavelength_m"] < THIN_WALL_WAVELENGTHS * w["thickness_m"]]
    if thick:
        warnings.append(f"no thin plate at {f_max:g} Hz: {', '.join(thick)} (bending wavelength < "
                        f"{THIN_WALL_WAVELENGTHS:g} thicknesses): the wave picture, and this estimate, do not hold")
    status = "far too coarse" if far else "coarse" if coarse else "ok"
    return Resolution(family, f_max, worst["element_size_m"], measure, walls, status, warnings)


def check_resolution(geometry, mesh, size: float, f_max: float, material) -> Resolution:
    """Before meshing: the resolution of elements of nominal `size` (m; with grading the largest element of the
    Bump distribution) at f_max (Hz); raises InputError in one line, naming the size key, the numbers and a size
    that would do, when the mesh is far too coarse (see assess) and mesh.allow_coarse is not set."""
    largest = graded_largest_element(size, getattr(mesh, "grading", 1.0))
    res = assess(geometry, mesh, largest, f_max, material, "nominal element size before meshing"
                 + (" (the middle element of the graded edges)" if largest != size else ""))
    if res.status == "far too coarse" and not getattr(mesh, "allow_coarse", False):
        w = res.worst
        key = "mesh.size" if mesh.size is not None else "mesh.elements_per_wavelength"
        err = f", estimated error of the modes near f_max {percent(res.estimated_error)}" \
            if res.estimated_error is not None else ""
        good = suggested_size(res.family, w["bending_wavelength_m"], mesh.degree)
        raise InputError(
            f"{key}: {largest * 1e3:.3g} mm elements are far too coarse for f_max = {f_max:g} Hz: "
            f"{w['elements_per_wavelength']:.2g} {res.family} elements per bending wavelength of the {w['name']} "
            f"({w['thickness_m'] * 1e3:.3g} mm thick, lambda_b = {w['bending_wavelength_m'] * 1e3:.3g} mm){err}"
            + (f" (at {f_max:g} Hz no thin plate: the wavelength is under {THIN_WALL_WAVELENGTHS:g} thicknesses)"
               if w["bending_wavelength_m"] < THIN_WALL_WAVELENGTHS * w["thickness_m"] else "")
            + f"; use mesh.size <= {good * 1e3:.3g} mm for ~{WARN_ERROR * 100:g} %, a lower f_max, or set "
            f"mesh.allow_coarse = true to run anyway")
    return res


def suggested_size(family: str, wavelength: float, degree: int) -> float:
    """The element size (m) whose typical error at `wavelength` (m) is WARN_ERROR (uncalibrated families: four
    node spacings per wavelength)."""
    if family in ERROR_MODEL:
        ct, _, _, q, _ = ERROR_MODEL[family]
        return wavelength * (WARN_ERROR / ct) ** (1.0 / q)
    return wavelength * degree / 4.0


def cell_longest_edges(mesh):
    """The longest edge (m) of every local cell of a dolfinx tetrahedral or hexahedral mesh (from its vertices:
    housingfe's meshes have affine cells)."""
    import itertools

    import numpy as np
    from dolfinx import cpp

    tdim = mesh.topology.dim
    n_local = mesh.topology.index_map(tdim).size_local
    if n_local == 0:
        return np.zeros(0)
    nodes = cpp.mesh.entities_to_geometry(getattr(mesh, "_mesh", mesh), tdim, np.arange(n_local, dtype=np.int32),
                                          False)
    x = mesh.geometry.x
    if nodes.shape[1] in (4, 10):          # tetrahedron: every vertex pair is an edge
        pairs = list(itertools.combinations(range(4), 2))
    else:                                  # hexahedron, vertices in lexicographic order: edges differ in one bit
        pairs = [(a, b) for a, b in itertools.combinations(range(8), 2) if bin(a ^ b).count("1") == 1]
    return np.max([np.linalg.norm(x[nodes[:, a]] - x[nodes[:, b]], axis=1) for a, b in pairs], axis=0)


def largest_cell_edge(mesh, cells=None) -> float:
    """The longest cell edge (m) of a dolfinx mesh (of the given local cells only), over all ranks: the element
    size that limits how well the mesh resolves a bending wave; 0 where there are no such cells."""
    from mpi4py import MPI

    lengths = cell_longest_edges(mesh)
    if cells is not None:
        lengths = lengths[cells[cells < len(lengths)]]
    return mesh.comm.allreduce(float(lengths.max(initial=0.0)), op=MPI.MAX)


def wall_element_sizes(geometry, housing) -> dict[str, float]:
    """The longest cell edge (m) in each wall of wall_thicknesses (its cells: the cell groups that
    geometry.wall_cell_groups names by prefix); a wall without cells of its own gets the mesh's longest edge."""
    import numpy as np
    from mpi4py import MPI

    mesh = housing.mesh
    lengths = cell_longest_edges(mesh)
    overall = mesh.comm.allreduce(float(lengths.max(initial=0.0)), op=MPI.MAX)
    prefixes = getattr(geometry, "wall_cell_groups", {})
    sizes = {}
    for wall in getattr(geometry, "wall_thicknesses", None) or {"thinnest wall": geometry.min_thickness}:
        tags = [tag for name, tag in housing.cell_groups.items()
                if any(name.startswith(p) for p in prefixes.get(wall, ()))]
        cells = np.unique(np.concatenate([housing.cell_tags.find(t) for t in tags])) if tags else np.zeros(0, int)
        cells = cells[cells < len(lengths)]
        local = float(lengths[cells].max(initial=0.0))
        size = mesh.comm.allreduce(local, op=MPI.MAX)
        sizes[wall] = size if size > 0 else overall
    return sizes
