"""What a plugin shares with the core: ``import masonryfw.plugin_api as mfp``.

The user's API is ``masonryfw`` (``mf``): build, solve, compare, draw, read what results mean. A plugin, the
command line and the conformance kit need more: the records and hooks of the contract, the options, the
progress, the geometry of the ragged polygon layout, the role masks, the fields every solver's result derives
the same way, the files written atomically and read safely, the text tables, the sparse Cholesky. They live
here, documented in docs/api.md ("For plugin authors"), and like ``mf`` every name is imported on first use
(lazy_loader, Scientific Python's SPEC 1): importing this module costs nothing. The names and where they live
are in ``plugin_api.pyi`` (relative to the ``masonryfw`` package), which type checkers read: the stub is the table.
"""
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub("masonryfw", __file__)
