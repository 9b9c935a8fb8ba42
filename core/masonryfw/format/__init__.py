"""The model and result datasets (docs/format.md): the schema and its flags, block roles, the degrees of
freedom (loads and motions per block), derived geometry, the checks of a dataset, a model's checked form, the 3D
model (polyhedra, contacts, twins of 2D walls), and io (writing atomically, reading safely).

Data passes through it as xarray datasets: a builder's arrays become a model here (``model.checked_model``), a
file is read (``io.open_dataset``) and checked (``checks.check``) before anything uses it.
"""
