"""Isotropic linear-elastic materials (SI units)."""
from __future__ import annotations

from dataclasses import dataclass

from housingfe.errors import InputError


@dataclass(frozen=True)
class Material:
    """Isotropic material: Young's modulus E (Pa), Poisson ratio nu (-), density rho (kg/m^3),
    hysteretic loss factor eta (-)."""

    name: str
    youngs_modulus: float
    poisson_ratio: float
    density: float
    loss_factor: float = 0.0

    def __post_init__(self):
        if not (self.youngs_modulus > 0 and self.density > 0 and -1.0 < self.poisson_ratio < 0.5):
            raise InputError(f"material {self.name!r}: youngs_modulus = {self.youngs_modulus} Pa, poisson_ratio = "
                             f"{self.poisson_ratio}, density = {self.density} kg/m^3: non-physical")

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) in Pa."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def lame(self) -> tuple[float, float]:
        """Lamé constants (lambda, mu) in Pa."""
        E, nu = self.youngs_modulus, self.poisson_ratio
        return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


# The thesis' steel (Sec. 4.2); the others are common handbook values.
LIBRARY = {
    "steel": Material("steel", 210e9, 0.3, 7850.0),
    "cast-iron": Material("cast-iron", 120e9, 0.26, 7200.0),
    "aluminium": Material("aluminium", 70e9, 0.33, 2700.0),
}
