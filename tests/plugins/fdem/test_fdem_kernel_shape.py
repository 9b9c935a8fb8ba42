"""The kernels take their state: named tuples of arrays, no kernel with more than ten arguments."""
from __future__ import annotations

import inspect

from masonryfw_fdem import deformable, kernels


def test_no_kernel_takes_more_than_ten_arguments():
    compiled = {f"{module.__name__}.{name}": function for module in (kernels, deformable)
                for name, function in vars(module).items() if hasattr(function, "py_func")}
    assert {"masonryfw_fdem.kernels.advance", "masonryfw_fdem.deformable.advance",
            "masonryfw_fdem.kernels.contact_forces"} <= set(compiled)
    counts = {name: len(inspect.signature(f.py_func).parameters) for name, f in compiled.items()}
    assert max(counts.values()) <= 10, counts
