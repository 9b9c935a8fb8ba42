"""What a time step costs, as measured on the 2-core machine of docs/benchmarks.md (the estimate's basis, and the
length of a kernel call)."""

# 2026-11-27 evening (the 2-core VM on an Intel Xeon host): 0.256e-6 (2,432 blocks to 5 mm, one thread);
# the same day on an AMD EPYC host 0.38e-6 to 0.42e-6; 0.29e-6 on 2026-11-25
STEP_SECONDS_PER_BLOCK = 0.26e-6
DEFORMABLE_FACTOR = 6.0  # Test 12C: 14.4 s against 2.3 s (docs/benchmarks.md, fdem-deformable)
#: Rigid polyhedra (3D) against polygons, a block's step: fitted 2026-12-02 on whole runs, the corner building
#: (134 blocks, one thread) 7.3, the building tests' small house (489, two threads) 7.3, the bundled house (1,126,
#: two threads) 10.4 (as the estimate counts threads); 8.5 puts all three within 20 % (5.0, from 2,000 steps of
#: the house, made its whole run's estimate 3x low with the 3D gravity phase's steps).
POLYHEDRA_FACTOR = 8.5
#: Seconds a kernel call runs at most, as estimated: Python takes Ctrl-C between calls.
CALL_SECONDS = 0.25


def call_steps(blocks: int, deformable: bool = False, polyhedra: bool = False) -> int:
    """The steps of a kernel call of about :data:`CALL_SECONDS` on one thread."""
    step = blocks * STEP_SECONDS_PER_BLOCK * (DEFORMABLE_FACTOR if deformable else 1.0) \
        * (POLYHEDRA_FACTOR if polyhedra else 1.0)
    return max(1, int(CALL_SECONDS / step))
