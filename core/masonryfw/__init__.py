"""masonryfw: failure analysis of dry-joint masonry walls under foundation settlements.

The public API (docs/api.md). Data flows one way::

    spec --build--> model --solve(plugin)--> result --compare/plot--> ...

Plugins and scripts import only the names exported here; the modules behind them are not an API.

Every name is imported on first use (Scientific Python's SPEC 1, ``lazy_loader``): ``import masonryfw``
costs milliseconds, and a command pays only for the modules it runs. The names and where they live are
in ``__init__.pyi``, which type checkers read.
"""
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
