"""The geometry every model derives on loading, in 2D or in 3D: one entry for the core and the plugins."""
from __future__ import annotations

import xarray as xr

from ..geometry.polygons import DERIVED_GEOMETRY_VARIABLES, derive_planar_geometry
from .model3d import DERIVED_3D_VARIABLES, derive_geometry_3d, space

#: What :func:`derive_geometry` adds to a model of either dimension: dropped from a file, left out of hashes.
DERIVED_VARIABLES = tuple(dict.fromkeys(DERIVED_GEOMETRY_VARIABLES + DERIVED_3D_VARIABLES))


def derive_geometry(ds: xr.Dataset) -> xr.Dataset:
    """Return ``ds`` with its derived geometry, always recomputed from the vertices (values stored in a file are
    never trusted): block areas, centroids, interface lengths, normals and tangents of a 2D model; block
    volumes and centroids, interface areas and normals of a 3D one (:mod:`masonryfw.format.model3d`)."""
    return derive_geometry_3d(ds) if space(ds) == 3 else derive_planar_geometry(ds)
