"""The FE model of a housing: mesh, displacement space, boundary conditions, K and M.

Builds only what the analysis needs: the element size follows from the highest frequency of interest.  Takes
explicit inputs (geometry, material, regions, supports, mesh spec, f_max); the scene-level entry point is
housingfe.scene.build_model_from_scene.
"""
from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass, field

from housingfe.errors import InputError
from housingfe.fe.resolution import assess, check_resolution, wall_element_sizes, walls_of
from housingfe.geometry import HousingMesh, build_mesh
from housingfe.geometry.mesh import LOW_QUALITY, bending_wavelength
from housingfe.materials import Material

# Elements that fail this quality are rejected before any solve (hex: scaled Jacobian, tet: shape ratio) ...
MIN_ELEMENT_QUALITY = LOW_QUALITY
# ... unless they are a few slivers that fill at most this share of the volume: then the run goes on with a
# warning.  Real CAD parts leave such slivers at sub-millimetre chamfers whatever gmsh 4.8 is told (docs/cad.md,
# "Slivers").  Measured on NIST FTC-06 (P2, 20 mm, 33 slivers, worst 0.0014, 4.9e-4 of the volume): the slivers'
# stiffness scaled by 1e-3 (as if cut out) moved the first ten elastic frequencies by <= 0.8 %, by 10 <= 0.2 %,
# while refining to 15 mm moved them by up to 2 %: the slivers matter less than the discretisation error of
# the mesh they come with.  The bound grows with their share: 1e-3 keeps it about there.
MAX_SLIVER_VOLUME_FRACTION = 1e-3
# Below this the mesh passes with a warning on stderr and in summary.json's mesh_quality: slivers the mesher's own
# repair (housingfe.geometry.blocks._refine_slivers, target 0.08) could not remove, as from CAD.  The gearbox scenes'
# worst tetrahedra are at 0.08-0.19 (docs/housings.md).
WARN_ELEMENT_QUALITY = 0.08

# Peak memory of a run ~ base + per DOF (mesh, K and M, the MUMPS LDL^T factors of the inertia count and the
# shift-invert, the Krylov basis).  Upper end of what was measured on this stack: 39 k DOFs 0.5 GB, 136 k
# 1.2-1.7 GB, 317 k 2.8-4.0 GB (STACK-NOTES); `housingfe run` peak RSS: box-free 39 k DOFs 0.83 GB, gearbox-model
# 62 k DOFs 0.84 GB (estimates 0.81 and 1.1 GB).
MEMORY_BASE_BYTES = 0.3e9
MEMORY_PER_DOF_BYTES = 13e3


@dataclass
class HousingModel:
    """Everything the solvers need; a housingfe.fe.structure.Structure.  K, M are PETSc matrices with Dirichlet
    rows eliminated (1 on K's diagonal, 0 on M's); rigid_modes_expected is 6 for a free structure, else 0
    (partial supports may still leave mechanisms, which the modal result counts).  `scene`: the housing scene
    it was built from, when built by housingfe.scene.build_model_from_scene (for the reports only)."""

    housing: HousingMesh
    material: Material
    V: object
    bcs: list
    K: object
    M: object
    rigid_modes_expected: int
    timings: dict = field(default_factory=dict)
    materials: object = None
    scene: object = None
    element_degree: int = 2
    reduced_integration: bool = False
    resolution: object = None   # housingfe.fe.resolution.Resolution of the mesh at f_max (measured on the mesh)
    # the element size (m) the resolution rule gave before quantise_derived_size; None when mesh.size was given
    derived_element_size: float | None = None
    # the meshes made on the derived-size ladder (mesh_on_size_ladder), first the derived size: dicts of size_m,
    # elements, low_count, low_volume_fraction, min, mesh_s, passed; None when mesh.size was given
    element_size_tries: list | None = None

    # ----------------------------------------------------------------------- the Structure protocol
    C = None               # no viscous damping matrix on the bare housing
    symmetric = True       # K is symmetric (linear elasticity)

    @property
    def dofs(self) -> int:
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs

    @property
    def expected_zero_modes(self) -> int | None:
        """6 rigid-body modes for a free housing; None when supported (partial supports may leave mechanisms)."""
        return self.rigid_modes_expected or None

    def load_case(self, load, key: str | None = None):
        """The housingfe.fe.loads.LoadCase (unit-amplitude vector, N per unit load) of a surface load spec."""
        from housingfe.fe.loads import assemble_load

        if getattr(load, "node", None) is not None:
            raise InputError(f"{key or 'loads'}.node: node loads need a drivetrain interior ([coupling])")
        return assemble_load(load, self.housing, self.V, self.bcs)

    def load_vector(self, load):
        """Load vector (PETSc Vec, N per unit amplitude) of a surface load spec."""
        return self.load_case(load).vector

    def to_housing(self, vec):
        """The housing field of a vector in this model's DOFs: the vector itself."""
        return vec

    def rigid_body_vectors(self) -> list:
        """The six exact rigid-body motions (translations, rotations about the origin) as FE vectors."""
        from housingfe.solvers.elasticity import rigid_body_vectors

        return rigid_body_vectors(self.V)

    def basis_stiffness(self):
        """The symmetric stiffness for a modal basis: K itself."""
        return self.K

    def material_damping_matrix(self):
        """K_eta = int eta sigma:eps dx from the per-material loss factors (PETSc Mat, N/m), None if all are 0."""
        import numpy as np
        from dolfinx.fem.petsc import assemble_matrix
        from mpi4py import MPI

        from housingfe.solvers.elasticity import stiffness_form

        eta = self.materials.eta
        if self.V.mesh.comm.allreduce(float(np.abs(eta.x.array).max(initial=0.0)), op=MPI.MAX) == 0.0:
            return None
        D = assemble_matrix(stiffness_form(self.V, self.materials, weight=eta, reduced=self.reduced_integration),
                            bcs=self.bcs, diagonal=0.0)
        D.assemble()
        return D


# Significant digits a DERIVED element size keeps, rounded down (quantise_derived_size).  3 digits: a step of 0.1-1 %
# of the size, so the mesh is at most 1 % finer than the resolution rule asks and never coarser.
DERIVED_SIZE_DIGITS = 3


def quantise_derived_size(size: float, digits: int = DERIVED_SIZE_DIGITS) -> float:
    """A derived element size (m) rounded DOWN to `digits` significant digits (0.0254309 -> 0.0254).

    Why: the mesh must not depend on the last digits of a computed wall thickness.  On NIST FTC-06 at 6 kHz a
    2e-7 relative change of the estimated thin wall (the ray caster in float32 or float64) moved the size from
    0.02543090 to 0.02543089 m, and that decided whether gmsh's sliver refinement split the chamfers' slivers:
    12 378 or 8 152 tetrahedra, a mode near f_max there or not (docs/cad.md).  Rounded to a coarse grid, a size
    changes only where the computed value crosses a grid point (a 1e-3 to 1e-2 relative step), not with every
    round-off.  Down, so that the elements-per-wavelength rule still holds: a finer mesh, never a coarser one
    (at most 1 % finer at 3 digits).  The digits are those of the shortest decimal that gives the float back
    (repr), so a size already on the grid (0.0254) stays as it is."""
    from decimal import ROUND_FLOOR, Decimal

    if not (size > 0.0 and math.isfinite(size)):
        return size
    exact = Decimal(repr(size))
    step = Decimal(1).scaleb(exact.adjusted() - digits + 1)
    return float(exact.quantize(step, rounding=ROUND_FLOOR))


# When the mesh at a DERIVED element size fails the quality rule (check_element_quality: more than
# MAX_SLIVER_VOLUME_FRACTION of the volume in elements below MIN_ELEMENT_QUALITY), it is made again at most this
# many times, each at SIZE_LADDER_FACTOR times the size before, rounded down to DERIVED_SIZE_DIGITS (size_ladder);
# the first that passes is used.  Why: whether gmsh's sliver refinement leaves the chamfers' slivers of a real part
# above or below the bound depends on the nominal size (NIST FTC-06: between 43.4 and 44.5 mm 7 of 12 sizes refused,
# the derived 44.0 mm among them; 39.6 mm passes with 6.1e-4, docs/cad.md).  A finer mesh is never less accurate
# than the rule asks, and the ladder is fixed, so the size used follows from the scene alone.  Three steps make the
# last size 0.73 of the derived one (at most ~2.6 times the elements); a mesh.size written in the scene is never
# changed.
SIZE_LADDER_FACTOR = "0.9"       # a decimal string: the ladder's steps are exact decimals, not binary round-off
SIZE_LADDER_STEPS = 3


def size_ladder(size: float, steps: int = SIZE_LADDER_STEPS) -> list[float]:
    """The derived element size (m) and the `steps` finer ones tried when its mesh fails the quality rule: each
    SIZE_LADDER_FACTOR times the one before, rounded down to DERIVED_SIZE_DIGITS significant digits
    (0.044 -> [0.044, 0.0396, 0.0356, 0.032])."""
    from decimal import Decimal

    sizes = [size]
    for _ in range(steps):
        sizes.append(quantise_derived_size(float(Decimal(repr(sizes[-1])) * Decimal(SIZE_LADDER_FACTOR))))
    return sizes


def derived_element_size(mesh, geometry, f_max: float, material: Material) -> float | None:
    """The element size (m) the resolution rule gives before quantise_derived_size: the bending wavelength of the
    geometry's thinnest wall at f_max (Hz) divided by mesh.elements_per_wavelength; None when the size is not
    derived (mesh.size given, or an imported mesh without a wall thickness)."""
    if mesh.size is not None or geometry.min_thickness is None:
        return None
    wavelength = bending_wavelength(f_max, geometry.min_thickness,
                                    material.youngs_modulus, material.poisson_ratio, material.density)
    return wavelength / mesh.elements_per_wavelength


def element_size(mesh, geometry, f_max: float, material: Material) -> float:
    """Element size (m): explicit mesh.size exactly as written, or the bending wavelength of the geometry's
    thinnest wall at f_max (Hz) divided by mesh.elements_per_wavelength, rounded down to DERIVED_SIZE_DIGITS
    significant digits (quantise_derived_size: reproducible across machines); 0 for an imported mesh.
    mesh: a housingfe.scene.MeshSpec; geometry: a geometry spec.  Every size the package derives comes from here."""
    if mesh.size is not None:
        return mesh.size
    derived = derived_element_size(mesh, geometry, f_max, material)
    if derived is None:                     # an imported mesh brings its own elements
        return 0.0
    return quantise_derived_size(derived)


def build_model(geometry, material: Material, mesh, f_max: float, comm, *, regions: dict | None = None,
                supports=()) -> HousingModel:
    """Mesh a housing geometry and assemble K and M.

    geometry: a geometry spec (housingfe.geometry.specs); material: the housing's Material (SI); mesh: a
    housingfe.scene.MeshSpec (element, degree, size or elements_per_wavelength, layers, allow_large); f_max: the
    highest frequency of interest (Hz), which sets the element size when mesh.size is not given and against which
    the mesh's resolution is checked (housingfe.fe.resolution: InputError before meshing when far too coarse,
    unless mesh.allow_coarse; the measured resolution is model.resolution); regions: cell
    group name -> Material (or a material spec with .resolve()) overriding `material` there; supports: support
    specs (kind fixed | normal | elastic, surface, stiffnesses in N/m^3)."""
    from housingfe.solvers import elasticity

    regions = dict(regions or {})
    size = element_size(mesh, geometry, f_max, material)
    # an imported mesh (geometry kind "mesh") has no wall thickness the check could use: its resolution is not assessed
    walls_known = walls_of(geometry) is not None
    if walls_known:
        check_resolution(geometry, mesh, size, f_max, material)
    check_model_size(geometry, mesh, size, comm)
    derived = mesh.size is None and size > 0.0      # not written in the scene, not an imported mesh's own
    housing, tries = mesh_on_size_ladder(geometry, mesh, size, comm, derived=derived)
    t0 = time.perf_counter()
    V = elasticity.displacement_space(housing.mesh, mesh.degree, mesh.family)
    materials = material_field(regions, housing, material)
    bcs = boundary_conditions(supports, geometry, housing, V)
    reduced = mesh.integration == "reduced"
    K, M = elasticity.assemble_stiffness_mass(V, materials, bcs, foundation_forms(supports, housing, V), reduced)
    # meshing time of every size the ladder made (one mesh unless the derived size's was refused)
    timings = {"mesh_s": sum(t["mesh_s"] for t in tries), "assembly_s": time.perf_counter() - t0}
    free = not bcs and not any(s.kind == "elastic" for s in supports)
    resolution = assess(geometry, mesh, wall_element_sizes(geometry, housing), f_max, material,
                        "longest cell edge in each wall") if walls_known else None
    return HousingModel(housing, material, V, bcs, K, M, 6 if free else 0, timings, materials,
                        element_degree=mesh.degree, reduced_integration=reduced, resolution=resolution,
                        derived_element_size=derived_element_size(mesh, geometry, f_max, material),
                        element_size_tries=tries if derived else None)


def mesh_on_size_ladder(geometry, mesh, size: float, comm, *, derived: bool) -> tuple[HousingMesh, list[dict]]:
    """Mesh the housing at `size` (m) and apply the quality rule (check_element_quality).  For a derived size
    (derived=True) whose mesh the rule refuses, mesh again at the finer sizes of size_ladder, each first through
    the memory guard (check_model_size; a size it refuses ends the ladder), and keep the first that passes, with
    a note on stderr.  Returns (the mesh, one dict per mesh made: size_m, elements, low_count,
    low_volume_fraction, min, mesh_s, passed).  Raises the first size's InputError, naming the sizes tried, when none
    passes; an explicit mesh.size (derived=False) is meshed once and refused as it is."""
    sizes = size_ladder(size) if derived else [size]
    tries, refusal, memory_stop = [], None, None
    wall = getattr(geometry, "min_thickness", None)
    for i, s in enumerate(sizes):
        if i:
            try:
                check_model_size(geometry, mesh, s, comm)
            except InputError:
                memory_stop = s
                break
        housing = build_mesh(geometry, mesh.element, s, mesh.layers, comm, grading=mesh.grading,
                             layer_size=mesh.layer_size)
        quality = housing.quality
        if quality["min"] < MIN_ELEMENT_QUALITY and wall is None and not _few_slivers(quality):
            raise InputError(f"{geometry.file}: geometry.file: element quality {quality['min']:.3f} < "
                             f"{MIN_ELEMENT_QUALITY} ({quality['measure']}); remesh the housing")
        entry = {"size_m": s, "elements": quality.get("elements"), "low_count": quality.get("low_count"),
                 "low_volume_fraction": quality.get("low_volume_fraction"), "min": quality["min"],
                 "mesh_s": housing.mesh_time_s, "passed": False}
        tries.append(entry)
        try:
            check_element_quality(quality, s, wall, mesh.element)
        except InputError as exc:
            refusal = refusal or exc
            continue
        entry["passed"] = True
        if i:
            _note(f"mesh: the derived element size {sizes[0] * 1e3:g} mm left {_share(tries[0])} of the volume in "
                  f"elements below quality {MIN_ELEMENT_QUALITY} (more than {MAX_SLIVER_VOLUME_FRACTION:g}); "
                  f"meshed at {s * 1e3:g} mm instead ({_share(entry)}), {i} step(s) down the fixed ladder of "
                  f"x{SIZE_LADDER_FACTOR} sizes (sizes tried: {_tried(tries)}; docs/cad.md)")
        return housing, tries
    if len(tries) == 1 and memory_stop is None:
        raise refusal
    more = f"; the next finer size, {memory_stop * 1e3:g} mm, exceeds the memory guard" if memory_stop else ""
    raise InputError(f"{refusal} (derived size and the finer sizes of the ladder tried: {_tried(tries)}{more})")


def _share(entry: dict) -> str:
    fraction = entry.get("low_volume_fraction")
    return f"{fraction:.1e}" if fraction is not None else f"quality {entry['min']:.3f}"


def _tried(tries: list[dict]) -> str:
    return ", ".join(f"{t['size_m'] * 1e3:g} mm {_share(t)}" for t in tries)


def _note(text: str) -> None:
    """A note on stderr (rank 0)."""
    from mpi4py import MPI

    if MPI.COMM_WORLD.rank == 0:
        print(f"housingfe: note: {text}", file=sys.stderr)


def check_element_quality(quality: dict, size: float, wall: float | None, element: str) -> str:
    """Refuse a mesh whose elements below MIN_ELEMENT_QUALITY fill more than MAX_SLIVER_VOLUME_FRACTION of its
    volume (or whose quality dict does not say: InputError naming mesh.size); return a warning (printed on
    stderr, kept in quality["warning"]) for fewer such slivers or a worst element below WARN_ELEMENT_QUALITY,
    else "".
    quality: element_quality's dict; size: the element size (m); wall: the thinnest wall (m) or None."""
    q = quality["min"]
    flat = (f": the elements are flat, {size / wall:.0f} times wider ({size:g} m) than the thinnest wall ({wall:g} m)"
            if wall and element == "tet" and size > 3 * wall else "")
    if q < MIN_ELEMENT_QUALITY and _few_slivers(quality):
        warning = (f"mesh: {quality['low_count']} of {quality['elements']} elements below quality "
                   f"{MIN_ELEMENT_QUALITY} (worst {q:.3f}, {quality['measure']}), "
                   f"{quality['low_volume_fraction']:.1e} of the volume: slivers at small features (on NIST "
                   "FTC-06, 4.9e-4 of the volume, even cutting them out moved the first ten frequencies by <= 0.8 %, "
                   "docs/cad.md); check the result against a finer mesh")
        return _warn(quality, warning)
    share = (f" ({quality['low_count']} elements, {quality['low_volume_fraction']:.1e} of the volume: more than the "
             f"{MAX_SLIVER_VOLUME_FRACTION:g} a few slivers may fill)" if "low_volume_fraction" in quality else "")
    if q < MIN_ELEMENT_QUALITY:
        raise InputError(f"mesh.size: element quality {q:.3f} < {MIN_ELEMENT_QUALITY}{share} ({quality['measure']}){flat}; "
                         "make mesh.size at most ~3 wall thicknesses for tetrahedra, or use mesh.element = \"hex\"")
    if q < WARN_ELEMENT_QUALITY:
        warning = (f"mesh: element quality {q:.3f} < {WARN_ELEMENT_QUALITY} ({quality['measure']}){flat}: slivers "
                   "(bench stability: one P2 sliver of quality 0.004 moved a free cube's frequencies by <= 0.17 %); "
                   "check the result against a finer or hexahedral mesh")
        return _warn(quality, warning)
    return ""


def _few_slivers(quality: dict) -> bool:
    """Whether the elements below MIN_ELEMENT_QUALITY fill at most MAX_SLIVER_VOLUME_FRACTION of the volume
    (False where the quality dict does not say)."""
    fraction = quality.get("low_volume_fraction")
    return fraction is not None and fraction <= MAX_SLIVER_VOLUME_FRACTION


def _warn(quality: dict, warning: str) -> str:
    """Keep the warning in quality["warning"] and print it on stderr (rank 0)."""
    quality["warning"] = warning
    from mpi4py import MPI

    if MPI.COMM_WORLD.rank == 0:
        print(f"housingfe: warning: {warning}", file=sys.stderr)
    return warning


def available_memory_bytes() -> tuple[int, int]:
    """(MemAvailable, MemTotal) of this machine in bytes, from /proc/meminfo (0, 0 where it cannot be read)."""
    info = {}
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                key, value = line.split(":", 1)
                info[key] = int(value.split()[0]) * 1024
    except (OSError, ValueError):
        return 0, 0
    return info.get("MemAvailable", info.get("MemFree", 0)), info.get("MemTotal", 0)


def check_model_size(geometry, mesh, size: float, comm) -> dict:
    """Estimate DOFs and peak memory before meshing (housingfe.geometry.mesh.estimate_dofs, MEMORY_*) and raise
    InputError in one line when the estimate exceeds the memory available on this machine (MemAvailable of
    /proc/meminfo; all ranks of a run share the machine), unless mesh.allow_large is set.  The message names
    the element size, its key, and the geometry's largest dimension.  Returns the estimate."""
    from housingfe.geometry.mesh import estimate_dofs

    dofs = estimate_dofs(geometry, mesh.element, mesh.degree, size, mesh.layers, mesh.layer_size)
    need = MEMORY_BASE_BYTES * comm.size + MEMORY_PER_DOF_BYTES * dofs
    available, total = comm.bcast(available_memory_bytes() if comm.rank == 0 else None, root=0)
    estimate = {"dofs": dofs, "memory_bytes": need, "available_bytes": available, "total_bytes": total}
    if available and need > available and not mesh.allow_large and geometry.min_thickness is None:
        raise InputError(f"{geometry.file}: mesh.degree: model too large: ~{dofs:,} DOFs at degree {mesh.degree} "
                         f"need ~{need / 1e9:.1f} GB, this machine has {available / 1e9:.1f} GB available "
                         f"(MemAvailable, {total / 1e9:.1f} GB total); use a coarser mesh file or a lower "
                         f"mesh.degree, or set mesh.allow_large = true to run anyway")
    if available and need > available and not mesh.allow_large:
        size_key = "mesh.size" if mesh.size is not None else "mesh.elements_per_wavelength"
        lengths = {k: v for k, v in geometry.model_dump().items()
                   if isinstance(v, float) and not isinstance(v, bool)}
        largest = max(lengths, key=lengths.get) if lengths else None
        dims = f" (largest dimension: geometry.{largest} = {lengths[largest]:g} m)" if largest else ""
        raise InputError(f"mesh: model too large: ~{dofs:,} DOFs at {size * 1e3:.3g} mm elements need "
                         f"~{need / 1e9:.1f} GB, this machine has {available / 1e9:.1f} GB available "
                         f"(MemAvailable, {total / 1e9:.1f} GB total); check {size_key}{dims} or set "
                         f"mesh.allow_large = true to run anyway")
    return estimate


def material_field(regions: dict, housing: HousingMesh, default: Material):
    """Per-cell material properties: `default`, overridden in the named regions (name -> Material or spec)."""
    from housingfe.solvers.elasticity import MaterialField

    groups = {}
    for name, spec in regions.items():
        if name not in housing.cell_groups:
            raise InputError(f"regions.{name}: no such cell group (known: {', '.join(sorted(housing.cell_groups))})")
        groups[housing.cell_groups[name]] = spec if isinstance(spec, Material) else spec.resolve()
    return MaterialField(housing.mesh, default, housing.cell_tags, groups)


def support_stiffness_per_area(support, area_m2: float) -> tuple[float, float]:
    """(normal, tangential) spring stiffness per unit area (N/m^3) of an elastic support whose surface has the
    area `area_m2` (m^2): the per-area keys as given, a total stiffness (N/m) spread evenly over the area."""
    normal = (support.normal_stiffness if support.normal_stiffness is not None
              else support.total_normal_stiffness / area_m2)
    tangential = (support.tangential_stiffness if support.tangential_stiffness is not None
                  else (support.total_tangential_stiffness or 0.0) / area_m2)
    return normal, tangential


def surface_area(housing: HousingMesh, name: str, key: str = "surface") -> float:
    """Area (m^2) of the named surface group on the mesh, summed over all ranks."""
    import ufl
    from dolfinx import fem
    from mpi4py import MPI

    ds = ufl.Measure("ds", domain=housing.mesh, subdomain_data=housing.facet_tags)
    one = fem.Constant(housing.mesh, 1.0)
    local = fem.assemble_scalar(fem.form(one * ds(_surface_tags(housing, name, key))))
    return float(housing.mesh.comm.allreduce(local, op=MPI.SUM))


def foundation_forms(supports, housing: HousingMesh, V) -> list:
    """Stiffness forms of the elastic supports."""
    import ufl

    from housingfe.solvers.elasticity import foundation_form

    forms = []
    ds = ufl.Measure("ds", domain=housing.mesh, subdomain_data=housing.facet_tags)
    for i, support in enumerate(supports):
        if support.kind == "elastic":
            key = f"supports[{i}].surface"
            tags = _surface_tags(housing, support.surface, key)
            needs_area = support.normal_stiffness is None or support.total_tangential_stiffness is not None
            area = surface_area(housing, support.surface, key) if needs_area else 1.0
            if area <= 0.0:
                raise InputError(f"{key}: surface {support.surface!r} has no area on the mesh: a total "
                                 f"stiffness cannot be spread over it")
            forms.append(foundation_form(V, ds(tags), *support_stiffness_per_area(support, area)))
    return forms


def _surface_tags(housing: HousingMesh, name: str, key: str) -> tuple[int, ...]:
    if name not in housing.facet_groups:
        raise InputError(f"{key}: no surface {name!r} (known: {', '.join(sorted(housing.facet_groups))})")
    return housing.facet_tag_values(name)


def boundary_conditions(supports, geometry, housing: HousingMesh, V) -> list:
    """Dirichlet conditions: supports (fixed / normal) and the plate geometry's edge conditions."""
    from housingfe.solvers.elasticity import clamp_bc

    bcs = []
    for i, support in enumerate(supports):
        if support.kind == "elastic":
            continue
        _surface_tags(housing, support.surface, f"supports[{i}].surface")
        facets = housing.facets(support.surface)
        if support.kind == "fixed":
            bcs += clamp_bc(V, facets)
        else:
            bcs += clamp_bc(V, facets, components=(_normal_axis(housing, facets, f"supports[{i}]"),))
    if geometry.kind == "plate":
        for edge, condition in geometry.edges.model_dump().items():
            facets = housing.facets(f"edge_{edge}")
            if condition == "clamped":
                bcs += clamp_bc(V, facets)
            elif condition == "simply_supported":
                bcs += clamp_bc(V, facets, components=(2,))
    return bcs


def _normal_axis(housing: HousingMesh, facets, key: str) -> int:
    """The coordinate axis normal to a plane, axis-aligned set of facets (for `normal` supports)."""
    import numpy as np
    from dolfinx.mesh import compute_midpoints
    from mpi4py import MPI

    mesh = housing.mesh
    mids = compute_midpoints(mesh, mesh.topology.dim - 1, facets)
    lo = mids.min(axis=0) if len(mids) else np.full(3, np.inf)
    hi = mids.max(axis=0) if len(mids) else np.full(3, -np.inf)
    lo = np.array([mesh.comm.allreduce(v, op=MPI.MIN) for v in lo])
    hi = np.array([mesh.comm.allreduce(v, op=MPI.MAX) for v in hi])
    spread = hi - lo
    axis = int(np.argmin(spread))
    if spread[axis] > 1e-9 * max(1.0, float(spread.max())):
        raise InputError(f"{key}: a normal support needs a plane, axis-aligned surface")
    return axis
