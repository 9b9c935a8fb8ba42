"""Drawn example walls: a spec with ``[geometry]`` and its drawing each; :mod:`.generate` writes the drawings."""
