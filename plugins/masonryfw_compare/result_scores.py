"""The scores read alike from two results in 2D and in 3D: the collapse multipliers and the macro-block partition."""
from __future__ import annotations

import numpy as np
import xarray as xr

from . import scores


def multiplier_values(a: xr.Dataset, b: xr.Dataset) -> dict:
    """Both collapse multipliers, side by side, when both results are limit analyses."""
    if "collapse_multiplier" not in a or "collapse_multiplier" not in b:
        return {}
    return {
        "collapse_multiplier_a": float(a.collapse_multiplier.values),
        "collapse_multiplier_b": float(b.collapse_multiplier.values),
    }


def partition_scores(a: xr.Dataset, b: xr.Dataset, masonry: np.ndarray) -> dict:
    """Adjusted Rand index of the macro-block partitions of the masonry blocks."""
    if "macro_block" not in a or "macro_block" not in b:
        return {}
    return {"macro_block_ari": scores.adjusted_rand_index(a.macro_block.values[masonry], b.macro_block.values[masonry])}
