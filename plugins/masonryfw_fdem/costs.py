"""What a time step costs, as measured on the 2-core machine of docs/benchmarks.md (the estimate's basis, and the
length of a kernel call)."""

# 2026-11-27 evening (the 2-core VM on an Intel Xeon host): 0.256e-6 (2,432 blocks to 5 mm, one thread);
# the same day on an AMD EPYC host 0.38e-6 to 0.42e-6; 0.29e-6 on 2026-11-25
STEP_SECONDS_PER_BLOCK = 0.26e-6
DEFORMABLE_FACTOR = 6.0  # Test 12C: 14.4 s against 2.3 s (docs/benchmarks.md, fdem-deformable)
#: Rigid polyhedra (3D): a step costs about this much a joint of the model on one thread (the face pairs, about one
#: a joint, are the cost: their clipping and contact law). Fitted 2026-12-03 on whole runs with the overlaps
#: reused (the option ``reclip_ratio``), as the estimate counts threads: the corner building (134 blocks, 303
#: joints, one thread) 0.38 us, the building tests' small house (489, 1,216, two threads) 0.43, the bundled house
#: (1,126, 3,102, two threads) 0.43; by the block the three were 0.86, 1.07 and 1.20 us (a building has more
#: joints a block the larger it is). Clipping every pair every step, a block's step had cost 7.3-10.4 times the
#: polygons'.
POLYHEDRA_SECONDS_PER_JOINT = 0.42e-6
#: Seconds a kernel call runs at most, as estimated: Python takes Ctrl-C between calls.
CALL_SECONDS = 0.25


def step_seconds(blocks: int, joints: int, deformable: bool = False, polyhedra: bool = False) -> float:
    """A time step's seconds on one thread: polygons' by the block (``DEFORMABLE_FACTOR`` times that in the CST
    mode), polyhedra's by the joint."""
    if polyhedra:
        return joints * POLYHEDRA_SECONDS_PER_JOINT
    return blocks * STEP_SECONDS_PER_BLOCK * (DEFORMABLE_FACTOR if deformable else 1.0)


def call_steps(step: float) -> int:
    """The steps of a kernel call of about :data:`CALL_SECONDS` on one thread, of steps of ``step`` seconds."""
    return max(1, int(CALL_SECONDS / step))
