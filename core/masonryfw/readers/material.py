"""What a model's masonry is made of: read from a spec or a model, written into every block and joint."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Material:
    """What every masonry block and joint of a model is made of (SI)."""

    unit_weight: float  # N m-3
    friction: float  # mu = tan(phi)
    cohesion: float = 0.0  # Pa
    tensile_strength: float = 0.0  # Pa
    young_modulus: float | None = None  # Pa
    poisson_ratio: float | None = None
