"""What users give, read: the spec (TOML, typed tables, the keys every wall shares, its first and last
steps ``open_spec``/``model_attributes``), the material, DXF/CSV/GeoJSON drawings of blocks and elevations, OBJ
meshes of 3D blocks.

Data comes in as text and files and leaves as plain values (tables in SI, polygons, polyhedra); building a model
from them is the builders' work.
"""
