"""What a block is, by its ``block_role`` (the format's flags): masonry (units, voussoirs and lintels) or ground
(fixed and moving supports). The one place the role codes are read; every other part of the house asks here."""
from __future__ import annotations

import numpy as np

from .schema import flags

#: The role codes of the format: ``{"unit": 0, "lintel": 1, "fixed_support": 2, "moving_support": 3, "voussoir": 4}``.
ROLE = flags("block_role")
#: Masonry laid in joints: units, and voussoirs (the units of an arch, whose beds are the joints between them).
JOINTED_ROLES = (ROLE["unit"], ROLE["voussoir"])
MASONRY_ROLES = (*JOINTED_ROLES, ROLE["lintel"])
SUPPORT_ROLES = (ROLE["fixed_support"], ROLE["moving_support"])


def support_blocks(role: np.ndarray) -> np.ndarray:
    """Blocks that are supports (ground): fixed or moving."""
    return np.isin(role, SUPPORT_ROLES)


def masonry_blocks(role: np.ndarray) -> np.ndarray:
    """Units, voussoirs and lintels."""
    return np.isin(role, MASONRY_ROLES)


def jointed_blocks(role: np.ndarray) -> np.ndarray:
    """Units and voussoirs: the masonry of joints (not a lintel, one elastic piece)."""
    return np.isin(role, JOINTED_ROLES)


def moving_blocks(role: np.ndarray) -> np.ndarray:
    """The moving supports."""
    return np.asarray(role) == ROLE["moving_support"]


def fixed_blocks(role: np.ndarray) -> np.ndarray:
    """The fixed supports."""
    return np.asarray(role) == ROLE["fixed_support"]


def masonry_joints(role: np.ndarray, interface_blocks: np.ndarray) -> np.ndarray:
    """Interfaces with at least one masonry side (not ground against ground)."""
    return ~support_blocks(np.asarray(role)[np.asarray(interface_blocks, dtype=np.int64)]).all(axis=1)
