"""The plugin contract: the hook specifications, the records a plugin returns (solvers, estimates,
plotters, comparators), options and their parsing, lazy callables, the plugin registry (entry points, as a
third-party plugin registers) and provenance (versions and code digests written into every result).

Data passes as records: a plugin's hook returns them, the registry collects them, ``api`` calls them.
"""
