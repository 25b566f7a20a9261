"""Scenes: TOML files describing what to build and what to compute, validated with pydantic.

A scene is addressed by the name of a built-in scene (housingfe/scenes/<name>.toml) or by a path.
All values are SI (m, Pa, kg/m^3, Hz).  Every table forbids unknown keys, so a typo is an error that
names the file and the key, never a silently ignored setting.
"""
from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal, Optional

from pydantic import (
    Field,
    PositiveFloat,
    PositiveInt,
    field_validator,
    model_validator,
)

from housingfe.drivetrain.interior import CouplingSpec
from housingfe.errors import InputError
from housingfe.geometry.specs import Geometry
from housingfe.materials import LIBRARY, Material
from housingfe.scenefile import (
    SceneInfo,
    _Strict,
    apply_overrides,
    naming_the_override,
    parse_table,
    read_scene_dict,
)


class MaterialSpec(_Strict):
    """A library material by name, with optional overrides of its values."""

    name: str = "steel"  # a material of the library (see Materials); the keys below override its values
    youngs_modulus: Optional[PositiveFloat] = None
    poisson_ratio: Optional[float] = None  # in (-1, 0.5)
    density: Optional[PositiveFloat] = None
    loss_factor: Optional[float] = Field(None, ge=0.0, lt=1.0)  # hysteretic eta of this material

    @model_validator(mode="after")
    def _check(self):
        if self.name not in LIBRARY and None in (self.youngs_modulus, self.poisson_ratio, self.density):
            raise ValueError(f"name: {self.name!r} is not in the library ({', '.join(LIBRARY)}); "
                             "give youngs_modulus, poisson_ratio and density")
        if self.poisson_ratio is not None and not -1.0 < self.poisson_ratio < 0.5:
            raise ValueError(f"poisson_ratio: {self.poisson_ratio} is outside (-1, 0.5)")
        return self

    def resolve(self) -> Material:
        base = LIBRARY.get(self.name, Material(self.name, 1.0, 0.0, 1.0))
        return Material(self.name,
                        self.youngs_modulus if self.youngs_modulus is not None else base.youngs_modulus,
                        self.poisson_ratio if self.poisson_ratio is not None else base.poisson_ratio,
                        self.density if self.density is not None else base.density,
                        self.loss_factor if self.loss_factor is not None else base.loss_factor)


class MeshSpec(_Strict):
    """Discretisation.  The element size follows from the highest frequency of interest unless `size` is
    given: size = bending wavelength of the thinnest wall at f_max / elements_per_wavelength, rounded down to 3
    significant digits (so that the mesh does not depend on the last digits of a computed wall thickness); a
    given `size` is used as written.  A model whose estimated memory exceeds the machine's available memory
    stops before meshing unless allow_large."""

    element: Literal["hex", "tet"] = "hex"
    degree: Literal[1, 2, 3] = 2
    elements_per_wavelength: PositiveFloat = 6.0
    layers: PositiveInt = 1
    # hex meshes: element length through the walls (m); each wall gets at least ceil(thickness / layer_size)
    # layers, so a thick flange gets more than a thin wall (free box, S2R 30 mm: 4 mm -> 2 layers in the 8 mm
    # walls, 4 in the 15 mm flange: 0.92 % at 32 k DOFs, where 3 everywhere needs 40 k for 0.86 %).
    layer_size: Optional[PositiveFloat] = None
    size: Optional[PositiveFloat] = None
    # hex meshes: the ratio of the end to the middle element length along every block edge longer than a wall
    # (gmsh's "Bump"; 1 = uniform).  Walls meet at re-entrant edges whose singular fields make uniform meshes
    # converge at O(h) only (box, Q3: rates 0.7-1.4 per mode); < 1 puts the elements there.
    grading: float = Field(default=1.0, gt=0.0, le=1.0)
    allow_large: bool = False   # run even when the estimated memory exceeds what the machine has available
    # run even when the mesh is far too coarse for f_max (housingfe.fe.resolution: the estimated error of the modes
    # near f_max above REFUSE_ERROR); the run then reports the estimate and warns
    allow_coarse: bool = False
    # "serendipity" (hex, degree 2: the 20-node brick) with integration "reduced" (2x2x2 Gauss points in the
    # stiffness, the mass fully integrated) is CalculiX's / Abaqus' C3D20R: softer in bending than Q2/Q3 at
    # the same DOFs; with 3 layers through the walls it reaches 0.86 % on the free box at 40 k DOFs (bench
    # modal).  Modal analyses only: loads, sample points and couplings use Lagrange nodes.
    family: Literal["lagrange", "serendipity"] = "lagrange"
    integration: Literal["full", "reduced"] = "full"

    @model_validator(mode="after")
    def _element_family(self):
        if self.family == "serendipity" and (self.element != "hex" or self.degree != 2):
            raise ValueError("family: serendipity elements need element = \"hex\" and degree = 2")
        if self.integration == "reduced" and self.family != "serendipity":
            raise ValueError("integration: reduced integration needs family = \"serendipity\" (Lagrange bricks "
                             "under-integrated have spurious zero-energy modes)")
        return self


class ModalSpec(_Strict):
    """Eigenmodes: all modes below f_max (Hz), proven complete by an inertia count."""

    f_max: PositiveFloat  # every mode below this frequency
    tolerance: PositiveFloat = 1e-10  # relative eigen-residual the solver must reach


class Spectrum(_Strict):
    """A tabulated amplitude spectrum: values (rms, load units) at frequencies (Hz), interpolated linearly
    in log-frequency, held constant outside the table."""

    frequencies: list[PositiveFloat] = Field(min_length=1)
    values: list[float] = Field(min_length=1, json_schema_extra={"unit": "of what it scales (load: N, N m, Pa; "
                                                                         "loss factor: -)"})

    @model_validator(mode="after")
    def _check(self):
        if len(self.frequencies) != len(self.values):
            raise ValueError("values: must have as many entries as frequencies")
        if any(b <= a for a, b in zip(self.frequencies, self.frequencies[1:])):
            raise ValueError("frequencies: must increase")
        return self


class LoadSpec(_Strict):
    """One load case.  force: `amplitude` N along `direction`, spread uniformly over the facets of
    `surface` within `radius` of `point` (a true point load is singular in solids).  moment: a couple of
    `amplitude` N m about `direction`, as a linear traction field over the same kind of patch.  pressure:
    uniform `amplitude` Pa on the whole surface, pushing along -n.  With `node` instead of a surface, a force
    or moment acts on a node of the [coupling] interior (a shaft node "<shaft>:<index>" or a bore master), e.g.
    the thesis' 1 N m torque at the wheel centre (Sec. 5.4).  Amplitudes are rms; `spectrum` scales them per
    frequency (flat when absent)."""

    name: str
    kind: Literal["force", "moment", "pressure"]
    surface: Optional[str] = None
    node: Optional[str] = None
    point: Optional[list[float]] = Field(None, min_length=3, max_length=3)
    direction: Optional[list[float]] = Field(None, min_length=3, max_length=3)
    radius: PositiveFloat = 0.005
    amplitude: float = Field(1.0, json_schema_extra={"unit": "N, N m or Pa (by kind)"})
    spectrum: Optional[Spectrum] = None

    @model_validator(mode="after")
    def _check(self):
        if (self.surface is None) == (self.node is None):
            raise ValueError("surface: give either surface (a load on the housing) or node (on the interior)")
        if self.kind != "pressure" and (self.direction is None or sum(c * c for c in self.direction) == 0):
            raise ValueError("direction: required and non-zero for a force or moment load")
        if self.node is not None:
            if self.kind == "pressure":
                raise ValueError("kind: a node load is a force or a moment")
            if self.point is not None:
                raise ValueError("point: not used with node (the node is the point)")
        elif self.kind != "pressure" and self.point is None:
            raise ValueError("point: required for a force or moment load (m)")
        return self


class DampingSpec(_Strict):
    """Damping.  loss_factor: hysteretic eta, global; loss_factor_bands: eta over frequency (e.g. per
    1/3-octave band from T60, eq. 4.2), log-interpolated; modal_damping_ratio: viscous xi per mode (with
    the direct solver it is applied as eta = 2 xi, which is exact at each resonance)."""

    loss_factor: Optional[float] = Field(None, ge=0.0, lt=1.0)
    loss_factor_bands: Optional[Spectrum] = None
    modal_damping_ratio: Optional[float] = Field(None, ge=0.0, lt=0.5)
    # per elastic mode, in ascending order; modes beyond the list take its last value
    modal_damping_ratios: Optional[list[Annotated[float, Field(ge=0.0, lt=0.5)]]] = Field(None, min_length=1)

    @model_validator(mode="after")
    def _one(self):
        given = [x is not None for x in (self.loss_factor, self.loss_factor_bands, self.modal_damping_ratio,
                                         self.modal_damping_ratios)]
        if sum(given) > 1:
            raise ValueError("loss_factor: give only one of loss_factor, loss_factor_bands, modal_damping_ratio(s)")
        return self


class ResponsePointSpec(_Strict):
    """A named response point for point FRFs (points.csv): `point` (m) is snapped to the nearest point of
    `surface` (default: every tagged surface of the housing); farther than `tolerance` (m, default one element
    size) is an error.  direction: a vector (the response along it), "normal" (the outward surface normal at
    the snapped point), or absent (the x, y and z components)."""

    name: str = Field(min_length=1)
    point: list[float] = Field(min_length=3, max_length=3)
    direction: Optional[list[float] | Literal["normal"]] = None
    surface: Optional[str] = None
    tolerance: Optional[PositiveFloat] = Field(None, json_schema_extra={"unit": "m"})

    @model_validator(mode="after")
    def _check(self):
        if isinstance(self.direction, list) and (len(self.direction) != 3 or
                                                 sum(c * c for c in self.direction) == 0):
            raise ValueError("direction: a non-zero vector of 3 components, \"normal\", or absent (x, y, z)")
        return self


class HarmonicSpec(_Strict):
    """Forced harmonic response on lines f_min, f_min + df, ... <= f_max (Hz).

    solver: "modal" (superposition with residual flexibility), "direct" (one factorisation per line),
    "projected" (the full K, C, M on the modal basis + residual vectors: for bearing damping and non-symmetric
    fluid films), "both" (modal or projected, checked against direct), or "auto" (modal, or projected when the
    interior has bearing damping or a non-symmetric stiffness, direct for per-material loss factors).
    modal_basis_factor: modes up to this multiple of f_max are kept dynamically; the rest enter through
    the residual (static) flexibility when `residual` is true.
    """

    f_min: PositiveFloat = 4.88
    f_max: PositiveFloat
    df: PositiveFloat = 4.88
    solver: Literal["auto", "modal", "direct", "projected", "both"] = "auto"
    residual: bool = True
    modal_basis_factor: float = Field(1.5, ge=1.0, le=4.0)
    surface: str = "outer"
    # sizes of area-weighted sample-point sets (counts, eq. 5.4), each at most the surface's facet count
    sample_points: list[PositiveInt] = [18, 36, 48, 94]
    deflection_shapes_hz: list[PositiveFloat] = []
    # named response points: point FRFs (receptance, mobility, accelerance) in points.csv
    points: list[ResponsePointSpec] = []
    # a shaft node of the [coupling] interior: TF_omega = L_v - L_omega with omega its angular velocity about
    # the shaft axis (thesis eq. 5.5)
    angular_velocity_node: Optional[str] = None

    @model_validator(mode="after")
    def _check(self):
        if self.f_min > self.f_max:
            raise ValueError("f_min: must not exceed f_max")
        names = [p.name for p in self.points]
        if len(set(names)) != len(names):
            raise ValueError("points: response point names must be unique")
        return self

    @property
    def frequencies(self):
        import numpy as np

        n = int(np.floor((self.f_max - self.f_min) / self.df + 1e-9)) + 1
        return self.f_min + self.df * np.arange(n)


class RadiationPlate(_Strict):
    """A radiating plate of the housing: a surface group and its thickness (m); `count` identical copies
    are counted once more each in Föller's means."""

    surface: str
    thickness: PositiveFloat
    count: PositiveInt = 1


class RadiationSpec(_Strict):
    """Sound power from the forced response (eq. 4.16): L_W = L_v + 10 lg(S/S0) + L_sigma with L_sigma from
    a registered radiation model (housingfe.radiation.radiators.RADIATORS): "erp" (sigma = 1), "foller" (the box
    model of Sec. 4.7 on the plates below, areas and perimeters taken from the mesh) or "numerical" (Rayleigh
    integral per plate over the computed velocity field)."""

    model: str
    plates: list[RadiationPlate] = []

    @field_validator("model")
    @classmethod
    def _registered(cls, name):
        from housingfe.radiation.radiators import check_radiator  # loaded on use: the scene check stays light

        return check_radiator(name)

    @model_validator(mode="after")
    def _check(self):
        from housingfe.radiation.radiators import RADIATORS

        if RADIATORS[self.model].needs_plates and not self.plates:
            raise ValueError(f"plates: the {self.model} model needs the radiating plates "
                             "(surface and thickness of each)")
        return self


class Analyses(_Strict):
    modal: Optional[ModalSpec] = None
    harmonic: Optional[HarmonicSpec] = None

    @property
    def f_max(self) -> float:
        """Highest frequency any requested analysis needs (Hz): sets the mesh size."""
        return max(self.modal.f_max if self.modal else 0.0, self.harmonic.f_max if self.harmonic else 0.0)


class OutputSpec(_Strict):
    mode_pictures: int = Field(6, ge=0, le=12)
    paraview: bool = True
    pictures: bool = True


class ReferenceSpec(_Strict):
    """Published data to compare with: a section of housingfe/data/roosmalen1994.toml and/or a list of
    reference eigenfrequencies (Hz) with their source."""

    section: Optional[str] = None
    frequencies_hz: Optional[list[PositiveFloat]] = None
    source: str = ""


class SupportSpec(_Strict):
    """A support on a named surface group of the geometry.

    fixed: all displacement components zero.  normal: zero displacement normal to a plane, axis-aligned
    surface.  elastic: distributed springs, normal_stiffness and tangential_stiffness per unit area (N/m^3), or
    total_normal_stiffness and total_tangential_stiffness of the whole surface (N/m: what a frame's or an
    isolator's data sheet gives), spread evenly over the surface's area on the mesh.
    """

    surface: str
    kind: Literal["fixed", "normal", "elastic"]
    normal_stiffness: Optional[PositiveFloat] = None
    tangential_stiffness: Optional[float] = Field(None, ge=0.0)
    total_normal_stiffness: Optional[PositiveFloat] = None
    total_tangential_stiffness: Optional[float] = Field(None, ge=0.0)

    @model_validator(mode="after")
    def _check(self):
        given = [k for k in ("normal_stiffness", "tangential_stiffness", "total_normal_stiffness",
                             "total_tangential_stiffness") if getattr(self, k) is not None]
        if self.kind != "elastic" and given:
            raise ValueError(f"{given[0]}: only for an elastic support (this one is kind = {self.kind!r})")
        if self.kind == "elastic":
            if (self.normal_stiffness is None) == (self.total_normal_stiffness is None):
                raise ValueError("normal_stiffness: an elastic support needs exactly one of normal_stiffness "
                                 "(N/m^3) or total_normal_stiffness (N/m)")
            if self.tangential_stiffness is not None and self.total_tangential_stiffness is not None:
                raise ValueError("tangential_stiffness: give tangential_stiffness (N/m^3) or "
                                 "total_tangential_stiffness (N/m), not both")
        return self


class HousingScene(_Strict):
    scene: SceneInfo
    geometry: Geometry
    material: MaterialSpec = MaterialSpec()
    # materials of named cell groups (e.g. a gasket layer), overriding `material` there
    regions: dict[str, MaterialSpec] = {}
    supports: list[SupportSpec] = []
    mesh: MeshSpec = MeshSpec()
    analysis: Analyses
    loads: list[LoadSpec] = []
    damping: DampingSpec = DampingSpec()
    radiation: Optional[RadiationSpec] = None
    output: OutputSpec = OutputSpec()
    reference: Optional[ReferenceSpec] = None
    # the gearbox interior: bore masters, shafts, gears, bearings, gear meshes, tie rods (housingfe.drivetrain.interior)
    coupling: Optional[CouplingSpec] = None

    @model_validator(mode="after")
    def _needs_analysis(self):
        if self.analysis.modal is None and self.analysis.harmonic is None:
            raise ValueError("analysis: the scene requests no analysis (add [analysis.modal] or "
                             "[analysis.harmonic])")
        if self.radiation is not None and self.analysis.harmonic is None:
            raise ValueError("radiation: sound power needs a forced response ([analysis.harmonic])")
        if self.analysis.harmonic is not None and not self.loads:
            raise ValueError("loads: a harmonic analysis needs at least one [[loads]] entry")
        if self.coupling is None:
            if any(load.node is not None for load in self.loads):
                raise ValueError("loads: a node load needs a [coupling] interior")
            if self.analysis.harmonic is not None and self.analysis.harmonic.angular_velocity_node is not None:
                raise ValueError("analysis.harmonic.angular_velocity_node: needs a [coupling] interior")
        names = [load.name for load in self.loads]
        if len(set(names)) != len(names):
            raise ValueError("loads: load case names must be unique")
        if self.mesh.family != "lagrange" and (self.analysis.harmonic is not None or self.coupling is not None
                                               or self.supports):
            raise ValueError("mesh.family: serendipity elements support modal analyses of free housings only "
                             "(loads, supports, sample points and couplings use Lagrange nodes)")
        return self


def load_housing_scene(name_or_path: str, overrides: list[str] | None = None) -> tuple[HousingScene, Path]:
    """Read and validate a housing scene; InputError with file and key on any problem."""
    data, path = read_scene_dict(name_or_path)
    apply_overrides(data, overrides or [])
    kind = data.get("scene", {}).get("kind") if isinstance(data.get("scene"), dict) else None
    if kind == "source":
        raise InputError(f"{path}: scene.kind: this is a source scene; run it with `housingfe source`")
    if kind == "runup":
        raise InputError(f"{path}: scene.kind: this is a run-up scene, not a housing scene; run it with "
                         "`housingfe run`")
    _resolve_geometry_file(data, path)
    try:
        scene = parse_table(HousingScene, data, path)
        _check_block_extent(scene.geometry, path)
    except InputError as exc:
        raise naming_the_override(exc, overrides) from None
    return scene, path


# the largest extent of a built-in (block-model) housing, as for CAD and mesh files (geometry.cad,
# geometry.imported_mesh): beyond it a scene was almost surely written in millimetres
PLAUSIBLE_BLOCK_EXTENT_M = 20.0


def _check_block_extent(geometry, path: Path) -> None:
    """InputError naming the key when a top-level length of a built-in (block-model) housing exceeds
    PLAUSIBLE_BLOCK_EXTENT_M: lengths in millimetres would otherwise mesh a 325 m box (the memory guard stops only
    some of them, and with `mesh.size` in millimetres too nothing would).  The spec's own fields, not its block
    model: building that costs 0.2 s for a gearbox, on every scene load."""
    from housingfe.geometry.registry import own_mesh_kind

    if own_mesh_kind(geometry) is not None:
        return      # CAD and mesh files check their own extent against their `units`
    for key, value in geometry.model_dump().items():
        if isinstance(value, float) and value > PLAUSIBLE_BLOCK_EXTENT_M:
            raise InputError(f"{path}: geometry.{key}: {value:g} m is implausible for a housing (at most "
                             f"{PLAUSIBLE_BLOCK_EXTENT_M:g} m across); scene lengths are in m: it looks like "
                             f"millimetres ({value:g} mm = {value / 1e3:g} m)")


def _resolve_geometry_file(data: dict, path: Path) -> None:
    """An imported geometry's `file` (CAD, mesh) is relative to the scene file: make it absolute."""
    geometry = data.get("geometry")
    if isinstance(geometry, dict) and isinstance(geometry.get("file"), str):
        file = Path(geometry["file"]).expanduser()
        if not file.is_absolute():
            geometry["file"] = str(Path(path).parent / file)


def build_model_from_scene(scene: HousingScene, comm):
    """The housing FE model (housingfe.fe.model.HousingModel) of a housing scene: build_model on the scene's
    geometry, material, regions, supports, mesh spec and analysis.f_max; keeps the scene on the model for the
    reports."""
    from housingfe.fe.model import build_model

    model = build_model(scene.geometry, scene.material.resolve(), scene.mesh, scene.analysis.f_max, comm,
                        regions=scene.regions, supports=scene.supports)
    model.scene = scene
    return model
