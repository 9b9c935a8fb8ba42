"""Geometry on arrays only: 2D polygons (``polygons``: areas, centroids, offsets, interface frames),
overlaps of polygons, the interfaces between 2D blocks, polyhedra in 3D (volumes, faces, contacts), box broad
phases and graphs of blocks (connected components).

Data comes in as coordinate arrays and leaves as arrays (pairs of blocks, contact polygons, labels): no dataset,
no spec, no role. Imports only the runtime.
"""
