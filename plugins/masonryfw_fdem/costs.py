"""What a time step costs, as measured on the 2-core machine of docs/benchmarks.md (the estimate's basis, and the
length of a kernel call)."""

# 2026-11-27 evening (the 2-core VM on an Intel Xeon host): 0.256e-6 (2,432 blocks to 5 mm, one thread);
# the same day on an AMD EPYC host 0.38e-6 to 0.42e-6; 0.29e-6 on 2026-11-25
STEP_SECONDS_PER_BLOCK = 0.26e-6
DEFORMABLE_FACTOR = 6.0  # Test 12C: 14.4 s against 2.3 s (docs/benchmarks.md, fdem-deformable)
#: Rigid polyhedra (3D) against polygons, a block's step: 2026-12-02, 1.3e-6 s a block on the bundled house
#: (1,126 blocks, 2,000 steps in 2.8-3.3 s), 1.4e-6 on Test 12C's twin (74 blocks, one thread).
POLYHEDRA_FACTOR = 5.0
#: Seconds a kernel call runs at most, as estimated: Python takes Ctrl-C between calls.
CALL_SECONDS = 0.25


def call_steps(blocks: int, deformable: bool = False, polyhedra: bool = False) -> int:
    """The steps of a kernel call of about :data:`CALL_SECONDS` on one thread."""
    step = blocks * STEP_SECONDS_PER_BLOCK * (DEFORMABLE_FACTOR if deformable else 1.0) \
        * (POLYHEDRA_FACTOR if polyhedra else 1.0)
    return max(1, int(CALL_SECONDS / step))
