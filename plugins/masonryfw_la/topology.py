"""Whether every block is held: groups of blocks that no chain of contacts links to a support."""
from __future__ import annotations

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp


def check_supported(wall) -> None:
    """Raise when a connected group of blocks touches no support and holds no component.

    Such a group moves as a rigid body with no joint resisting: the problem has
    no finite multiplier, and naming the blocks is more useful than "unbounded".
    """
    labels = mfp.connected_components(wall.n_block, wall.sides)
    anchored = wall.support | wall.fixed.any(axis=1)
    supported = np.zeros(labels.max() + 1, dtype=bool)
    np.logical_or.at(supported, labels, anchored)
    loose = np.flatnonzero(~supported[labels])
    if loose.size:
        what = f"block {loose[0]} is" if loose.size == 1 else f"blocks {mfp.listed(loose)} are"
        raise mf.SolveError(
            f"{what} not supported: no chain of contacts links them to a support or a held "
            "block, so they can move as a rigid body with no joint resisting"
        )
