"""The `Structure` protocol: what the solvers and the response need of a structural model.

Both the bare housing (housingfe.fe.model.HousingModel) and the housing coupled with its drivetrain
(housingfe.drivetrain.interior.CoupledInterior) are Structures, so every later stage (modes, harmonic response,
radiation) takes either without asking which one it has.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable


@runtime_checkable
class Structure(Protocol):
    """A linear structural model in its solver DOFs.

    K, M: stiffness (N/m) and mass (kg) matrices (PETSc Mat, Dirichlet rows eliminated); C: viscous damping matrix
    (N s/m, e.g. bearing damping) or None; dofs: the number of DOFs; expected_zero_modes: rigid-body + mechanism
    modes the model must have (None when not known in advance, e.g. partial supports); load_vector(load): the
    load vector (PETSc Vec, N per unit amplitude) of a load spec (housingfe.scene.LoadSpec: a patch force,
    couple or pressure on a housing surface, or a force / moment on a drivetrain node); to_housing(vec): the
    housing's FE displacement field (PETSc Vec on V) of a vector in the solver DOFs; housing: the
    housingfe.geometry.HousingMesh; V: the housing's dolfinx displacement space."""

    @property
    def K(self): ...

    @property
    def M(self): ...

    @property
    def C(self): ...

    @property
    def dofs(self) -> int: ...

    @property
    def expected_zero_modes(self) -> int | None: ...

    def load_vector(self, load): ...

    def to_housing(self, vec): ...

    @property
    def housing(self): ...

    @property
    def V(self): ...
